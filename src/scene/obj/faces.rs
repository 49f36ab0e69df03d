//! Placing one model's faces: each face's corners transformed to the scene, the degenerate and
//! the too distant marked to be dropped (at load time, so the tracer never meets them), and
//! the indices of the normals and texture coordinates each face gives.

use glam::{Mat3, Vec2, Vec3};
use rayon::prelude::*;

use super::corners::{ALL_NORMALS, ALL_UVS};
use crate::scene::rules::{MAX_COORDINATE, is_visible_triangle};
use crate::scene::{MaterialId, NO_INDEX, ObjectId, Triangle};

/// One model's faces, to be placed in parallel: the model, the placement, and the mesh's
/// normals and texture coordinates so far with the index of this model's first (when its faces
/// give them).
pub(super) struct Faces<'a> {
    pub mesh: &'a tobj::Mesh,
    pub linear: Mat3,
    pub translate: Vec3,
    pub mirrors: bool,
    pub normals: Option<(&'a [Vec3], u32)>,
    pub uvs: Option<(&'a [Vec2], u32)>,
    /// The index of the model's first vertex colour in the mesh's, when it has colours.
    pub colors: Option<u32>,
}

/// The material of a placed triangle until its model's material is known.
pub(super) const PLACED: MaterialId = MaterialId(u32::MAX);
/// The material of a triangle to drop: zero area or not finite.
const DEGENERATE: MaterialId = MaterialId(u32::MAX - 1);
/// The material of a triangle to drop: beyond the scene-size limit.
const TOO_FAR: MaterialId = MaterialId(u32::MAX - 2);

impl Faces<'_> {
    /// Face `k` placed: its corners transformed (two swapped when the placement mirrors),
    /// marked [`PLACED`], [`DEGENERATE`] or [`TOO_FAR`] in place of its material.
    fn triangle(&self, k: usize, object: ObjectId) -> Triangle {
        let mesh = self.mesh;
        let corner = |index: u32| {
            let i = index as usize * 3;
            mesh.positions
                .get(i..i + 3)
                .map_or(Vec3::NAN, |p| Vec3::new(p[0], p[1], p[2]))
        };
        let face = &mesh.indices[3 * k..3 * k + 3];
        let mut v = [face[0], face[1], face[2]].map(|i| self.linear * corner(i) + self.translate);
        if self.mirrors {
            v.swap(1, 2);
        }
        let material = if !is_visible_triangle(&v) {
            DEGENERATE
        } else if v.iter().any(|p| p.abs().max_element() > MAX_COORDINATE) {
            TOO_FAR
        } else {
            PLACED
        };
        Triangle {
            vertices: v,
            material,
            object,
        }
    }

    /// The mesh's normal or texture-coordinate indices of face `k` (swapped as its corners),
    /// from `(the model's index list, the model's first in the mesh's list, how many the model
    /// has)`; [`NO_INDEX`]`× 3` when one is out of range or names a value that is not `usable`.
    fn corner_ids(
        &self,
        k: usize,
        (indices, base, count): (&[u32], u32, u32),
        usable: &(impl Fn(u32) -> bool + Sync),
    ) -> [u32; 3] {
        let Some(idx) = indices.get(3 * k..3 * k + 3) else {
            return [NO_INDEX; 3];
        };
        let mut idx = [idx[0], idx[1], idx[2]];
        if !idx.iter().all(|&i| i < count && usable(base + i)) {
            return [NO_INDEX; 3];
        }
        if self.mirrors {
            idx.swap(1, 2);
        }
        idx.map(|i| base + i)
    }
    /// Places the model's `count` faces in parallel, straight into `triangles` (the dropped
    /// ones marked, to be taken out by [`keep_placed`]): no per-thread lists, whose memory the
    /// allocator would keep after the load.
    pub(super) fn place(&self, triangles: &mut Vec<Triangle>, count: usize, object: ObjectId) {
        triangles.par_extend((0..count).into_par_iter().map(|k| self.triangle(k, object)));
    }

    /// The normal indices of the model's `count` faces (`NO_INDEX × 3` for a face that does not
    /// give `vn` at every corner, or gives an unusable one), or none when the model has none.
    pub(super) fn normal_ids(&self, count: usize, given: &Given) -> Vec<[u32; 3]> {
        let Some((normals, base)) = self.normals else {
            return Vec::new();
        };
        let usable = |i: u32| {
            let n = normals[i as usize];
            n.is_finite() && n != Vec3::ZERO
        };
        let list = (
            &self.mesh.normal_indices[..],
            base,
            normals.len() as u32 - base,
        );
        self.all_corner_ids(count, given, ALL_NORMALS, list, &usable)
    }

    /// The vertex-colour indices of the model's `count` faces (a colour per position, so the
    /// positions' own indices), or none when the model has no colours.
    pub(super) fn color_ids(&self, count: usize) -> Vec<[u32; 3]> {
        let Some(base) = self.colors else {
            return Vec::new();
        };
        let idx = &self.mesh.indices;
        (0..count)
            .into_par_iter()
            .map(|k| [idx[3 * k], idx[3 * k + 1], idx[3 * k + 2]].map(|i| base + i))
            .collect()
    }

    /// As [`Faces::normal_ids`], for the texture coordinates (`vt`).
    pub(super) fn uv_ids(&self, count: usize, given: &Given) -> Vec<[u32; 3]> {
        let Some((uvs, base)) = self.uvs else {
            return Vec::new();
        };
        let usable = |i: u32| uvs[i as usize].is_finite();
        let list = (
            &self.mesh.texcoord_indices[..],
            base,
            uvs.len() as u32 - base,
        );
        self.all_corner_ids(count, given, ALL_UVS, list, &usable)
    }

    /// [`Faces::corner_ids`] of each of the `count` faces that `given` says give `bit` at every
    /// corner, `NO_INDEX × 3` for the others.
    fn all_corner_ids(
        &self,
        count: usize,
        given: &Given,
        bit: u8,
        list: (&[u32], u32, u32),
        usable: &(impl Fn(u32) -> bool + Sync),
    ) -> Vec<[u32; 3]> {
        (0..count)
            .into_par_iter()
            .map(|k| match given.all(k, bit) {
                true => self.corner_ids(k, list, usable),
                false => [NO_INDEX; 3],
            })
            .collect()
    }
}

