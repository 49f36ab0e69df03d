//! Ray/triangle intersection: the lecture's plane-then-barycentric method, Möller–Trumbore and
//! the watertight test of Woop, Benthin and Wald (2013).
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::Ray;

/// How rays meet triangles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum TriangleMethod {
    /// The lecture: intersect the plane `n·p = d`, then solve for barycentric coordinates.
    Lecture,
    /// Möller–Trumbore (1997).
    MollerTrumbore,
    /// Woop, Benthin, Wald (2013): no cracks along shared edges and vertices.
    #[default]
    Watertight,
}

/// A ray/triangle hit: `t` and the barycentric weights of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Nearest hit in `(t_min, t_max)` of the ray with triangle `v` (both faces), if any.
pub fn intersect_triangle(
    _method: TriangleMethod,
    _v: &[Vec3; 3],
    _ray: &Ray,
    _t_min: f32,
    _t_max: f32,
) -> Option<TriHit> {
    todo!()
}

/// The point with barycentric weights `(1 − b1 − b2, b1, b2)` and a per-axis bound on its
/// absolute error.
pub fn triangle_hit_point(_v: &[Vec3; 3], _b1: f32, _b2: f32) -> (Vec3, Vec3) {
    todo!()
}
