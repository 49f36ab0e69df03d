//! Image textures for MTL `map_Kd` and `map_Ka` (docs/design.md, "Scene files"): PNG, JPEG,
//! TGA, BMP, TIFF and GIF (the formats real models' MTL files name) through the `image` crate,
//! decoded once from sRGB to linear RGB, checked against the memory budget from the image's
//! header before any texel is decoded. Sampling (bilinear, wrapping) is
//! [`super::Texture::sample`].

use std::io::Cursor;

use image::ImageDecoder;

use super::Texture;
use super::budget::{MemoryLimit, format_bytes};

/// Largest texture file read (a 16k × 16k JPEG is well under it).
pub const MAX_TEXTURE_FILE_BYTES: u64 = 256 << 20;

/// The sRGB transfer function inverted: the linear value of an 8-bit sRGB code.
fn srgb_to_linear(code: u8) -> f32 {
    srgb_unit_to_linear(f32::from(code) / 255.0)
}

/// The linear value of an sRGB-encoded one in [0, 1].
pub(crate) fn srgb_unit_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Whether `bytes` start with a header only a TGA file has: a colour map flag of 0 or 1, one of
/// the six image types (colour-mapped, true-colour or grey, raw or run-length), a size, a pixel
/// depth of 8, 15, 16, 24 or 32 bits, and nothing in the descriptor's unused bits; with room
/// for the header and its id field. Other files (text, other formats) fail it at once: a TGA's
/// second and third bytes, say, are never printable text.
fn looks_like_tga(bytes: &[u8]) -> bool {
    let [id_len, map_type, image_type, ..] = *bytes else {
        return false;
    };
    if bytes.len() < 18 + usize::from(id_len) {
        return false;
    }
    let word = |i: usize| u16::from_le_bytes([bytes[i], bytes[i + 1]]);
    let (width, height, depth, descriptor) = (word(12), word(14), bytes[16], bytes[17]);
    map_type <= 1
        && matches!(image_type, 1 | 2 | 3 | 9 | 10 | 11)
        && (image_type % 8 == 1) == (map_type == 1)
        && width > 0
        && height > 0
        && matches!(depth, 8 | 15 | 16 | 24 | 32)
        && descriptor & 0xC0 == 0
}

/// What [`decode_texture`] says of a file in none of the formats it reads.
pub const NOT_AN_IMAGE: &str = "it is not a PNG, JPEG, TGA, BMP, TIFF, GIF or DDS image";

/// Decodes PNG, JPEG, TGA, BMP, TIFF, GIF (its first frame) or DDS `bytes` into a linear texture
/// named `name`, or says why not in a phrase ([`NOT_AN_IMAGE`], "its 40000x40000 texels would
/// need ..."). The format is read from the bytes, and for TGA (which has no signature) from a
/// `.tga` ending of `name`, or from a header that can only be a TGA's (a TGA renamed `.png` by
/// an exporter).
/// `limit` is the memory still available: a texture larger than it is refused from its header,
/// before a texel is decoded. A JPEG cut short (no end-of-image marker after its last scan) is
/// refused too: the decoder would fill the missing part with grey and say nothing.
pub fn decode_texture(name: &str, bytes: &[u8], limit: &MemoryLimit) -> Result<Texture, String> {
    use image::ImageFormat;
    if bytes.starts_with(b"DDS ") {
        return decode_dds(name, bytes, limit);
    }
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot read it ({})", one_line(&e)))?;
    let tga = std::path::Path::new(name)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("tga"));
    if reader.format().is_none() && (tga || looks_like_tga(bytes)) {
        reader.set_format(ImageFormat::Tga);
    }
    match reader.format() {
        Some(
            ImageFormat::Png
            | ImageFormat::Tga
            | ImageFormat::Bmp
            | ImageFormat::Tiff
            | ImageFormat::Gif,
        ) => {}
        Some(ImageFormat::Jpeg) if !jpeg_is_whole(bytes) => {
            return Err("it is cut short (a JPEG without its end-of-image marker)".into());
        }
        Some(ImageFormat::Jpeg) => {}
        _ => return Err(NOT_AN_IMAGE.into()),
    }
    let mut decoder = reader
        .into_decoder()
        .map_err(|e| format!("cannot read its size ({})", one_line(&e)))?;
    let (width, height) = decoder.dimensions();
    if width == 0 || height == 0 {
        return Err(format!("it has no texels ({width}x{height})"));
    }
    // While the texture is made, three copies exist: the decoded image (its own texel size),
    // its 8-bit RGB copy and the linear texels.
    let texels = u64::from(width) * u64::from(height);
    let decoded_bytes = texels.saturating_mul(u64::from(decoder.color_type().bytes_per_pixel()));
    let peak = Texture::bytes(width, height)
        .saturating_add(decoded_bytes)
        .saturating_add(texels.saturating_mul(3));
    limit
        .check(format!("its {width}x{height} texels"), peak)
        .map_err(|e| e.to_string())?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(peak.max(1 << 20));
    decoder
        .set_limits(limits)
        .map_err(|e| format!("cannot decode it ({})", one_line(&e)))?;
    let decoded = image::DynamicImage::from_decoder(decoder)
        .map_err(|e| format!("cannot decode it ({})", one_line(&e)))?;
    Ok(linear(name, &decoded.to_rgb8()))
}

