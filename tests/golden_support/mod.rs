//! Golden images shared by the tests that keep them (`tests/render.rs`, `tests/scene_view.rs`):
//! where they live, how they are read, and the one tolerance they are compared with.

use std::path::{Path, PathBuf};

/// `tests/golden/FILE`.
pub fn golden_path(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(file)
}

/// Width, height and 8-bit samples of the PNG at `path`, which must be of `color`; a missing
/// golden says how to `regenerate` it.
pub fn read_png(path: &Path, color: png::ColorType, regenerate: &str) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}; regenerate with {regenerate}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("PNG header");
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut buf).expect("PNG data");
    assert_eq!(info.color_type, color, "{}", path.display());
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// `got` against `want` (`channels` samples a pixel): `None` within the tolerance, else why.
/// Tolerance: a channel may differ by more than 2/255 on at most 0.5 % of pixels (a libm's
/// rounding can flip a shadow-edge pixel or move a drawn line's end by one), and the mean
/// absolute difference stays below 0.25/255.
pub fn mismatch(got: &[u8], want: &[u8], channels: usize) -> Option<String> {
    let mut off_pixels = 0usize;
    let mut total = 0u64;
    for (a, b) in got.chunks(channels).zip(want.chunks(channels)) {
        let d: Vec<u8> = a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).collect();
        total += d.iter().map(|&x| u64::from(x)).sum::<u64>();
        if d.iter().any(|&x| x > 2) {
            off_pixels += 1;
        }
    }
    let n = (want.len() / channels) as f64;
    let mean = total as f64 / (channels as f64 * n);
    (off_pixels as f64 > 0.005 * n || mean > 0.25).then(|| {
        format!("{off_pixels} pixels off by more than 2/255, mean difference {mean:.3}/255")
    })
}
