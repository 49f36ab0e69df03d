//! Shading normals on flat triangles (docs/stability.md, rows N1–N3): the normal interpolated from
//! vertex normals with the hit's barycentric coordinates, and the three places where it and the
//! triangle's own (geometric) normal disagree.
//!
//! - N1, the shadow terminator (Hanika 2021, "Hacking the shadow terminator", Ray Tracing Gems
//!   II ch. 4): the shading normal says the light is in front, but the flat triangle lies below
//!   the smooth surface its normals describe, so the shadow ray from the flat point is blocked
//!   by the mesh itself and dark facets show near the terminator. The robust method starts the
//!   shadow ray from the point on the smooth surface: the hit point projected onto the tangent
//!   planes of the three vertices, blended with the barycentric weights ([`terminator_origin`]).
//! - N2: a direction reflected or refracted about the shading normal can cross the geometric
//!   plane into the surface it leaves; the robust method mirrors it back across that plane
//!   ([`keep_side`]).
//! - N3: a light that is behind the geometric surface but in front of the shading normal leaks
//!   through it; the robust method counts it only when a shadow ray from the smooth surface
//!   reaches it (see `trace`).

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::gamma;

/// How shading normals are used where they disagree with the geometric normal
/// (docs/stability.md, rows N1–N3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadingNormals {
    /// Shadow rays from the smooth surface (Hanika 2021), secondary directions kept on their
    /// side of the geometric plane, lights behind the geometric surface counted only when the
    /// smooth surface sees them.
    #[default]
    Robust,
    /// The textbook: the shading normal used as if it were the surface's, shadow rays from the
    /// flat hit point. Shows the terminator bands, directions into the surface and leaks.
    Naive,
}

crate::choice::choice!(ShadingNormals {
    Robust => ("robust", "shadow rays from the smooth surface (Hanika 2021), R/T kept on their side, no leaks"),
    Naive => ("naive", "shading normals used as the surface's: terminator bands, R/T into the surface, leaks"),
});

/// How far (relative to the coordinates' magnitude) the smooth-surface point must lie above
/// the triangle's plane for a shadow ray from it to a light *behind* the plane to be trusted:
/// `γ(64)`, about 9× the error of the `t` at which a grazing ray meets a neighbouring triangle
/// (`≈ γ(7)·|P| / |N·L|` against the true `lift / |N·L|`). Below it, the light counts as behind
/// the surface (docs/stability.md, row N3: a 0.5° grazing light otherwise leaked through a
/// flat wall).
pub const MIN_LIFT: f32 = 64.0 * f32::EPSILON * 0.5 / (1.0 - 64.0 * f32::EPSILON * 0.5);

/// The unit normal interpolated from vertex normals `n` with barycentric weights `b`, or `None`
/// when it has no direction (opposite normals cancelling, or non-finite input).
#[inline]
pub fn interpolate_normal(n: &[Vec3; 3], b: [f32; 3]) -> Option<Vec3> {
    let s = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
    let s = s.normalize_or_zero();
    (s != Vec3::ZERO).then_some(s)
}