/// A DDS texture (game assets: BC1–BC7 blocks, or uncompressed): its largest mipmap, and of a
/// cube map or an array its first image. As for [`decode_texture`], one that would not fit in
/// `limit` is refused from its header. Its texels are taken as sRGB, as an exporter writes a
/// colour texture whatever format flag it sets.
fn decode_dds(name: &str, bytes: &[u8], limit: &MemoryLimit) -> Result<Texture, String> {
    let dds = image_dds::ddsfile::Dds::read(Cursor::new(bytes))
        .map_err(|e| format!("cannot read it as DDS ({})", one_line(&e)))?;
    let (width, height, depth) = (dds.get_width(), dds.get_height(), dds.get_depth());
    if width == 0 || height == 0 {
        return Err(format!("it has no texels ({width}x{height})"));
    }
    if depth > 1 {
        return Err(format!(
            "it is a volume texture ({width}x{height}x{depth}), not an image"
        ));
    }
    // The decoded RGBA image, its RGB copy and the linear texels.
    let texels = u64::from(width) * u64::from(height);
    let peak = Texture::bytes(width, height).saturating_add(texels.saturating_mul(4 + 3));
    limit
        .check(format!("its {width}x{height} texels"), peak)
        .map_err(|e| e.to_string())?;
    let rgba = image_dds::SurfaceRgba8::decode_layers_mipmaps_dds(&dds, 0..1, 0..1)
        .map_err(|e| format!("cannot decode it ({})", one_line(&e)))?
        .into_image()
        .map_err(|e| format!("cannot decode it ({})", one_line(&e)))?;
    Ok(linear(
        name,
        &image::DynamicImage::ImageRgba8(rgba).to_rgb8(),
    ))
}

/// The texture named `name` of an 8-bit sRGB image.
fn linear(name: &str, rgb: &image::RgbImage) -> Texture {
    let lut: Vec<f32> = (0..=255u8).map(srgb_to_linear).collect();
    let texels = rgb
        .pixels()
        .map(|p| p.0.map(|c| lut[usize::from(c)]))
        .collect();
    Texture {
        name: name.to_string(),
        width: rgb.width(),
        height: rgb.height(),
        texels,
    }
}

