//! Ray/sphere intersection: the lecture's quadratic (section "Ray/Sphere Intersection") and the
//! robust form of Ray Tracing Gems ch. 7 (Haines, Günther, Akenine-Möller: "Precision
//! Improvements for Ray/Sphere Intersection"), plus the hit point with an error bound
//! (pbrt-v4, "Bounding Intersection Point Error").
//!
//! Where the lecture's formula fails (docs/stability.md, rows S1, S2): `(u·ΔP)² − |ΔP|² + r²`
//! subtracts two numbers of size `D²` (D = distance from the ray origin to the centre) to find one
//! of size `r²`, so once `D/r` passes about `1e3…1e4` in `f32` the discriminant is rounding noise:
//! rays that miss are reported as hits and rays that hit are lost. The robust form takes the
//! discriminant as `r² − |f + b·u|²` (Hearn–Baker: the squared distance from the centre to the
//! ray's closest point, computed without cancellation) and picks the root pair without subtracting
//! nearly equal numbers.
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use super::{Ray, gamma};

/// How rays meet spheres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SphereMethod {
    /// The lecture's `s = u·ΔP ± sqrt((u·ΔP)² − |ΔP|² + r²)`, nearest root above `t_min`.
    Lecture,
    /// Ray Tracing Gems ch. 7 (Hearn–Baker discriminant, stable root pair) with the hit point
    /// re-projected onto the sphere.
    #[default]
    Robust,
}

crate::choice::choice!(SphereMethod {
    Robust => ("robust", "Ray Tracing Gems ch. 7: stable roots, hit point re-projected"),
    Lecture => ("lecture", "the lecture's quadratic (misses far-away spheres)"),
});

/// Nearest `t` in `(t_min, t_max)` where the ray meets the sphere, if any.
///
/// The near root is taken when it lies above `t_min`; otherwise the far root (the ray starts
/// inside the sphere, e.g. after refraction). The result never depends on `t_max` other than
/// through the final range check, so accelerators that shrink `t_max` see the same `t`.
#[inline(always)]
pub fn intersect_sphere(
    method: SphereMethod,
    center: Vec3,
    radius: f32,
    ray: &Ray,
    t_min: f32,
    t_max: f32,
) -> Option<f32> {
    let (t0, t1) = match method {
        SphereMethod::Lecture => lecture_roots(center, radius, ray)?,
        SphereMethod::Robust => robust_roots(center, radius, ray)?,
    };
    pick_root(t0, t1, t_min, t_max)
}

/// The lecture, literally: `ΔP = C − P0`, `s = u·ΔP ± sqrt((u·ΔP)² − |ΔP|² + r²)`.
#[inline]
fn lecture_roots(center: Vec3, radius: f32, ray: &Ray) -> Option<(f32, f32)> {
    let dp = center - ray.origin;
    let b = ray.dir.dot(dp);
    let disc = b * b - dp.dot(dp) + radius * radius;
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some((b - s, b + s))
}

