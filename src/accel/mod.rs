//! Acceleration structures behind one type: none (test every primitive), a uniform grid with
//! 3D-DDA traversal (the lecture's "spatial subdivision") and a BVH built with `obvhs`
//! (the lecture's "BVH"). All answer the same two queries, closest hit and occlusion, and give
//! the identical answer: the nearest `t`, ties broken by the lower primitive id.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::geometry::{Methods, Ray};

/// Which accelerator to build. `Auto` picks from the scene's size.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum AccelKind {
    #[default]
    Auto,
    None,
    Grid,
    Bvh,
}

/// Geometry the accelerators see. Primitive ids: spheres are `0..spheres.len()`, triangles
/// follow, so id `spheres.len() + i` is triangle `i`.
#[derive(Clone, Debug, Default)]
pub struct PrimSet {
    /// (centre, radius) per sphere.
    pub spheres: Vec<(Vec3, f32)>,
    pub triangles: Vec<[Vec3; 3]>,
}

/// A closest hit: the parameter along the ray, the primitive id and, for triangles, the
/// barycentric weights of vertices 1 and 2 (vertex 0 has `1 − b1 − b2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimHit {
    pub t: f32,
    pub prim: u32,
    pub b1: f32,
    pub b2: f32,
}

pub struct Accel {
    _todo: (),
}

impl Accel {
    pub fn build(_kind: AccelKind, _prims: &PrimSet) -> Accel {
        todo!()
    }
    pub fn closest_hit(&self, _m: &Methods, _ray: &Ray, _t_min: f32, _t_max: f32) -> Option<PrimHit> {
        todo!()
    }
    pub fn occluded(&self, _m: &Methods, _ray: &Ray, _t_min: f32, _t_max: f32) -> bool {
        todo!()
    }
}
impl Accel {
    pub fn kind(&self) -> AccelKind {
        todo!()
    }
}