/// Which of a model's faces give `vn` (`vt`) at every corner: the mesh's flags by triangle in
/// tobj's order (empty when every face does), from the model's first triangle on.
pub(super) struct Given<'a> {
    pub flags: &'a [u8],
    pub first: usize,
}

impl Given<'_> {
    /// Face `k` of the model gives every corner what `bit` ([`ALL_NORMALS`], [`ALL_UVS`]) says.
    fn all(&self, k: usize, bit: u8) -> bool {
        self.flags.get(self.first + k).is_none_or(|f| f & bit != 0)
    }

    /// Faces that give an index at every corner, but one out of range or unusable (a face that
    /// does not give them all is shaded flat, or untextured, and counted apart).
    pub(super) fn unusable(&self, ids: &[[u32; 3]], bit: u8) -> usize {
        ids.par_iter()
            .enumerate()
            .filter(|&(k, i)| i[0] == NO_INDEX && self.all(k, bit))
            .count()
    }
}

/// How many of `placed` were marked [`DEGENERATE`] and how many [`TOO_FAR`].
pub(super) fn dropped(placed: &[Triangle]) -> (usize, usize) {
    let fates = |fate: MaterialId| placed.par_iter().filter(|t| t.material == fate).count();
    (fates(DEGENERATE), fates(TOO_FAR))
}

/// Keeps the triangles from `start` on marked [`PLACED`], in order, with their normal and
/// texture-coordinate indices (`ids`, each empty or one per triangle from `start`).
pub(super) fn keep_placed(
    triangles: &mut Vec<Triangle>,
    start: usize,
    mut ids: [&mut Vec<[u32; 3]>; 3],
) {
    let count = triangles.len() - start;
    let mut w = 0;
    for k in 0..count {
        if triangles[start + k].material == PLACED {
            triangles[start + w] = triangles[start + k];
            for ids in ids.iter_mut() {
                if !ids.is_empty() {
                    ids[w] = ids[k];
                }
            }
            w += 1;
        }
    }
    triangles.truncate(start + w);
    for ids in ids {
        ids.truncate(w);
    }
}

/// The sine of the angle within which a vertex normal lies in its face's plane for
/// [`fit_normals`] (5°).
const EDGE_ON: f32 = 0.087;

/// What [`fit_normals`] did: faces turned round, and faces whose normals it dropped.
pub(super) struct Fitted {
    pub turned: usize,
    pub edge_on: usize,
}

