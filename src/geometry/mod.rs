//! Rays, ray/primitive intersection methods and ray-origin offsets (lecture: "Ray/Surface
//! Intersection"; robust variants from Ray Tracing Gems ch. 6–7, Woop–Benthin–Wald 2013 and
//! pbrt-v4). Every method is selectable so the speed/accuracy sweeps can compare them. Also the
//! shading normals of triangles ([`shading`]) and the vertex normals of smooth meshes
//! ([`normals`]).

pub mod lanes;
pub mod normals;
pub mod offset;
pub mod shading;
pub mod sphere;
pub mod triangle;

use glam::Vec3;
use serde::{Deserialize, Serialize};

pub use normals::smooth_normals;
pub use offset::{OffsetMethod, offset_ray_origin};
pub use shading::{ShadingNormals, interpolate_normal, keep_side, terminator_origin};
pub use sphere::{SphereMethod, intersect_sphere, sphere_hit_point};
pub use triangle::{
    Shear, TriHit, TriHits4, TriangleMethod, Triangles4, intersect_triangle, intersect_triangles4,
    triangle_hit_point,
};

/// `P = origin + s·dir`, `dir` unit length, `s ≥ 0` (lecture: "Ray equation").
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    pub fn at(&self, s: f32) -> Vec3 {
        self.origin + s * self.dir
    }
}

/// The intersection methods a render uses, one flat struct (yocto-gl style).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Methods {
    pub sphere: SphereMethod,
    pub triangle: TriangleMethod,
    pub offset: OffsetMethod,
    /// Where shading and geometric normals disagree (docs/stability.md, rows N1–N3).
    #[serde(default)]
    pub shading_normals: ShadingNormals,
}

/// `γ(n) = n·u / (1 − n·u)` with `u` the f32 unit roundoff: bounds the relative error of `n`
/// chained f32 operations (pbrt-v4, "Floating-point arithmetic").
#[inline]
pub fn gamma(n: u32) -> f32 {
    let u = f32::EPSILON * 0.5;
    let nu = n as f32 * u;
    nu / (1.0 - nu)
}

/// The next representable `f32` above `v` (pbrt-v4 `NextFloatUp`): `+∞` and NaN stay put, `−0`
/// counts as `+0`, so the result is always strictly greater for finite input.
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_nan() || v == f32::INFINITY {
        return v;
    }
    // −0 and +0 both step to the smallest positive subnormal.
    let v = if v == 0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The next representable `f32` below `v` (pbrt-v4 `NextFloatDown`): `−∞` and NaN stay put,
/// `+0` counts as `−0`, so the result is always strictly smaller for finite input.
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_nan() || v == f32::NEG_INFINITY {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}
