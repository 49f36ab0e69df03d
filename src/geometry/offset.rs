//! Where secondary rays start: the hit point pushed off the surface so the new ray does not
//! hit the surface it leaves (Ray Tracing Gems ch. 6; pbrt-v4 error bounds).
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// How secondary ray origins are moved off the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
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

/// The origin for a ray leaving point `p` (absolute error `p_error` per axis) of a surface with
/// unit geometric normal `n`, in direction `dir`: moved to the side `dir` goes to.
pub fn offset_ray_origin(
    _method: OffsetMethod,
    _p: Vec3,
    _p_error: Vec3,
    _n: Vec3,
    _dir: Vec3,
) -> Vec3 {
    todo!()
}