/// Fits each face to its own vertex normals (`normals`, unit length), in one pass. A face whose
/// three `vn` all lie within 5° of its own plane ([`EDGE_ON`]) loses them and is shaded flat: no
/// smooth surface has a normal along itself, so they belong to other faces (a file whose
/// normals were written in another face order). A face whose three `vn` all lie on the other
/// side of its plane from the normal its winding gives (a file wound clockwise, or converted
/// between left- and right-handed axes by negating one coordinate of its points and normals)
/// is turned round: two corners swapped, with their normal, texture-coordinate and colour
/// indices (`ids`: normals first, each empty or one per triangle), so that its front is the
/// side its normals face. Faces without usable `vn` at every corner are left as they are.
pub(super) fn fit_normals(
    triangles: &mut [Triangle],
    normals: &[Vec3],
    ids: [&mut Vec<[u32; 3]>; 3],
) -> Fitted {
    let [normal_ids, uv_ids, color_ids] = ids;
    if normal_ids.len() != triangles.len() {
        return Fitted {
            turned: 0,
            edge_on: 0,
        };
    }
    // One pass decides, and turns the corners and their normals or drops the normals; the few
    // turned faces' texture and colour indices follow. `(k, true)`: face k turned.
    let fitted: Vec<(usize, bool)> = (triangles.par_iter_mut().zip(normal_ids.par_iter_mut()))
        .enumerate()
        .filter_map(|(k, (t, n))| {
            if n[0] == NO_INDEX {
                return None;
            }
            let v = &t.vertices;
            let winding = (v[1] - v[0]).cross(v[2] - v[0]);
            let face = winding.normalize_or_zero();
            let corner = |i: &u32| normals[*i as usize];
            if face != Vec3::ZERO && n.iter().all(|i| corner(i).dot(face).abs() < EDGE_ON) {
                *n = [NO_INDEX; 3];
                return Some((k, false));
            }
            n.iter().all(|i| corner(i).dot(winding) < 0.0).then(|| {
                t.vertices.swap(1, 2);
                n.swap(1, 2);
                (k, true)
            })
        })
        .collect();
    let mut turned = 0;
    for &(k, _) in fitted.iter().filter(|(_, turn)| *turn) {
        turned += 1;
        for ids in [&mut *uv_ids, &mut *color_ids] {
            if let Some(corners) = ids.get_mut(k) {
                corners.swap(1, 2);
            }
        }
    }
    Fitted {
        turned,
        edge_on: fitted.len() - turned,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_triangles_are_invisible() {
        let ok = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(is_visible_triangle(&ok));
        assert!(!is_visible_triangle(&[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]));
        assert!(!is_visible_triangle(&[Vec3::ZERO, Vec3::X, Vec3::NAN]));
        assert!(!is_visible_triangle(&[
            Vec3::ZERO,
            Vec3::X * 3e38,
            Vec3::Y * 3e38
        ]));
    }

    #[test]
    fn only_faces_whose_three_normals_all_face_the_other_way_are_turned() {
        let t = Triangle {
            vertices: [Vec3::ZERO, Vec3::X, Vec3::Y],
            material: PLACED,
            object: ObjectId(0),
        };
        // Normals 0, 1: +z (the winding's side); 2, 3: -z; 4: tilted, still -z's side.
        let normals = [
            Vec3::Z,
            Vec3::Z,
            -Vec3::Z,
            -Vec3::Z,
            Vec3::new(0.9, 0.0, -0.1),
        ];
        let mut triangles = vec![t; 4];
        let mut normal_ids = vec![[0, 1, 0], [2, 3, 0], [2, 3, 4], [NO_INDEX; 3]];
        let mut uv_ids = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]];
        let mut color_ids = Vec::new();
        let ids = [&mut normal_ids, &mut uv_ids, &mut color_ids];
        assert_eq!(fit_normals(&mut triangles, &normals, ids).turned, 1);
        assert_eq!(triangles[2].vertices, [Vec3::ZERO, Vec3::Y, Vec3::X]);
        assert_eq!((normal_ids[2], uv_ids[2]), ([2, 4, 3], [6, 8, 7]));
        // A face with one normal on its winding's side, and one without normals, stay.
        for k in [0, 1, 3] {
            assert_eq!(triangles[k].vertices, t.vertices);
        }
        assert_eq!((normal_ids[1], uv_ids[1]), ([2, 3, 0], [3, 4, 5]));
    }
}
