//! Where secondary rays start: the hit point pushed off the surface so the new ray does not
//! hit the surface it leaves (Ray Tracing Gems ch. 6; pbrt-v4 error bounds, "Robust Spawned
//! Ray Origins").
//!
//! Where the naive offsets fail (docs/stability.md, rows A1–A3): a fixed distance is below the
//! spacing of `f32` values once coordinates reach about `1e3`, so the origin rounds back onto the
//! surface and shadow rays hit it (acne); and it is larger than the whole scene at small scales, so
//! shadow rays jump over nearby occluders (light leaks at contacts). Scaling by the magnitude of
//! the point fixes the first but keeps a floor of 1. The error-bound offset moves the origin
//! exactly as far as the hit point's computed error along the normal, then one `f32` step further,
//! so it is outside the surface's uncertainty at every scale and no further.
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{next_float_down, next_float_up};

/// How secondary ray origins are moved off the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OffsetMethod {
    /// A fixed distance along the normal, whatever the scene's scale.
    Fixed,
    /// A distance along the normal scaled by the magnitude of the hit point's coordinates.
    NormalScaled,
    /// pbrt-v4: the hit point's error bound projected on the normal, then rounded outwards.
    #[default]
    ErrorBound,
}

crate::choice::choice!(OffsetMethod {
    ErrorBound => ("error-bound", "pbrt-v4: the hit point's error bound along the normal (robust at any scale)"),
    NormalScaled => ("normal-scaled", "a distance along the normal scaled by the hit point's magnitude"),
    Fixed => ("fixed", "the textbook fixed 1e-4 along the normal (acne on large scenes)"),
});

/// [`OffsetMethod::Fixed`]: the textbook `1e-4` (world units). Right for scenes of size about
/// 1 centred near the origin; below one `f32` step of the coordinates from `|p| ≈ 1e3` on
/// (ulp(1024) = 1.2e-4), so large scenes get acne; larger than the features of scenes of size
/// `1e-3`, so contact shadows leak there.
pub const FIXED_OFFSET: f32 = 1e-4;

/// [`OffsetMethod::NormalScaled`]: offset `= NORMAL_SCALED_EPSILON · max(1, max_i |p_i|)`.
///
/// `1e-5` relative is about 84 ulp of the largest coordinate: 20× the hit-point error bound
/// of a triangle (`γ(7) ≈ 4.2e-7` relative) and of a re-projected sphere point, so it clears
/// the surface's rounding at any scale, while staying 10× below `1e-4` to keep contact-shadow
/// leaks small. The `max(1, ·)` floor makes it an absolute `1e-5` below scale 1, so it is too
/// large for scenes of size `1e-3` and smaller (the documented failure).
pub const NORMAL_SCALED_EPSILON: f32 = 1e-5;

/// The origin for a ray leaving point `p` (absolute error `p_error` per axis) of a surface with
/// unit geometric normal `n`, in direction `dir`: moved to the side `dir` goes to.
///
/// With [`OffsetMethod::ErrorBound`] the new ray is meant to be traced with `t_min = 0`
/// (exclusive): the origin is already outside the surface's error region.
#[inline(always)]
pub fn offset_ray_origin(method: OffsetMethod, p: Vec3, p_error: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    // The side of the surface the new ray travels to (tangent rays go to the +n side).
    let n_out = if dir.dot(n) < 0.0 { -n } else { n };
    match method {
        OffsetMethod::Fixed => p + FIXED_OFFSET * n_out,
        OffsetMethod::NormalScaled => {
            let scale = p.abs().max_element().max(1.0);
            p + (NORMAL_SCALED_EPSILON * scale) * n_out
        }
        OffsetMethod::ErrorBound => {
            // pbrt-v4 OffsetRayOrigin: distance to the error box's face along n, d = |n|·err.
            let d = n.abs().dot(p_error);
            let offset = d * n_out;
            let mut po = p + offset;
            // Round away from p so the addition's own rounding cannot pull the origin back.
            for i in 0..3 {
                if offset[i] > 0.0 {
                    po[i] = next_float_up(po[i]);
                } else if offset[i] < 0.0 {
                    po[i] = next_float_down(po[i]);
                }
            }
            po
        }
    }
}
