//! Writing results: PNG (8-bit sRGB, with the render's settings in text chunks) and OpenEXR
//! (linear 32-bit float). Every write goes to a temporary file in the destination folder and is
//! renamed into place, so a failed or interrupted write never leaves a half-written file.

use std::io::{BufWriter, Write};
use std::path::Path;

use glam::Vec3;

use crate::accel::AccelKind;
use crate::render::{Image, Rect};
use crate::scene::{RenderParams, Scene};
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
/// Whether a file can be written at `path` (its folder exists and takes a new file), asked
/// before a long render so that a typo in the folder fails at once, with the sentence the
/// write itself would give.
pub fn check_writable(path: &Path) -> Result<(), ExportError> {
    temp_beside(path).map(drop)
}

/// A new private temporary file in `path`'s folder (the current one for a bare name), where
/// [`write_atomically`] writes before renaming it over `path`.
fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile, ExportError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    tempfile::Builder::new()
        .prefix(".raytree-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|e| export_error(path, e))
}

pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&std::fs::File>) -> Result<(), String>,
) -> Result<(), ExportError> {
    let tmp = temp_beside(path)?;
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

/// The stamp key of the scene's fingerprint ([`scene_hash`]).
pub const KEY_SCENE_HASH: &str = "raytree.scene_hash";
/// The stamp key of the pixels an image holds of the full image: `X,Y,W,H`.
pub const KEY_REGION: &str = "raytree.region";
/// The stamp key of a turntable frame: `I/N`.
pub const KEY_FRAME: &str = "raytree.frame";

/// A fingerprint of everything in the scene that shapes its pixels (render parameters, camera,
/// lights, materials, objects, spheres, triangles, the meshes' vertex normals and texture
/// coordinates; not the file's path nor its warnings, and textures by their place in the scene,
/// not their pixels): 16 hex digits of a 64-bit FNV-1a hash. Parts of one render made on
/// different machines from the same scene carry the same fingerprint.
///
/// The small parts are hashed as their `Debug` text (which prints floats exactly: the
/// shortest text that reads back to the same value); the triangles and mesh attributes, which
/// can number millions, as the bits of their numbers, 32 bits a step (text would take most of
/// a second for a million triangles).
pub fn scene_hash(scene: &Scene) -> String {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    struct Fnv(u64);
    impl Fnv {
        fn word(&mut self, w: u32) {
            self.0 = (self.0 ^ u64::from(w)).wrapping_mul(PRIME);
        }
        fn vec3(&mut self, v: glam::Vec3) {
            for c in v.to_array() {
                self.word(c.to_bits());
            }
        }
    }
    impl std::fmt::Write for Fnv {
        fn write_str(&mut self, s: &str) -> std::fmt::Result {
            for b in s.bytes() {
                self.0 = (self.0 ^ u64::from(b)).wrapping_mul(PRIME);
            }
            Ok(())
        }
    }
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    let _ = std::fmt::Write::write_fmt(
        &mut h,
        format_args!(
            "{:?}{:?}{:?}{:?}{:?}{:?}",
            scene.render, scene.camera, scene.lights, scene.materials, scene.objects, scene.spheres,
        ),
    );
    // Counts first, so lists of different lengths cannot run into each other.
    h.word(scene.triangles.len() as u32);
    for t in scene.triangles.iter() {
        for v in t.vertices {
            h.vec3(v);
        }
        h.word(t.material.0);
        h.word(t.object.0);
    }
    h.word(scene.attributes.len() as u32);
    for a in &scene.attributes {
        for w in [
            a.first_triangle,
            a.triangle_count,
            a.normals.len() as u32,
            a.normal_indices.len() as u32,
            a.uvs.len() as u32,
            a.uv_indices.len() as u32,
        ] {
            h.word(w);
        }
        for &n in &a.normals {
            h.vec3(n);
        }
        for uv in &a.uvs {
            h.word(uv.x.to_bits());
            h.word(uv.y.to_bits());
        }
        for idx in a.normal_indices.iter().chain(&a.uv_indices) {
            for &i in idx {
                h.word(i);
            }
        }
    }
    format!("{:016x}", h.0)
}

/// `X,Y,W,H`, as `--region` takes it and [`KEY_REGION`] holds it.
pub fn format_region(r: Rect) -> String {
    format!("{},{},{},{}", r.x, r.y, r.width, r.height)
}

/// Reads `X,Y,W,H` (whole numbers); `None` when it is not that.
pub fn parse_region(text: &str) -> Option<Rect> {
    let v: Vec<u32> = text
        .split(',')
        .map(|p| p.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .ok()?;
    match v[..] {
        [x, y, width, height] => Some(Rect {
            x,
            y,
            width,
            height,
        }),
        _ => None,
    }
}

/// The stamp entries that make an image a part of a larger render: the scene's fingerprint and
/// the region it holds (the whole image for a single-machine render), after [`stamp`]'s.
pub fn part_stamp(scene: &Scene, region: Rect) -> Vec<(String, String)> {
    vec![
        (KEY_SCENE_HASH.to_string(), scene_hash(scene)),
        (KEY_REGION.to_string(), format_region(region)),
    ]
}

/// The pixels of an image read back: 8-bit sRGB RGB bytes (PNG) or linear floats (EXR).
#[derive(Clone, Debug, PartialEq)]
pub enum Pixels {
    Srgb8(Vec<u8>),
    Linear(Vec<Vec3>),
}

/// An image raytree wrote, read back with its stamp.
#[derive(Clone, Debug, PartialEq)]
pub struct StampedImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Pixels,
    /// The stamp, in the order written (empty when the file has none).
    pub text: Vec<(String, String)>,
}

impl StampedImage {
    /// The stamp's value for `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.text
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// A read that failed: one sentence naming the file.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {path}: {reason}")]
pub struct ReadError {
    pub path: String,
    pub reason: String,
}

fn read_error(path: &Path, reason: impl std::fmt::Display) -> ReadError {
    ReadError {
        path: path.display().to_string(),
        reason: plain_reason(&reason.to_string()),
    }
}

/// Reads a PNG (8-bit RGB, as raytree writes) or an EXR (RGB) with its stamp, by the
/// extension of `path`.
pub fn read_stamped(path: &Path) -> Result<StampedImage, ReadError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => read_png(path),
        Some("exr") => read_exr(path),
        _ => Err(read_error(path, "the file name must end in .png or .exr")),
    }
}

