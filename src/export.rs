//! Writing results: PNG (8-bit sRGB, with the render's settings in text chunks) and OpenEXR
//! (linear 32-bit float). Every write goes to a temporary file in the destination folder and is
//! renamed into place, so a failed or interrupted write never leaves a half-written file.

use std::io::{BufWriter, Write};
use std::path::Path;

use glam::Vec3;

use crate::accel::AccelKind;
use crate::render::Image;
use crate::scene::RenderParams;
use crate::trace::TraceSettings;

/// A write that failed: one sentence naming the file.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {path}: {reason}")]
pub struct ExportError {
    pub path: String,
    pub reason: String,
}

fn export_error(path: &Path, reason: impl std::fmt::Display) -> ExportError {
    ExportError {
        path: path.display().to_string(),
        reason: plain_reason(&reason.to_string()),
    }
}

/// The OS's reason alone. `tempfile` appends the temporary file's path ("… at path
/// /dir/.raytree-Xy12.tmp"), a name the user never chose and that no longer exists, and
/// "(os error N)" is for programs; both would only blur the sentence.
fn plain_reason(text: &str) -> String {
    let text = text.split(" at path ").next().unwrap_or(text);
    match text.find(" (os error") {
        Some(i) => {
            let tail = text[i..].split_once(')').map_or("", |(_, t)| t);
            format!("{}{tail}", &text[..i])
        }
        None => text.to_string(),
    }
}

/// The sRGB transfer function of a linear value, clamped to [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// A linear colour as 8-bit sRGB (exposure 1, clamped).
pub fn to_srgb8(c: Vec3) -> [u8; 3] {
    let q = |v: f32| (linear_to_srgb(v) * 255.0 + 0.5) as u8;
    [q(c.x), q(c.y), q(c.z)]
}

/// The image as 8-bit sRGB RGB bytes, row-major.
pub fn srgb8_bytes(image: &Image) -> Vec<u8> {
    image.pixels.iter().flat_map(|&c| to_srgb8(c)).collect()
}

/// Writes `path` through a temporary file in the same folder, then renames it into place.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&std::fs::File>) -> Result<(), String>,
) -> Result<(), ExportError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = tempfile::Builder::new()
        .prefix(".raytree-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|e| export_error(path, e))?;
    {
        let mut out = BufWriter::new(tmp.as_file());
        write(&mut out).map_err(|e| export_error(path, e))?;
        out.flush().map_err(|e| export_error(path, e))?;
    }
    // Temporary files are private (0600); the result is an ordinary file like any other.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))
            .map_err(|e| export_error(path, e))?;
    }
    tmp.as_file()
        .sync_all()
        .map_err(|e| export_error(path, e))?;
    tmp.persist(path).map_err(|e| export_error(path, e.error))?;
    Ok(())
}

/// The PNG text chunks (keyword, value) that say how an image was made: the program, the scene
/// (a file or a built-in name), the samples done of the target, and as JSON the settings that
/// shaped it. The CLI's render and the viewer's export both stamp through here, so a PNG says
/// the same whichever wrote it.
pub fn stamp(
    scene_label: &str,
    samples_done: u32,
    samples_target: u32,
    render: &RenderParams,
    trace: &TraceSettings,
    accel_used: AccelKind,
) -> Vec<(String, String)> {
    // `json!` builds a map sorted by key (serde_json without `preserve_order`): the settings
    // read in that order, whatever the order written here.
    let settings = serde_json::json!({
        "width": render.width, "height": render.height, "max_depth": render.max_depth,
        "shading": render.shading, "trace": trace, "accel_used": accel_used,
    });
    vec![
        (
            "Software".to_string(),
            format!("raytree {}", env!("CARGO_PKG_VERSION")),
        ),
        ("raytree.scene".to_string(), scene_label.to_string()),
        (
            "raytree.samples".to_string(),
            format!("{samples_done}/{samples_target}"),
        ),
        ("raytree.settings".to_string(), settings.to_string()),
    ]
}

/// Writes an 8-bit sRGB PNG with `text` as `tEXt` chunks (keyword, value).
pub fn write_png(path: &Path, image: &Image, text: &[(String, String)]) -> Result<(), ExportError> {
    let bytes = srgb8_bytes(image);
    encode_png(
        path,
        image.width,
        image.height,
        png::ColorType::Rgb,
        &bytes,
        text,
    )
}

/// Writes 8-bit sRGB RGBA pixels (row-major, straight alpha) as a PNG with `text`, like
/// [`write_png`]: the scene view's pictures, drawn in 8 bits.
pub fn write_png_rgba8(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[u8],
    text: &[(String, String)],
) -> Result<(), ExportError> {
    encode_png(path, width, height, png::ColorType::Rgba, rgba, text)
}

