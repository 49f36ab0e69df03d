//! Where each sample of a pixel looks. Sample 0 is the pixel centre (so a 1-sample render and
//! a clicked pixel's tree agree); samples 1, 2, … follow the R2 low-discrepancy sequence
//! (Roberts 2018), rotated per pixel by a hash of its coordinates so neighbouring pixels do not
//! share a pattern. Everything depends only on (x, y, sample index): never on threads or order.

/// Offset inside the pixel, in `[0, 1)²`, of sample `index` of pixel (`x`, `y`).
pub fn sample_offset(x: u32, y: u32, index: u32) -> (f32, f32) {
    if index == 0 {
        return (0.5, 0.5);
    }
    // R2: the generalised golden ratio φ₂ (root of x³ = x + 1); α = (1/φ₂, 1/φ₂²).
    const A1: f64 = 0.754_877_666_246_692_7;
    const A2: f64 = 0.569_840_290_998_053_2;
    let h = hash2(x, y);
    let rot1 = (h & 0xffff) as f64 / 65536.0;
    let rot2 = (h >> 16) as f64 / 65536.0;
    let k = index as f64;
    let u = (0.5 + rot1 + k * A1).fract();
    let v = (0.5 + rot2 + k * A2).fract();
    // f64 → f32 may round up to 1.0; keep the offset inside the pixel.
    (
        (u as f32).min(1.0 - f32::EPSILON),
        (v as f32).min(1.0 - f32::EPSILON),
    )
}

/// A 32-bit integer hash of two coordinates (a PCG-style permutation).
fn hash2(x: u32, y: u32) -> u32 {
    let mut h = x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^ (h >> 16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_sample_is_centre() {
        assert_eq!(sample_offset(7, 9, 0), (0.5, 0.5));
    }

    #[test]
    fn samples_cover_the_pixel_evenly() {
        // 64 samples: every quarter of the pixel gets between 12 and 20 of them.
        let mut quads = [0u32; 4];
        for i in 0..64 {
            let (u, v) = sample_offset(3, 4, i);
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
            quads[(u >= 0.5) as usize + 2 * (v >= 0.5) as usize] += 1;
        }
        assert!(quads.iter().all(|&q| (12..=20).contains(&q)), "{quads:?}");
        assert_ne!(sample_offset(3, 4, 1), sample_offset(4, 3, 1));
    }
}