/// Hanika (2021): the hit point `p` (barycentric weights `b` of triangle `v`) moved onto the smooth
/// surface described by the unit vertex normals `n`, all turned to the side the ray came from, and
/// `ng` the geometric normal on that side. Each vertex contributes `p` projected onto its tangent
/// plane when `p` lies below that plane (and `p` itself otherwise), weighted by `b`. Returns the
/// point and its absolute error bound per axis and whether it lies clearly above the triangle's
/// plane (by at least [`MIN_LIFT`] of the coordinates' magnitude: a ray from it that crosses the
/// plane at a grazing angle then meets the plane where `f32` can tell; below that it is as good as
/// on the flat triangle). `None` when the point does not move outside (where the flat triangle
/// already is the surface, or bulges above it), so the flat point is used.
#[inline]
pub fn terminator_origin(
    v: &[Vec3; 3],
    n: &[Vec3; 3],
    b: [f32; 3],
    p: Vec3,
    p_error: Vec3,
    ng: Vec3,
) -> Option<(Vec3, Vec3, bool)> {
    let mut lift = Vec3::ZERO;
    let mut scale = p.abs();
    for i in 0..3 {
        let below = (p - v[i]).dot(n[i]).min(0.0);
        lift -= (b[i] * below) * n[i];
        scale = scale.max(v[i].abs());
    }
    let p2 = p + lift;
    // NaN (a degenerate normal) counts as not moving out.
    if lift.dot(ng).is_nan() || lift.dot(ng) <= 0.0 || !p2.is_finite() {
        return None;
    }
    // Each `(p − v_i)·n_i` is a handful of roundings of numbers of size `scale`.
    let error = p_error + Vec3::splat(gamma(12)) * (scale + p2.abs());
    let clear = lift.dot(ng) > MIN_LIFT * scale.max_element();
    Some((p2, error, clear))
}

/// `dir` kept on the side of the geometric plane (unit normal `ng`) it must go to: `above`
/// true for reflections (the side `ng` points to), false for refractions. A direction on the
/// wrong side is mirrored across the plane (tangent ones tipped just off it). Returns the
/// direction and whether it was corrected.
#[inline]
pub fn keep_side(dir: Vec3, ng: Vec3, above: bool) -> (Vec3, bool) {
    let side = if above { ng } else { -ng };
    let c = dir.dot(side);
    if c > 0.0 {
        return (dir, false);
    }
    // Mirror the normal component (`−c` instead of `c`); at least a little of it, so that a
    // tangent direction leaves the plane.
    let lift = (-c).max(1e-4);
    let out = (dir - c * side + lift * side).normalize_or_zero();
    if out == Vec3::ZERO {
        return (side, true);
    }
    (out, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_unit_and_exact_at_vertices() {
        let n = [Vec3::X, Vec3::Y, Vec3::Z];
        assert_eq!(interpolate_normal(&n, [1.0, 0.0, 0.0]), Some(Vec3::X));
        let m = interpolate_normal(&n, [1.0 / 3.0; 3]).expect("a direction");
        assert!((m.length() - 1.0).abs() < 1e-6);
        assert_eq!(
            interpolate_normal(&[Vec3::X, -Vec3::X, Vec3::X], [0.5, 0.5, 0.0]),
            None
        );
    }

    #[test]
    fn directions_on_the_wrong_side_are_mirrored() {
        let ng = Vec3::Y;
        let (d, fixed) = keep_side(Vec3::new(1.0, 0.5, 0.0).normalize(), ng, true);
        assert!(!fixed && d.y > 0.0);
        let (d, fixed) = keep_side(Vec3::new(1.0, -0.5, 0.0).normalize(), ng, true);
        assert!(fixed && d.y > 0.0 && (d.length() - 1.0).abs() < 1e-6);
        assert!((d - Vec3::new(1.0, 0.5, 0.0).normalize()).length() < 1e-6);
        let (d, fixed) = keep_side(Vec3::X, ng, false);
        assert!(fixed && d.y < 0.0);
    }

    #[test]
    fn the_terminator_origin_lies_on_the_smooth_side() {
        // A triangle of a sphere of radius 1: its vertices on the sphere, normals radial.
        let v = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let n = v;
        let b = [1.0 / 3.0; 3];
        let p = b[0] * v[0] + b[1] * v[1] + b[2] * v[2];
        let (q, _, clear) =
            terminator_origin(&v, &n, b, p, Vec3::ZERO, Vec3::ONE.normalize()).expect("moves out");
        assert!(clear);
        assert!(q.length() > p.length(), "{q} further out than {p}");
        // Flat normals: the triangle is its own surface, nothing moves.
        let ng = Vec3::ONE.normalize();
        assert_eq!(terminator_origin(&v, &[ng; 3], b, p, Vec3::ZERO, ng), None);
    }
}