/// The one PNG encoder: 8 bits a channel, marked sRGB, `text` as `tEXt` chunks, written
/// atomically.
fn encode_png(
    path: &Path,
    width: u32,
    height: u32,
    color: png::ColorType,
    bytes: &[u8],
    text: &[(String, String)],
) -> Result<(), ExportError> {
    write_atomically(path, |out| {
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(color);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        for (key, value) in text {
            encoder
                .add_text_chunk(key.clone(), value.clone())
                .map_err(|e| e.to_string())?;
        }
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(bytes).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    })
}

/// Writes a linear 32-bit float RGB OpenEXR file.
pub fn write_exr(path: &Path, image: &Image) -> Result<(), ExportError> {
    use exr::prelude::*;
    let w = image.width as usize;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let c = image.pixels[y * w + x];
        (c.x, c.y, c.z)
    });
    let exr_image = exr::image::Image::from_channels((w, image.height as usize), channels);
    write_atomically(path, |out| {
        let mut cursor = std::io::Cursor::new(Vec::new());
        exr_image
            .write()
            .to_buffered(&mut cursor)
            .map_err(|e| e.to_string())?;
        out.write_all(cursor.get_ref()).map_err(|e| e.to_string())
    })
}

/// Writes `.png` or `.exr` by the extension of `path` (case-insensitive).
pub fn write_image(
    path: &Path,
    image: &Image,
    text: &[(String, String)],
) -> Result<(), ExportError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => write_png(path, image, text),
        Some("exr") => write_exr(path, image),
        _ => Err(export_error(
            path,
            "the file name must end in .png (8-bit sRGB) or .exr (linear float)",
        )),
    }
}

/// Writes text (a scene, a tree) atomically.
pub fn write_text(path: &Path, text: &str) -> Result<(), ExportError> {
    write_atomically(path, |out| {
        out.write_all(text.as_bytes()).map_err(|e| e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_endpoints_and_midpoint() {
        assert_eq!(to_srgb8(Vec3::ZERO), [0, 0, 0]);
        assert_eq!(to_srgb8(Vec3::ONE), [255, 255, 255]);
        assert_eq!(to_srgb8(Vec3::splat(2.0)), [255, 255, 255]);
        // Linear 0.22 is sRGB 1.055·0.22^(1/2.4) − 0.055 = 0.50640 → 129.13 → 129.
        assert_eq!(to_srgb8(Vec3::splat(0.22)), [129, 129, 129]);
        // Below the linear segment's end: 12.92 · 0.002 = 0.02584 → 6.59 → 7.
        assert_eq!(to_srgb8(Vec3::splat(0.002)), [7, 7, 7]);
        assert_eq!(to_srgb8(Vec3::splat(f32::NAN)), [0, 0, 0]);
    }

    /// The stamp is pinned byte for byte: PNGs written before and after read the same.
    #[test]
    fn stamp_keys_values_and_settings_json() {
        let scene = crate::scene::builtin::load_builtin("quiz").expect("quiz");
        let text = stamp(
            "quiz",
            2,
            4,
            &scene.render,
            &TraceSettings::default(),
            AccelKind::Bvh,
        );
        let keys: Vec<&str> = text.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "Software",
                "raytree.scene",
                "raytree.samples",
                "raytree.settings"
            ]
        );
        assert_eq!(text[0].1, format!("raytree {}", env!("CARGO_PKG_VERSION")));
        assert_eq!((text[1].1.as_str(), text[2].1.as_str()), ("quiz", "2/4"));
        // Keys sorted: `json!` builds serde_json's default (sorted) map.
        assert_eq!(
            text[3].1,
            "{\"accel_used\":\"bvh\",\"height\":201,\"max_depth\":5,\"shading\":\"blinn-phong\",\
             \"trace\":{\"accel\":\"auto\",\"cutoff\":0.0,\"methods\":{\"offset\":\"error-bound\",\"shading_normals\":\"robust\",\
             \"sphere\":\"robust\",\"triangle\":\"watertight\"}},\"width\":201}"
        );
    }

    #[test]
    fn reasons_are_plain() {
        assert_eq!(
            plain_reason("Not a directory (os error 20) at path \"/d/.raytree-x.tmp\""),
            "Not a directory"
        );
        assert_eq!(
            plain_reason("IO error: File too large (os error 27)"),
            "IO error: File too large"
        );
        assert_eq!(plain_reason("simulated failure"), "simulated failure");
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("x.png");
        let r = write_atomically(&path, |_| Err("simulated failure".into()));
        assert!(r.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).expect("list").count(), 0);
    }
}
