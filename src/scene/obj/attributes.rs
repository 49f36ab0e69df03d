//! A mesh's shading normals and texture coordinates: the indices each kept triangle takes, the
//! normals computed for `normals = "smooth"`, the warnings about unusable `vn` and `vt`, and
//! what of it the scene keeps (nothing for a flat, untextured mesh).

use std::sync::Arc;

use super::request::MeshRequest;
use crate::geometry::smooth_normals;
use crate::scene::{MeshAttributes, NO_INDEX, NormalsMode, Scene};

/// The normal and texture-coordinate indices of a mesh's kept triangles, while it loads; each
/// list is empty until a model gives some, then as long as the triangles kept up to that
/// model's end ([`finish_attributes`] pads it to the mesh's end).
#[derive(Default)]
pub(super) struct Corners {
    pub normals: Vec<[u32; 3]>,
    pub uvs: Vec<[u32; 3]>,
    pub colors: Vec<[u32; 3]>,
    /// Faces whose `vn` indices are out of range or name a zero or non-finite normal.
    pub bad_normals: usize,
    /// Faces whose `vt` indices are out of range or name non-finite coordinates.
    pub bad_uvs: usize,
    /// Faces whose three `vn` lie in the face's own plane (they belong to other faces).
    pub edge_on_normals: usize,
    /// Faces with `vn` (`vt`) at some corners only.
    pub partial_normals: usize,
    pub partial_uvs: usize,
}

impl Corners {
    /// Adds a model's normal, texture-coordinate and colour indices (each empty, or one per
    /// kept triangle) after the `added` triangles the mesh kept before it.
    pub(super) fn append(
        &mut self,
        added: usize,
        [normal_ids, uv_ids, color_ids]: [Vec<[u32; 3]>; 3],
    ) {
        for (list, ids) in [
            (&mut self.normals, normal_ids),
            (&mut self.uvs, uv_ids),
            (&mut self.colors, color_ids),
        ] {
            if ids.is_empty() {
                continue;
            }
            if list.is_empty() && added == 0 {
                *list = ids;
            } else {
                list.resize(added, [NO_INDEX; 3]);
                list.extend_from_slice(&ids);
            }
        }
    }
}

/// Keeps the mesh's normals (from the file, or computed for `normals = "smooth"`) and, when a
/// material of it has a texture, its texture coordinates; adds them to the scene only if there
/// are any, so flat untextured meshes cost nothing. Warns about unusable `vn`/`vt` once each.
pub(super) fn finish_attributes(
    scene: &mut Scene,
    req: &MeshRequest,
    mut attrs: MeshAttributes,
    mut corners: Corners,
    textured: bool,
    groups: Option<&[u32]>,
    warnings: &mut Vec<String>,
) {
    let first = attrs.first_triangle as usize;
    let count = scene.triangles.len() - first;
    attrs.triangle_count = count as u32;
    let grouped = groups.is_some() && req.normals == NormalsMode::File;
    warn_about_corners(req.label, &corners, textured, grouped, warnings);
    for list in [&mut corners.normals, &mut corners.uvs, &mut corners.colors] {
        if !list.is_empty() {
            list.resize(count, [NO_INDEX; 3]);
        }
    }
    match req.normals {
        NormalsMode::Flat => attrs.normals.clear(),
        NormalsMode::File => {
            if let Some(groups) = groups {
                let triangles = &scene.triangles[first..];
                fill_by_groups(triangles, req, &mut attrs, &mut corners.normals, groups);
            }
            if corners.normals.iter().any(|n| n[0] != NO_INDEX) {
                attrs.normal_indices = corners.normals;
            } else {
                attrs.normals.clear();
            }
        }
        NormalsMode::Smooth => {
            let (normals, indices) = smooth_normals(
                &scene.triangles[first..],
                |t| t.vertices,
                req.crease_angle_deg,
                groups,
            );
            attrs.normals = normals;
            attrs.normal_indices = indices;
        }
    }
    if textured && corners.uvs.iter().any(|t| t[0] != NO_INDEX) {
        attrs.uv_indices = corners.uvs;
    } else {
        attrs.uvs.clear();
    }
    if corners.colors.iter().any(|c| c[0] != NO_INDEX) {
        attrs.color_indices = corners.colors;
    } else {
        attrs.colors.clear();
    }
    attrs.normals.shrink_to_fit();
    attrs.uvs.shrink_to_fit();
    attrs.colors.shrink_to_fit();
    let carries = !attrs.normal_indices.is_empty()
        || !attrs.uv_indices.is_empty()
        || !attrs.color_indices.is_empty();
    if count > 0 && carries {
        scene.attributes.push(Arc::new(attrs));
    }
}