/// An image's size, kind and stamp without its pixels (the file's header only): what
/// `raytree merge` checks before it reads any part's pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct StampHeader {
    pub width: u32,
    pub height: u32,
    /// True for an EXR (linear floats), false for a PNG (8-bit sRGB).
    pub linear: bool,
    pub text: Vec<(String, String)>,
}

impl StampHeader {
    /// The stamp's value for `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.text
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// Reads the header of a PNG or EXR: size, kind and stamp, not the pixels.
pub fn read_stamp_header(path: &Path) -> Result<StampHeader, ReadError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => {
            let file = std::fs::File::open(path).map_err(|e| read_error(path, e))?;
            let reader = png::Decoder::new(std::io::BufReader::new(file))
                .read_info()
                .map_err(|e| read_error(path, e))?;
            let info = reader.info();
            Ok(StampHeader {
                width: info.width,
                height: info.height,
                linear: false,
                text: info
                    .uncompressed_latin1_text
                    .iter()
                    .map(|c| (c.keyword.clone(), c.text.clone()))
                    .collect(),
            })
        }
        Some("exr") => {
            let meta = exr::meta::MetaData::read_from_file(path, false)
                .map_err(|e| read_error(path, e))?;
            let header = meta
                .headers
                .first()
                .ok_or_else(|| read_error(path, "it has no layer"))?;
            Ok(StampHeader {
                width: header.layer_size.width() as u32,
                height: header.layer_size.height() as u32,
                linear: true,
                text: exr_stamp(path, &header.own_attributes)?,
            })
        }
        _ => Err(read_error(path, "the file name must end in .png or .exr")),
    }
}

