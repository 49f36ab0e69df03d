//! What to load: one mesh of a scene, with its file, its material override, how its normals are
//! made, and where it goes (scale, rotation, translation).

use glam::{Mat3, Vec3};

use crate::scene::resolve::{ResolveBytesFn, ResolveFn};
use crate::scene::{MaterialId, NormalsMode, ObjectId};

/// Where a mesh goes: `scale` first, then the rotation (degrees about X, then Y, then Z), then
/// `translate`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshPlacement {
    pub translate: Vec3,
    pub rotate_deg: Vec3,
    pub scale: Vec3,
}

impl Default for MeshPlacement {
    fn default() -> Self {
        Self {
            translate: Vec3::ZERO,
            rotate_deg: Vec3::ZERO,
            scale: Vec3::ONE,
        }
    }
}

impl MeshPlacement {
    /// The linear part, `Rz · Ry · Rx · S`, so X is applied first.
    pub fn linear(&self) -> Mat3 {
        let r = self.rotate_deg;
        Mat3::from_rotation_z(r.z.to_radians())
            * Mat3::from_rotation_y(r.y.to_radians())
            * Mat3::from_rotation_x(r.x.to_radians())
            * Mat3::from_diagonal(self.scale)
    }

    /// A mirroring scale turns counter-clockwise faces clockwise; the loader then swaps two
    /// corners so that the front still faces outside.
    pub fn mirrors(&self) -> bool {
        self.scale.x * self.scale.y * self.scale.z < 0.0
    }
}

/// One mesh to add to a scene.
pub(crate) struct MeshRequest<'a> {
    /// The object its triangles belong to (already in `scene.objects`).
    pub object: ObjectId,
    /// Prefix of its MTL materials' names: `<object name>/<mtl name>`.
    pub object_name: &'a str,
    /// What to call the file in warnings.
    pub label: &'a str,
    /// The path to give the resolver for the OBJ; MTL paths are relative to its folder.
    pub key: &'a str,
    pub text: &'a str,
    pub resolve: &'a ResolveFn<'a>,
    /// Reads textures (binary), relative to the same folder as `resolve`.
    pub resolve_bytes: &'a ResolveBytesFn<'a>,
    /// A scene material for every face instead of the MTL's.
    pub material_override: Option<MaterialId>,
    pub placement: &'a MeshPlacement,
    /// Where shading normals come from.
    pub normals: NormalsMode,
    /// Faces meeting at more than this (degrees) keep apart normals, for `Smooth`.
    pub crease_angle_deg: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placement_scales_then_rotates_x_y_z_then_translates() {
        let p = MeshPlacement {
            translate: Vec3::new(10.0, 0.0, 0.0),
            rotate_deg: Vec3::new(90.0, 90.0, 0.0),
            scale: Vec3::splat(2.0),
        };
        // (0,1,0) ·2 → (0,2,0); X 90° → (0,0,2); Y 90° → (2,0,0); + (10,0,0).
        let v = p.linear() * Vec3::Y + p.translate;
        assert!(v.abs_diff_eq(Vec3::new(12.0, 0.0, 0.0), 1e-5), "{v}");
    }
}