/// For a file with `vn` at some faces only: each face without them that is in a smoothing
/// group (`groups`, one per kept triangle, 0 for none) takes the normals `normals = "smooth"`
/// computes within its group, added after the file's (only those taken).
fn fill_by_groups(
    triangles: &[crate::scene::Triangle],
    req: &MeshRequest,
    attrs: &mut MeshAttributes,
    indices: &mut Vec<[u32; 3]>,
    groups: &[u32],
) {
    let wanted = |k: usize| groups[k] != 0 && indices.get(k).is_none_or(|n| n[0] == NO_INDEX);
    if !(0..triangles.len().min(groups.len())).any(wanted) {
        return;
    }
    let (normals, computed) = smooth_normals(
        triangles,
        |t| t.vertices,
        req.crease_angle_deg,
        Some(groups),
    );
    // Only the computed normals a face takes are kept, each value once, after the file's.
    let mut kept: std::collections::HashMap<[u32; 3], u32> = Default::default();
    indices.resize(triangles.len(), [NO_INDEX; 3]);
    for (k, slot) in indices.iter_mut().enumerate() {
        if groups.get(k).is_some_and(|&g| g != 0) && slot[0] == NO_INDEX {
            *slot = computed[k].map(|i| {
                let n = normals[i as usize];
                *kept
                    .entry(n.to_array().map(f32::to_bits))
                    .or_insert_with(|| {
                        attrs.normals.push(n);
                        attrs.normals.len() as u32 - 1
                    })
            });
        }
    }
}

/// One warning for each kind of unusable `vn` or `vt` the mesh's faces have (those about `vt`
/// only when a material of the mesh has a texture).
fn warn_about_corners(
    label: &str,
    corners: &Corners,
    textured: bool,
    grouped: bool,
    warnings: &mut Vec<String>,
) {
    // (count, whether it applies, the verb for one face and for several, what those faces do,
    // and what becomes of them), one warning each.
    let flat = if grouped {
        "shaded flat unless in a smoothing group"
    } else {
        "shaded flat"
    };
    let problems = [
        (
            corners.bad_normals,
            true,
            ["names", "name"],
            "normals (`vn`) that are out of range, zero or not finite",
            flat,
        ),
        (
            corners.edge_on_normals,
            true,
            ["has", "have"],
            "normals (`vn`) lying in the face's own plane, which no surface has there (they belong to other faces)",
            flat,
        ),
        (
            corners.partial_normals,
            true,
            ["gives", "give"],
            "normals (`vn`) at some corners only",
            flat,
        ),
        (
            corners.partial_uvs,
            textured,
            ["gives", "give"],
            "texture coordinates (`vt`) at some corners only",
            "not textured",
        ),
        (
            corners.bad_uvs,
            textured,
            ["names", "name"],
            "texture coordinates (`vt`) that are out of range or not finite",
            "not textured",
        ),
    ];
    for (n, applies, [verb_one, verb_many], what, fate) in problems {
        if n > 0 && applies {
            warnings.push(faces_warning(label, n, [verb_one, verb_many], what, fate));
        }
    }
}

/// `LABEL: N face(s) VERB WHAT; it is (they are) FATE.`, singular for one face, plural for
/// several (`verb` for one and for several).
fn faces_warning(label: &str, n: usize, verb: [&str; 2], what: &str, fate: &str) -> String {
    let (faces, verb, they) = match n {
        1 => ("face", verb[0], "it is"),
        _ => ("faces", verb[1], "they are"),
    };
    format!("{label}: {n} {faces} {verb} {what}; {they} {fate}.")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mesh warnings' sentences agree in number for one face and for two.
    #[test]
    fn face_warnings_agree_in_number() {
        // Through the loader: one (two) faces with a zero normal, and one (two) with `vn` at
        // some corners only.
        for (n, faces, verb, they) in [
            (1, "face", ["names", "gives"], "it is"),
            (2, "faces", ["name", "give"], "they are"),
        ] {
            let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 0\n");
            for _ in 0..n {
                obj += "f 1//2 2//2 3//2\nf 1//1 2 3//1\n";
            }
            let scene = crate::scene::load_scene_str_with(
                "[[mesh]]\nfile = \"m.obj\"\n",
                "t.toml",
                &|_: &str| Ok(obj.clone()),
            )
            .unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                scene.warnings,
                [
                    format!(
                        "m.obj: {n} {faces} {} normals (`vn`) that are out of range, zero or \
                         not finite; {they} shaded flat.",
                        verb[0]
                    ),
                    format!(
                        "m.obj: {n} {faces} {} normals (`vn`) at some corners only; {they} \
                         shaded flat.",
                        verb[1]
                    ),
                ]
            );
        }
        let what = "normals (`vn`) that are out of range, zero or not finite";
        assert_eq!(
            faces_warning("m.obj", 1, ["names", "name"], what, "shaded flat"),
            "m.obj: 1 face names normals (`vn`) that are out of range, zero or not finite; \
             it is shaded flat."
        );
        assert_eq!(
            faces_warning("m.obj", 2, ["names", "name"], what, "shaded flat"),
            "m.obj: 2 faces name normals (`vn`) that are out of range, zero or not finite; \
             they are shaded flat."
        );
        let what = "texture coordinates (`vt`) at some corners only";
        assert_eq!(
            faces_warning("m.obj", 1, ["gives", "give"], what, "not textured"),
            "m.obj: 1 face gives texture coordinates (`vt`) at some corners only; it is not \
             textured."
        );
        assert_eq!(
            faces_warning("m.obj", 2, ["gives", "give"], what, "not textured"),
            "m.obj: 2 faces give texture coordinates (`vt`) at some corners only; they are not \
             textured."
        );
    }
}