/// The stamp in an EXR layer's attributes (empty when it has none).
fn exr_stamp(
    path: &Path,
    attributes: &exr::meta::header::LayerAttributes,
) -> Result<Vec<(String, String)>, ReadError> {
    match attributes
        .other
        .get(&exr::meta::attribute::Text::from(EXR_STAMP_ATTRIBUTE))
    {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => serde_json::from_str(&t.to_string())
            .map_err(|e| {
                read_error(
                    path,
                    format!("its {EXR_STAMP_ATTRIBUTE} attribute is not a stamp: {e}"),
                )
            }),
        _ => Ok(Vec::new()),
    }
}

fn read_png(path: &Path) -> Result<StampedImage, ReadError> {
    let file = std::fs::File::open(path).map_err(|e| read_error(path, e))?;
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder.read_info().map_err(|e| read_error(path, e))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| read_error(path, "the image is too large"))?;
    let mut buf = vec![0; size];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| read_error(path, e))?;
    if info.color_type != png::ColorType::Rgb || info.bit_depth != png::BitDepth::Eight {
        return Err(read_error(
            path,
            format!(
                "it is {:?} at {:?} bits, not the 8-bit RGB raytree writes",
                info.color_type, info.bit_depth
            ),
        ));
    }
    buf.truncate(info.line_size * info.height as usize);
    let text = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|c| (c.keyword.clone(), c.text.clone()))
        .collect();
    Ok(StampedImage {
        width: info.width,
        height: info.height,
        pixels: Pixels::Srgb8(buf),
        text,
    })
}

