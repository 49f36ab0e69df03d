//! Image error against a reference: mean FLIP (Andersson et al. 2020, "FLIP: A Difference
//! Evaluator for Alternating Images", through `nv-flip` on 8-bit sRGB, the viewer's display
//! encoding), RMSE and PSNR on the linear values, and the share of pixels that differ at all
//! in 8-bit sRGB. Exact pixel equality ([`differing_pixels`]) is how "the accelerator must not
//! change the image" is checked.

use serde::{Deserialize, Serialize};

use crate::export::srgb8_bytes;
use crate::render::Image;

/// How far an image is from its reference.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ImageError {
    /// Mean of FLIP's per-pixel error map (0 = identical, 1 = maximal), at
    /// `nv_flip::DEFAULT_PIXELS_PER_DEGREE` (67: a 0.7 m viewing distance from a 1080p
    /// monitor about 0.7 m wide).
    pub mean_flip: f64,
    /// Root mean square of the linear RGB differences over all channels.
    pub rmse: f64,
    /// `10·log10(1 / rmse²)`, peak 1 (linear white); `inf` for identical images.
    pub psnr_db: f64,
    /// Share of pixels whose 8-bit sRGB value differs in any channel, `0..=1`.
    pub differing_share: f64,
}

/// All four measures of `test` against `reference` (same size).
///
/// # Panics
/// If the sizes differ: comparing images of different sizes is a bug of the caller.
pub fn image_error(reference: &Image, test: &Image) -> ImageError {
    assert_eq!(
        (reference.width, reference.height),
        (test.width, test.height),
        "image_error needs images of the same size"
    );
    let ref8 = srgb8_bytes(reference);
    let test8 = srgb8_bytes(test);
    let rmse = rmse(reference, test);
    let pixels = (reference.width as usize * reference.height as usize).max(1);
    let differing = ref8
        .chunks_exact(3)
        .zip(test8.chunks_exact(3))
        .filter(|(a, b)| a != b)
        .count();
    ImageError {
        mean_flip: mean_flip_srgb8(reference.width, reference.height, &ref8, &test8),
        rmse,
        psnr_db: psnr_db(rmse),
        differing_share: differing as f64 / pixels as f64,
    }
}

/// Mean FLIP of two 8-bit sRGB RGB images of `width × height`.
pub fn mean_flip_srgb8(width: u32, height: u32, reference: &[u8], test: &[u8]) -> f64 {
    if width == 0 || height == 0 {
        return 0.0;
    }
    let r = nv_flip::FlipImageRgb8::with_data(width, height, reference);
    let t = nv_flip::FlipImageRgb8::with_data(width, height, test);
    let map = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let values = map.to_vec();
    values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len().max(1) as f64
}

/// RMSE of the linear values over all channels. A non-finite difference (a NaN pixel) counts
/// as an error of 1 in that channel, so a broken pixel is visible rather than poisoning the
/// mean.
pub fn rmse(a: &Image, b: &Image) -> f64 {
    let mut sum = 0.0f64;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let d = f64::from(p[c]) - f64::from(q[c]);
            sum += if d.is_finite() { d * d } else { 1.0 };
        }
    }
    (sum / (3 * a.pixels.len().max(1)) as f64).sqrt()
}

/// PSNR in dB for a linear peak of 1.
pub fn psnr_db(rmse: f64) -> f64 {
    if rmse == 0.0 {
        f64::INFINITY
    } else {
        -20.0 * rmse.log10()
    }
}

/// Pixels whose linear values are not bit-identical (NaN counts as differing).
pub fn differing_pixels(a: &Image, b: &Image) -> usize {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.to_array().map(f32::to_bits) != q.to_array().map(f32::to_bits))
        .count()
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3) -> Image {
        let mut img = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                img.pixels[(y * w + x) as usize] = f(x, y);
            }
        }
        img
    }

    #[test]
    fn identical_images_have_no_error() {
        let a = image(16, 8, |x, y| {
            Vec3::new(x as f32 / 16.0, y as f32 / 8.0, 0.3)
        });
        let e = image_error(&a, &a);
        assert_eq!((e.mean_flip, e.rmse, e.differing_share), (0.0, 0.0, 0.0));
        assert!(e.psnr_db.is_infinite());
        assert_eq!(differing_pixels(&a, &a), 0);
    }

    #[test]
    fn a_changed_block_is_measured() {
        let a = image(32, 32, |_, _| Vec3::splat(0.2));
        let b = image(32, 32, |x, y| {
            if x < 8 && y < 8 {
                Vec3::splat(0.8)
            } else {
                Vec3::splat(0.2)
            }
        });
        let e = image_error(&a, &b);
        assert_eq!(e.differing_share, 64.0 / 1024.0);
        assert!((e.rmse - (0.36f64 * 64.0 / 1024.0).sqrt()).abs() < 1e-6);
        assert!(e.mean_flip > 0.01 && e.mean_flip < 0.2, "{}", e.mean_flip);
        assert!((e.psnr_db - psnr_db(e.rmse)).abs() < 1e-12);
        assert_eq!(differing_pixels(&a, &b), 64);
        let mut c = a.clone();
        c.pixels[0] = Vec3::NAN;
        assert_eq!(differing_pixels(&a, &c), 1);
        assert!(rmse(&a, &c).is_finite());
    }
}
