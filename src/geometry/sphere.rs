//! Ray/sphere intersection: the lecture's quadratic and a robust form.
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::Ray;

/// How rays meet spheres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum SphereMethod {
    /// The lecture's `s = u·ΔP ± sqrt((u·ΔP)² − |ΔP|² + r²)`, nearest root above `t_min`.
    Lecture,
    /// Ray Tracing Gems ch. 7 (Hearn–Baker discriminant, stable root pair) with the hit point
    /// re-projected onto the sphere.
    #[default]
    Robust,
}

/// Nearest `t` in `(t_min, t_max)` where the ray meets the sphere, if any.
pub fn intersect_sphere(
    _method: SphereMethod,
    _center: Vec3,
    _radius: f32,
    _ray: &Ray,
    _t_min: f32,
    _t_max: f32,
) -> Option<f32> {
    todo!()
}

/// The hit point at `t` and a per-axis bound on its absolute error (for ray-origin offsets).
pub fn sphere_hit_point(
    _method: SphereMethod,
    _center: Vec3,
    _radius: f32,
    _ray: &Ray,
    _t: f32,
) -> (Vec3, Vec3) {
    todo!()
}