fn read_exr(path: &Path) -> Result<StampedImage, ReadError> {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| (size.width(), vec![Vec3::ZERO; size.width() * size.height()]),
            |(w, px): &mut (usize, Vec<Vec3>), Vec2(x, y), (r, g, b): (f32, f32, f32)| {
                px[y * *w + x] = Vec3::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| read_error(path, e))?;
    let layer = &image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let text = exr_stamp(path, &layer.attributes)?;
    Ok(StampedImage {
        width: w as u32,
        height: h as u32,
        pixels: Pixels::Linear(layer.channel_data.pixels.1.clone()),
        text,
    })
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

/// Writes 8-bit sRGB RGB bytes (row-major) as a PNG with `text`, exactly as [`write_png`]
/// writes an image: `raytree merge` assembles PNG parts through here.
pub fn write_png_rgb8(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    text: &[(String, String)],
) -> Result<(), ExportError> {
    encode_png(path, width, height, png::ColorType::Rgb, rgb, text)
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

/// The EXR header attribute that holds the stamp: the same (key, value) pairs as a PNG's text
/// chunks, as a JSON array of pairs (one attribute, so the header's order never varies).
pub const EXR_STAMP_ATTRIBUTE: &str = "raytree.stamp";

/// Writes a linear 32-bit float RGB OpenEXR file.
pub fn write_exr(path: &Path, image: &Image) -> Result<(), ExportError> {
    write_exr_stamped(path, image, &[])
}

/// [`write_exr`] with `text` in the header attribute [`EXR_STAMP_ATTRIBUTE`] (none when
/// `text` is empty).
pub fn write_exr_stamped(
    path: &Path,
    image: &Image,
    text: &[(String, String)],
) -> Result<(), ExportError> {
    use exr::prelude::*;
    let w = image.width as usize;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let c = image.pixels[y * w + x];
        (c.x, c.y, c.z)
    });
    let mut exr_image = exr::image::Image::from_channels((w, image.height as usize), channels);
    if !text.is_empty() {
        let json = serde_json::to_string(text).map_err(|e| export_error(path, e))?;
        // EXR text is Latin-1: every non-ASCII character (only ever inside a JSON string) is
        // written as its JSON escape, so the attribute is plain ASCII.
        let mut ascii = String::with_capacity(json.len());
        for c in json.chars() {
            if c.is_ascii() {
                ascii.push(c);
            } else {
                for unit in c.encode_utf16(&mut [0u16; 2]) {
                    ascii += &format!("\\u{unit:04x}");
                }
            }
        }
        let value = exr::meta::attribute::Text::new_or_none(&ascii)
            .ok_or_else(|| export_error(path, "the stamp is not plain text"))?;
        exr_image.layer_data.attributes.other.insert(
            exr::meta::attribute::Text::from(EXR_STAMP_ATTRIBUTE),
            exr::meta::attribute::AttributeValue::Text(value),
        );
    }
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
        Some("exr") => write_exr_stamped(path, image, text),
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

    /// The fingerprint is the same for the same scene loaded twice, and changes with anything
    /// that shapes pixels: one ulp of one vertex, one vertex normal, a triangle's material.
    #[test]
    fn scene_hash_follows_geometry_and_vertex_normals() {
        let load = || crate::scene::builtin::load_builtin("smooth").expect("smooth");
        let base = scene_hash(&load());
        assert_eq!(base.len(), 16);
        assert_eq!(scene_hash(&load()), base);

        let mut moved = load();
        let v = &mut std::sync::Arc::make_mut(&mut moved.triangles)[0].vertices[1];
        v.x = crate::geometry::next_float_up(v.x);
        assert_ne!(scene_hash(&moved), base, "one ulp of one vertex");

        let mut bent = load();
        let mesh = bent
            .attributes
            .iter_mut()
            .find(|a| !a.normals.is_empty())
            .expect("the smooth scene has vertex normals");
        let n = &mut std::sync::Arc::make_mut(mesh).normals[0];
        *n = (*n + Vec3::splat(0.01)).normalize();
        assert_ne!(scene_hash(&bent), base, "one vertex normal");

        let mut repainted = load();
        let t = &mut std::sync::Arc::make_mut(&mut repainted.triangles)[0];
        t.material = crate::scene::MaterialId(t.material.0 + 1);
        assert_ne!(scene_hash(&repainted), base, "a triangle's material");
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
    fn stamps_read_back_from_exr_and_png_even_beyond_latin1() {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut image = Image::new(3, 2);
        image.pixels[4] = Vec3::new(0.25, 1.5, -0.0);
        let text = vec![
            (
                "raytree.scene".to_string(),
                "scènes/☃ \"q\".toml".to_string(),
            ),
            (KEY_REGION.to_string(), "1,2,3,2".to_string()),
        ];
        let exr = dir.path().join("a.exr");
        write_exr_stamped(&exr, &image, &text).expect("write exr");
        let header = read_stamp_header(&exr).expect("exr header");
        assert_eq!((header.width, header.height, header.linear), (3, 2, true));
        assert_eq!(header.text, text);
        let full = read_stamped(&exr).expect("exr");
        assert_eq!(full.text, text);
        assert_eq!(full.pixels, Pixels::Linear(image.pixels.clone()));
        assert_eq!(
            parse_region(full.get(KEY_REGION).expect("region")),
            Some(Rect {
                x: 1,
                y: 2,
                width: 3,
                height: 2
            })
        );
        // PNG text is Latin-1: the label's Latin-1 part survives.
        let png = dir.path().join("a.png");
        let latin = vec![("raytree.scene".to_string(), "scène".to_string())];
        write_png(&png, &image, &latin).expect("write png");
        let header = read_stamp_header(&png).expect("png header");
        assert_eq!((header.width, header.height, header.linear), (3, 2, false));
        assert_eq!(header.text, latin);
        assert_eq!(
            read_stamped(&png).expect("png").pixels,
            Pixels::Srgb8(srgb8_bytes(&image))
        );
        assert!(read_stamp_header(&dir.path().join("a.jpg")).is_err());
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
