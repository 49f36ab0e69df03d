//! The crate's one seeded random number generator, for the stability sweeps, the procedural
//! meshes and every test that needs random cases: PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient Statistically Good
//! Algorithms for Random Number Generation"), XSH-RR output. Not cryptographic; the point is
//! that every sweep replays exactly from its seed on every machine.

use glam::Vec3;

/// PCG32 with the reference multiplier and increment.
#[derive(Clone, Debug)]
pub struct Pcg(u64);

const MULTIPLIER: u64 = 6364136223846793005;
const INCREMENT: u64 = 1442695040888963407;

impl Pcg {
    pub fn new(seed: u64) -> Self {
        let mut p = Pcg(seed.wrapping_mul(MULTIPLIER).wrapping_add(INCREMENT));
        p.next_u32();
        p
    }

    pub fn next_u32(&mut self) -> u32 {
        let old = self.0;
        self.0 = old.wrapping_mul(MULTIPLIER).wrapping_add(INCREMENT);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in `[0, 1)`, 24 random bits.
    pub fn f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f32()
    }

    /// Uniform in `0..n` (`n > 0`; the modulo bias is irrelevant for test inputs).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u32() as usize) % n
    }

    /// A uniformly distributed unit vector (rejection sampling in the unit ball).
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let l = v.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }

    /// Uniform in the box `[lo, hi)`.
    pub fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        Vec3::new(
            self.range(lo.x, hi.x),
            self.range(lo.y, hi.y),
            self.range(lo.z, hi.z),
        )
    }

    /// A unit vector perpendicular to the unit vector `a`, random about it.
    pub fn perpendicular(&mut self, a: Vec3) -> Vec3 {
        loop {
            let v = self.unit();
            let p = v - a * a.dot(v);
            if p.length() > 0.1 {
                return p.normalize();
            }
        }
    }
}

/// Numbers in `[0, 1)` from a generator started at `seed`, as a closure (for tests that draw
/// many coordinates inline).
pub fn uniform(seed: u64) -> impl FnMut() -> f32 {
    let mut pcg = Pcg::new(seed);
    move || pcg.f32()
}

/// Numbers in `[−1, 1)` from a generator started at `seed`, as a closure.
pub fn signed(seed: u64) -> impl FnMut() -> f32 {
    let mut pcg = Pcg::new(seed);
    move || pcg.range(-1.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replays_from_the_seed_and_stays_in_range() {
        let (mut a, mut b) = (Pcg::new(42), Pcg::new(42));
        for _ in 0..1000 {
            assert_eq!(a.next_u32(), b.next_u32());
            let x = a.f32();
            assert!((0.0..1.0).contains(&x));
            b.f32();
            let u = a.unit();
            assert!((u.length() - 1.0).abs() < 1e-6);
            let p = a.perpendicular(u);
            assert!(p.dot(u).abs() < 1e-5 && (p.length() - 1.0).abs() < 1e-6);
            b.unit();
            b.perpendicular(u);
        }
        assert_ne!(Pcg::new(1).next_u32(), Pcg::new(2).next_u32());
    }
}
