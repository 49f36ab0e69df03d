//! Seeded numbers for the unit tests: a 32-bit xorshift generator, so a failing case comes out
//! the same on every run and every machine.

/// Numbers in `[0, 1]` from the generator started at `seed` (not 0).
pub fn uniform(mut seed: u32) -> impl FnMut() -> f32 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    }
}

/// Numbers in `[−1, 1]`: [`uniform`]'s, times 2, minus 1.
pub fn signed(seed: u32) -> impl FnMut() -> f32 {
    let mut unit = uniform(seed);
    move || unit() * 2.0 - 1.0
}