/// Ray Tracing Gems ch. 7: `f = P0 − C`, `b = −f·u / (u·u)`, `Δ = r² − |f + b·u|²`,
/// `q = b·a + sign(b)·sqrt(a·Δ)`, roots `c/q` and `q/a` with `c = |f|² − r²`.
///
/// `a = u·u` is kept (it is `1 ± 2⁻²³` for a normalised `f32` direction) so the roots stay
/// within a few ulp of the exact roots of the `f32` ray, not of an idealised unit ray.
#[inline(always)]
fn robust_roots(center: Vec3, radius: f32, ray: &Ray) -> Option<(f32, f32)> {
    let u = ray.dir;
    let f = ray.origin - center;
    let a = u.dot(u);
    let b_prime = -f.dot(u);
    let r2 = radius * radius;
    // Hearn–Baker: the vector from the centre to the point of the ray closest to it.
    let l = f + (b_prime / a) * u;
    let disc = r2 - l.dot(l);
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let c = f.dot(f) - r2;
    let q = b_prime + (a * disc).sqrt().copysign(b_prime);
    if q == 0.0 {
        // b' = 0 and Δ = 0: the origin is the tangent point itself; both roots are 0.
        return Some((0.0, 0.0));
    }
    let t0 = c / q;
    let t1 = q / a;
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// The nearest of `t0 ≤ t1` strictly inside `(t_min, t_max)`.
#[inline(always)]
fn pick_root(t0: f32, t1: f32, t_min: f32, t_max: f32) -> Option<f32> {
    if t0 > t_min {
        (t0 < t_max).then_some(t0)
    } else if t1 > t_min && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// The hit point at `t` and a per-axis bound on its absolute error (for ray-origin offsets).
///
/// - `Lecture`: `ray.at(t)`. The bound covers the rounding of `P0 + t·u` *and* the error of
///   `t` itself as the lecture's formula computes it (first-order propagation of the rounding
///   in `u·ΔP`, `|ΔP|²` and the square root), so it grows like `D²·ε/sqrt(disc)`: honest,
///   and large exactly where the lecture's method is inaccurate.
/// - `Robust`: the point re-projected onto the sphere relative to its centre,
///   `C + r·(P − C)/|P − C|` (pbrt-v4; evaluated in `f64`, rounded once), with pbrt's error
///   bound `γ(5)·|P − C| + γ(1)·|P|` per axis (the re-projection plus the rounding of adding
///   `C`), which is conservative for the `f64` evaluation.
#[inline(always)]
pub fn sphere_hit_point(
    method: SphereMethod,
    center: Vec3,
    radius: f32,
    ray: &Ray,
    t: f32,
) -> (Vec3, Vec3) {
    match method {
        SphereMethod::Lecture => {
            let p = ray.at(t);
            let dp = center - ray.origin;
            let b = ray.dir.dot(dp);
            let dp2 = dp.dot(dp);
            let disc = (b * b - dp2 + radius * radius).max(0.0);
            // Absolute error of the computed discriminant is about γ(4)·|ΔP|²; the square root
            // turns it into γ(4)·|ΔP|²/(2·sqrt(disc)), but never more than sqrt(γ(4))·|ΔP|.
            let disc_err = gamma(4) * dp2;
            let sqrt_err = if disc > disc_err {
                disc_err / (2.0 * disc.sqrt())
            } else {
                disc_err.sqrt()
            };
            let t_err = gamma(3) * b.abs() + sqrt_err;
            let err = gamma(2) * (ray.origin.abs() + (t * ray.dir).abs()) + t_err * ray.dir.abs();
            (p, err)
        }
        SphereMethod::Robust => {
            // Re-projection in f64: `P − C` of two f32 is exact there, and the only rounding
            // left is the final one to f32 (half an ulp per axis), so the point is within
            // about one ulp of the sphere (the target of docs/stability.md, row S2, is 2 ulp).
            // Once per shading point, not per intersection test, so the cost does not matter.
            let c = DVec3::from(center);
            let v = DVec3::from(ray.at(t)) - c;
            let len = v.length();
            let local = if len > 0.0 && len.is_finite() {
                v * (f64::from(radius) / len)
            } else {
                // Only for a degenerate input (t far off, or radius 0): keep the computed point.
                v
            };
            let p = (c + local).as_vec3();
            let err = gamma(5) * local.as_vec3().abs() + gamma(1) * p.abs();
            (p, err)
        }
    }
}

/// Exact-as-possible `f64` replay of the ray/sphere test on the same `f32` inputs, used by the
/// stability tests and sweeps as the oracle: the roots of `|o + t·u − c|² = r²` (with `u`
/// as given, not re-normalised) in double precision, Hearn–Baker form.
pub fn sphere_roots_f64(center: Vec3, radius: f32, ray: &Ray) -> Option<(f64, f64)> {
    let u = DVec3::from(ray.dir);
    let f = DVec3::from(ray.origin) - DVec3::from(center);
    let r = f64::from(radius);
    let a = u.dot(u);
    let b = -f.dot(u);
    let l = f + (b / a) * u;
    let disc = r * r - l.dot(l);
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let c = f.dot(f) - r * r;
    let q = b + (a * disc).sqrt().copysign(b);
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (t0, t1) = (c / q, q / a);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}