/// A decoder's error as words on one line (some end theirs with a line break): a warning is
/// one line.
fn one_line(e: &impl std::fmt::Display) -> String {
    e.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// True if the JPEG `bytes` has an end-of-image marker (`FF D9`) after the start of its last
/// scan (`FF DA`). Inside a scan's data a byte `FF` is always followed by `00` or a restart
/// marker, so neither can appear there by chance; a thumbnail's markers come before the main
/// image's scans. Bytes after the marker (some cameras append data) do not matter.
fn jpeg_is_whole(bytes: &[u8]) -> bool {
    let marker = |code: u8| bytes.windows(2).rposition(|w| w == [0xFF, code]);
    match (marker(0xDA), marker(0xD9)) {
        (Some(scan), Some(end)) => end > scan,
        _ => false,
    }
}

/// A resolver of binary files (textures) relative to `folder`: regular files only (a folder,
/// a device such as `/dev/zero` or a pipe is refused with a phrase), at most
/// [`MAX_TEXTURE_FILE_BYTES`]; a name not found as written is matched regardless of case
/// (`disk_names::ignoring_case`).
pub fn fs_bytes_resolver(folder: std::path::PathBuf) -> impl Fn(&str) -> Result<Vec<u8>, String> {
    move |path: &str| {
        read_bytes(
            &super::disk_names::ignoring_case(&folder.join(path)),
            MAX_TEXTURE_FILE_BYTES,
        )
    }
}

fn read_bytes(path: &std::path::Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let reason = |e: std::io::Error| {
        let text = e.to_string();
        match text.find(" (os error") {
            Some(i) => text[..i].to_string(),
            None => text,
        }
    };
    let meta = std::fs::metadata(path).map_err(reason)?;
    if meta.is_dir() {
        return Err("it is a folder, not a file".into());
    }
    if !meta.is_file() {
        return Err("it is not a regular file (a device, a pipe or a socket)".into());
    }
    let too_big = format!(
        "it is more than the {} a texture file may have",
        format_bytes(max_bytes)
    );
    if meta.len() > max_bytes {
        return Err(too_big);
    }
    let file = std::fs::File::open(path).map_err(reason)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(reason)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big);
    }
    if let Some(reason) = super::lfs::pointer_reason(&bytes) {
        return Err(reason);
    }
    Ok(bytes)
}

/// "`name` (1.2 MiB)": for messages about a texture's memory.
pub fn describe_size(texture: &Texture) -> String {
    format!(
        "`{}` ({})",
        texture.name,
        format_bytes(Texture::bytes(texture.width, texture.height))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().expect("header");
        w.write_image_data(rgb).expect("data");
        drop(w);
        out
    }

    fn roomy() -> MemoryLimit {
        MemoryLimit {
            bytes: 1 << 30,
            source: "a test".into(),
        }
    }

    #[test]
    fn pngs_decode_to_linear_and_sample_bilinearly_with_wrapping() {
        let bytes = png(2, 1, &[255, 0, 0, 0, 0, 255]);
        let t = decode_texture("t.png", &bytes, &roomy()).expect("decodes");
        assert_eq!((t.width, t.height), (2, 1));
        assert_eq!(t.texels, vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        // Texel centres at u = 0.25 and 0.75; halfway between, an even mix; u = 0 wraps to
        // halfway between the last and the first texel.
        let mid = t.sample(glam::Vec2::new(0.5, 0.5));
        assert!(
            (mid - glam::Vec3::new(0.5, 0.0, 0.5)).length() < 1e-6,
            "{mid}"
        );
        let edge = t.sample(glam::Vec2::new(0.0, 0.5));
        assert!(
            (edge - glam::Vec3::new(0.5, 0.0, 0.5)).length() < 1e-6,
            "{edge}"
        );
        let at = t.sample(glam::Vec2::new(1.25, 7.5));
        assert!((at - glam::Vec3::X).length() < 1e-6, "{at}");
        assert!((srgb_to_linear(128) - 0.2158605).abs() < 1e-6);
    }

    #[test]
    fn bad_images_get_a_phrase() {
        let limit = roomy();
        assert_eq!(
            decode_texture("x", b"not an image", &limit)
                .err()
                .as_deref(),
            Some(NOT_AN_IMAGE)
        );
        let e = decode_texture("x.tga", b"", &limit).expect_err("no header");
        assert!(
            e.starts_with("cannot read its size"),
            "an empty `.tga` is read as TGA and refused for its missing header: {e}"
        );
        let bytes = png(4, 4, &[7; 48]);
        let e = decode_texture("x", &bytes[..bytes.len() / 2], &limit).expect_err("truncated");
        assert!(e.starts_with("cannot decode it"), "{e}");
        let small = MemoryLimit {
            bytes: 100,
            source: "a test".into(),
        };
        let e = decode_texture("x", &bytes, &small).expect_err("over budget");
        assert!(e.contains("its 4x4 texels would need about"), "{e}");
    }

    #[test]
    fn jpegs_cut_short_are_refused() {
        let mut jpeg = Vec::new();
        image::RgbImage::from_pixel(16, 16, image::Rgb([200, 100, 50]))
            .write_to(&mut Cursor::new(&mut jpeg), image::ImageFormat::Jpeg)
            .expect("encodes");
        let t = decode_texture("x.jpg", &jpeg, &roomy()).expect("a whole JPEG decodes");
        assert_eq!((t.width, t.height), (16, 16));
        // Appended bytes after the end marker are harmless.
        let mut longer = jpeg.clone();
        longer.extend_from_slice(b"trailing");
        assert!(decode_texture("x.jpg", &longer, &roomy()).is_ok());
        let e = decode_texture("x.jpg", &jpeg[..jpeg.len() - 40], &roomy()).expect_err("cut short");
        assert_eq!(
            e,
            "it is cut short (a JPEG without its end-of-image marker)"
        );
    }

    fn tga_bytes(image: image::DynamicImage) -> Vec<u8> {
        let mut bytes = Vec::new();
        image
            .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Tga)
            .expect("encodes");
        bytes
    }

    /// The formats real models name besides PNG and JPEG (Sponza's TGA, old exports' BMP,
    /// Blender's and 3ds Max's TIFF, old models' GIF) decode to the same linear texels as the
    /// PNG of the image.
    #[test]
    fn tga_bmp_tiff_and_gif_decode_like_png() {
        let rgb = [255, 0, 0, 0, 128, 255, 10, 20, 30, 255, 255, 255];
        let image = image::RgbImage::from_raw(2, 2, rgb.to_vec()).expect("2x2");
        let reference = decode_texture("t.png", &png(2, 2, &rgb), &roomy()).expect("png");
        for (name, format) in [
            ("t.tga", image::ImageFormat::Tga),
            ("T.TGA", image::ImageFormat::Tga),
            ("t.bmp", image::ImageFormat::Bmp),
            ("t.tif", image::ImageFormat::Tiff),
            ("t.gif", image::ImageFormat::Gif),
        ] {
            let mut bytes = Vec::new();
            image
                .write_to(&mut Cursor::new(&mut bytes), format)
                .expect("encodes");
            let t =
                decode_texture(name, &bytes, &roomy()).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!((t.width, t.height), (2, 2), "{name}");
            assert_eq!(t.texels, reference.texels, "{name}");
        }
        // A TGA under another name (an exporter's `.png`) is known by its header, raw or
        // run-length encoded, grey or colour.
        for (what, bytes) in [
            (
                "raw colour",
                tga_bytes(image::DynamicImage::ImageRgb8(image.clone())),
            ),
            (
                "grey",
                tga_bytes(image::DynamicImage::ImageLuma8(
                    image::DynamicImage::ImageRgb8(image.clone()).to_luma8(),
                )),
            ),
        ] {
            let t = decode_texture("t.png", &bytes, &roomy())
                .unwrap_or_else(|e| panic!("{what} TGA named .png: {e}"));
            assert_eq!((t.width, t.height), (2, 2), "{what}");
            if what == "raw colour" {
                assert_eq!(t.texels, reference.texels, "{what}");
            }
        }
        // Text, an empty file and a header of a type TGA does not have are not images.
        let mut not_tga = tga_bytes(image::DynamicImage::ImageRgb8(image.clone()));
        not_tga[2] = 4;
        for (what, bytes) in [
            ("text", b"newmtl a\nKd 1 1 1\nmap_Kd a.png\n".to_vec()),
            ("empty", Vec::new()),
            ("image type 4", not_tga),
        ] {
            assert_eq!(
                decode_texture("t.png", &bytes, &roomy()).err().as_deref(),
                Some(NOT_AN_IMAGE),
                "{what}"
            );
        }
    }
}
