//! One OBJ mesh added to a scene, step by step: its text read and checked against the memory
//! budget, its material libraries read, then each model's faces placed, its attributes and
//! material found, and the degenerate faces dropped; last the mesh's normals, texture
//! coordinates and warnings.

use std::borrow::Cow;
use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};
use rayon::prelude::*;

use super::attributes::{Corners, finish_attributes};
use super::corners::{self, FaceCorners};
use super::faces::{Faces, Given, PLACED, dropped, fit_normals, keep_placed};
use super::memory::check_memory;
use super::mtl::{Libraries, mtl_material, named_material, read_maya_illum, warn_unknown_usemtl};
use super::parse::Facts;
use super::read::{ObjProblem, join_continued_lines, read_models, respell, scan};
use super::request::MeshRequest;
use crate::scene::diag::{list_some, short, short_path};
use crate::scene::{MaterialId, MeshAttributes, MeshPart, NormalsMode, Scene};

/// The name tobj gives the faces before any `o` or `g` (and an `o` or `g` without a name).
const UNNAMED: &str = "unnamed_object";

/// What [`add_mesh`] added.
pub(crate) struct Added {
    /// Triangles added.
    pub triangles: usize,
    /// The file has vertex normals (`vn` statements): they, not the winding alone, say which
    /// side of a face is its front.
    pub gives_normals: bool,
}

/// Adds the OBJ's triangles (placed, degenerate ones dropped) and the MTL materials they use
/// to `scene`.
pub(crate) fn add_mesh(scene: &mut Scene, req: &MeshRequest) -> Result<Added, ObjProblem> {
    let joined = join_continued_lines(req.text);
    let with_joined;
    let req = match &joined {
        Cow::Owned(text) => {
            with_joined = MeshRequest { text, ..*req };
            &with_joined
        }
        Cow::Borrowed(_) => req,
    };
    let (mut scanned, mut fast_corners, mut facts) = scan(req.text)?;
    // What the parallel reader gave up on may be a spelling tobj refuses too (`usemtl` alone,
    // `1.#IND`): spelled so that it reads, and read again.
    let respelled = scanned.is_none().then(|| respell(req.text)).flatten();
    let made_white = respelled.as_ref().map_or(0, |(_, white)| *white);
    let with_respelled;
    let req = match &respelled {
        Some((text, _)) => {
            (scanned, fast_corners, facts) = scan(text)?;
            with_respelled = MeshRequest { text, ..*req };
            &with_respelled
        }
        None => req,
    };
    // A file without `vn` whose faces are in smoothing groups (`s 1`) shades as its exporter
    // meant: smooth, with normals computed as for `normals = "smooth"` within each group.
    let by_groups = req.normals == NormalsMode::File && facts.normals == 0 && facts.smoothing;
    let smoothed;
    let req = if by_groups {
        smoothed = MeshRequest {
            normals: NormalsMode::Smooth,
            ..*req
        };
        &smoothed
    } else {
        req
    };
    check_memory(scene, req.text.len(), &facts, req.normals)?;
    let libraries = Libraries::new(req);
    let (mut models, mut mtl_materials, fast) =
        read_models(req.text, scanned, |path| libraries.load(path))?;
    if facts.ngons > 0 {
        super::polygons::cut_concave_faces(&mut models, req.text);
    }
    let face_corners = face_corners(req.text, &models, fast, fast_corners)?;
    let (mut warnings, mtl_texts) = libraries.finish();
    read_maya_illum(&mut mtl_materials, req.label, &mut warnings);
    warn_about_reading(req, &facts, &mtl_materials, &mut warnings);
    if made_white > 0 {
        let (which, give) = match made_white {
            1 => ("1 vertex".to_string(), "gives"),
            n => (format!("{n} vertices"), "give"),
        };
        warnings.push(format!(
            "{}: {which} {give} no colour (`v x y z`) where the others give one (`v x y z r g b`): taken as white, so their faces show their material's colour.",
            req.label
        ));
    }
    // A file with `vn` on some faces only: those of the others in a smoothing group get
    // normals computed within it.
    let lacking = |f: u8| f & corners::ALL_NORMALS == 0;
    let some_lack = req.normals == NormalsMode::File
        && facts.smoothing
        && face_corners.triangles.iter().any(|&f| lacking(f));
    let mut build = MeshBuild::new(scene, req, &models, &face_corners, &mtl_materials, warnings);
    if by_groups || some_lack {
        build.read_groups(req.text, &models);
        let grouped_without_vn = match &build.file_groups {
            Some(groups) if !by_groups => face_corners
                .triangles
                .iter()
                .zip(groups)
                .filter(|&(&f, &g)| lacking(f) && g != 0)
                .count(),
            _ => 0,
        };
        let which: Option<&str> = if by_groups {
            Some("no vertex normals (`vn`), so the faces of its smoothing groups (`s`) are")
        } else if grouped_without_vn > 0 {
            Some("the faces without vertex normals (`vn`) in its smoothing groups (`s`) are")
        } else {
            // None of the faces without `vn` is in a group: nothing to compute.
            build.file_groups = None;
            None
        };
        if let Some(which) = which {
            build.warnings.push(format!(
                "{}: {which} shaded with normals computed within each group across edges under \
                 {}° (`normals = \"flat\"` keeps the facets).",
                req.label, req.crease_angle_deg
            ));
        }
    }
    for model in &models {
        let start = scene.triangles.len();
        build.add_model(scene, &model.mesh, &mtl_texts);
        add_part(scene, req, &model.name, start);
    }
    Ok(Added {
        triangles: build.finish(scene, &face_corners),
        gives_normals: facts.normals > 0,
    })
}

/// Names the triangles a model added from `start` on after its `o` or `g` (tobj's model name):
/// one [`MeshPart`] per run, the previous one grown when the run continues it (same object,
/// name and material). A model without a name, named as the mesh, or whose faces were all
/// dropped, names nothing.
fn add_part(scene: &mut Scene, req: &MeshRequest, name: &str, start: usize) {
    let end = scene.triangles.len();
    // A part named as its mesh ("torus" in torus.obj) would say the name twice.
    if name == UNNAMED || name == req.object_name || end == start {
        return;
    }
    let material = scene.triangles[start].material;
    let parts = Arc::make_mut(&mut scene.parts);
    if let Some(last) = parts.last_mut()
        && (last.first_triangle + last.triangle_count) as usize == start
        && (last.object, last.material, last.name.as_str()) == (req.object, material, name)
    {
        last.triangle_count += (end - start) as u32;
        return;
    }
    parts.push(MeshPart {
        first_triangle: start as u32,
        triangle_count: (end - start) as u32,
        object: req.object,
        material,
        name: name.to_string(),
    });
}

/// Which faces give `vn`/`vt` at every corner (tobj fills the others from a neighbour): the
/// fast reader's pass found them; a file read by tobj is read again for them.
fn face_corners(
    text: &str,
    models: &[tobj::Model],
    fast: bool,
    fast_corners: Option<FaceCorners>,
) -> Result<FaceCorners, ObjProblem> {
    let (uvs_in_file, normals_in_file) = models.iter().fold((false, false), |(t, n), m| {
        (
            t || !m.mesh.texcoords.is_empty(),
            n || !m.mesh.normals.is_empty(),
        )
    });
    Ok(match (uvs_in_file || normals_in_file, fast_corners) {
        (false, _) => Default::default(),
        (true, Some(found)) if fast => found.only(uvs_in_file, normals_in_file),
        (true, _) => {
            corners::face_corners(text, uvs_in_file, normals_in_file).map_err(|(line, error)| {
                ObjProblem {
                    line: Some(line),
                    reason: super::explain::explain(&error, text, Some(line)),
                }
            })?
        }
    })
}

/// The warnings about what was read: the polylines ignored, and, when nothing else went wrong
/// so far, the `usemtl` names no library defines.
fn warn_about_reading(
    req: &MeshRequest,
    facts: &Facts,
    mtl_materials: &[tobj::Material],
    warnings: &mut Vec<String>,
) {
    let polylines = facts.polylines;
    if polylines > 0 {
        let s = if polylines == 1 { "" } else { "s" };
        warnings.push(format!(
            "{}: ignored {polylines} polyline{s} (`l`): a line has no surface to show.",
            req.label
        ));
    }
    if req.material_override.is_none() && warnings.is_empty() {
        warn_unknown_usemtl(req.label, facts, mtl_materials, warnings);
    }
}

/// A mesh while its models are added, one after another.
struct MeshBuild<'a> {
    req: &'a MeshRequest<'a>,
    mtl_materials: &'a [tobj::Material],
    /// The scene material of each MTL material, made when first used.
    mtl_ids: Vec<Option<MaterialId>>,
    /// The material of textured faces without one, once looked for: the texture named for the
    /// OBJ ([`named_material`]), if there is one.
    named: Option<Option<MaterialId>>,
    linear: Mat3,
    /// Normals go through the inverse transpose, which keeps them perpendicular to the placed
    /// surface (and on its outside when a mirroring scale swaps the corners).
    normal_matrix: Mat3,
    mirrors: bool,
    file_normals: bool,
    /// Which faces give every corner's `vn` (`vt`): flags by triangle in tobj's order, or
    /// none when every face does.
    explicit: &'a [u8],
    /// Triangles of the models so far, as tobj read them (kept or not).
    triangle_read: usize,
    first_triangle: usize,
    /// Triangles kept so far.
    added: usize,
    /// Triangles dropped so far: of zero area or not finite, and beyond the scene-size limit.
    dropped: usize,
    too_far: usize,
    /// Triangles kept so far that were wound against their vertex normals, and turned round.
    turned: usize,
    attrs: MeshAttributes,
    corners: Corners,
    warnings: Vec<String>,
    /// Textures not where the MTL says but found next to the OBJ: (as written, as found).
    textures_elsewhere: Vec<(String, String)>,
    /// MTL materials whose black `Kd` under a texture was taken as 1 ([`mtl_material`]).
    black_under_texture: Vec<String>,
    /// The smoothing group of each triangle read (file order), when the mesh is shaded by its
    /// groups ([`MeshBuild::read_groups`]), and of each triangle kept.
    file_groups: Option<Vec<u32>>,
    groups: Vec<u32>,
}

impl<'a> MeshBuild<'a> {
    fn new(
        scene: &mut Scene,
        req: &'a MeshRequest<'a>,
        models: &[tobj::Model],
        face_corners: &'a FaceCorners,
        mtl_materials: &'a [tobj::Material],
        warnings: Vec<String>,
    ) -> Self {
        let linear = req.placement.linear();
        let first_triangle = scene.triangles.len();
        let triangles_read: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
        let explicit: &[u8] = match face_corners.triangles.len() == triangles_read {
            true => &face_corners.triangles,
            false => &[],
        };
        Arc::make_mut(&mut scene.triangles).reserve(triangles_read);
        Self {
            req,
            mtl_materials,
            mtl_ids: vec![None; mtl_materials.len()],
            named: None,
            linear,
            normal_matrix: linear.inverse().transpose(),
            mirrors: req.placement.mirrors(),
            file_normals: req.normals == NormalsMode::File,
            explicit,
            triangle_read: 0,
            first_triangle,
            added: 0,
            dropped: 0,
            too_far: 0,
            turned: 0,
            attrs: MeshAttributes {
                first_triangle: first_triangle as u32,
                ..MeshAttributes::default()
            },
            corners: Corners::default(),
            warnings,
            textures_elsewhere: Vec::new(),
            black_under_texture: Vec::new(),
            file_groups: None,
            groups: Vec::new(),
        }
    }

    /// Reads the smoothing group of every face, for a mesh shaded smooth by its groups. Should
    /// the count differ from the triangles read (it does not for a file the readers take), the
    /// groups are left out and every face is smoothed alike.
    fn read_groups(&mut self, text: &str, models: &[tobj::Model]) {
        let groups = super::parse::smoothing_groups(text);
        let read: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
        self.file_groups = (groups.len() == read).then_some(groups);
    }

    /// Adds one model's faces: placed, with their normal and texture-coordinate indices and
    /// their material, the degenerate and too distant ones dropped.
    fn add_model(&mut self, scene: &mut Scene, mesh: &tobj::Mesh, mtl_texts: &[(String, String)]) {
        let (normal_base, uv_base, color_base) = self.read_attributes(mesh);
        let faces = Faces {
            mesh,
            linear: self.linear,
            translate: self.req.placement.translate,
            mirrors: self.mirrors,
            normals: normal_base.map(|base| (&self.attrs.normals[..], base)),
            uvs: uv_base.map(|base| (&self.attrs.uvs[..], base)),
            colors: color_base,
        };
        let count = mesh.indices.len() / 3;
        let given = Given {
            flags: self.explicit,
            first: self.triangle_read,
        };
        let start = scene.triangles.len();
        faces.place(Arc::make_mut(&mut scene.triangles), count, self.req.object);
        let mut normal_ids = faces.normal_ids(count, &given);
        let mut uv_ids = faces.uv_ids(count, &given);
        let mut color_ids = faces.color_ids(count);
        self.corners.bad_normals += given.unusable(&normal_ids, corners::ALL_NORMALS);
        self.corners.bad_uvs += given.unusable(&uv_ids, corners::ALL_UVS);
        self.triangle_read += count;
        let (degenerate, far) = dropped(&scene.triangles[start..]);
        if let Some(file_groups) = &self.file_groups {
            let first = self.triangle_read - count;
            let placed = scene.triangles[start..].iter().enumerate();
            self.groups.extend(
                placed
                    .filter(|(_, t)| t.material == PLACED)
                    .map(|(k, _)| file_groups[first + k]),
            );
        }
        self.dropped += degenerate;
        self.too_far += far;
        let kept = count - degenerate - far;
        // Materials are added on first use, so a scene lists only what it shows.
        let material = (kept > 0).then(|| self.material(scene, mesh, mtl_texts));
        if kept < count {
            // Rare: keep the placed ones, in order, with their corner indices.
            let triangles = Arc::make_mut(&mut scene.triangles);
            keep_placed(
                triangles,
                start,
                [&mut normal_ids, &mut uv_ids, &mut color_ids],
            );
        }
        let fitted = fit_normals(
            &mut Arc::make_mut(&mut scene.triangles)[start..],
            &self.attrs.normals,
            [&mut normal_ids, &mut uv_ids, &mut color_ids],
        );
        self.turned += fitted.turned;
        self.corners.edge_on_normals += fitted.edge_on;
        if let Some(material) = material {
            Arc::make_mut(&mut scene.triangles)[start..]
                .par_iter_mut()
                .for_each(|t| t.material = material);
        }
        self.corners
            .append(self.added, [normal_ids, uv_ids, color_ids]);
        self.added += kept;
    }

    /// Adds the model's normals (placed) and texture coordinates to the mesh's, when its faces
    /// give them; returns the index of the model's first of each. Per-face normal and texture
    /// indices exist only when every face gives them.
    fn read_attributes(&mut self, mesh: &tobj::Mesh) -> (Option<u32>, Option<u32>, Option<u32>) {
        let attrs = &mut self.attrs;
        let normal_base = attrs.normals.len() as u32;
        let has_normals = self.file_normals
            && !mesh.normals.is_empty()
            && mesh.normal_indices.len() == mesh.indices.len();
        if has_normals {
            let normal_matrix = self.normal_matrix;
            attrs.normals.par_extend(
                mesh.normals
                    .par_chunks_exact(3)
                    .map(|n| (normal_matrix * Vec3::new(n[0], n[1], n[2])).normalize_or_zero()),
            );
        }
        let uv_base = attrs.uvs.len() as u32;
        let has_uvs =
            !mesh.texcoords.is_empty() && mesh.texcoord_indices.len() == mesh.indices.len();
        if has_uvs {
            attrs.uvs.par_extend(
                mesh.texcoords
                    .par_chunks_exact(2)
                    .map(|t| Vec2::new(t[0], t[1])),
            );
        }
        // Vertex colours, one per position, written as the display shows them (sRGB, 0 to 1):
        // made linear as a texture's texels are.
        let color_base = attrs.colors.len() as u32;
        let has_colors =
            !mesh.vertex_color.is_empty() && mesh.vertex_color.len() == mesh.positions.len();
        if has_colors {
            attrs
                .colors
                .par_extend(mesh.vertex_color.par_chunks_exact(3).map(|c| {
                    Vec3::new(c[0], c[1], c[2]).map(|x| {
                        if x.is_finite() {
                            crate::scene::texture::srgb_unit_to_linear(x.clamp(0.0, 1.0))
                        } else {
                            1.0
                        }
                    })
                }));
        }
        (
            has_normals.then_some(normal_base),
            has_uvs.then_some(uv_base),
            has_colors.then_some(color_base),
        )
    }

    /// The material of a model's faces: the override, its MTL material (made on first use), the
    /// texture named for the OBJ when they have texture coordinates, or the scene's default.
    fn material(
        &mut self,
        scene: &mut Scene,
        mesh: &tobj::Mesh,
        mtl_texts: &[(String, String)],
    ) -> MaterialId {
        let mtl_materials = self.mtl_materials;
        match (self.req.material_override, mesh.material_id) {
            (Some(id), _) => id,
            (None, Some(i)) if i < mtl_materials.len() => {
                *self.mtl_ids[i].get_or_insert_with(|| {
                    let (id, brightened) = mtl_material(
                        scene,
                        self.req,
                        &mtl_materials[i],
                        mtl_texts,
                        &mut self.warnings,
                        &mut self.textures_elsewhere,
                    );
                    if brightened {
                        self.black_under_texture
                            .push(format!("`{}`", short(&mtl_materials[i].name)));
                    }
                    id
                })
            }
            (None, _) if !mesh.texcoords.is_empty() => {
                let (req, warnings) = (self.req, &mut self.warnings);
                let named = self
                    .named
                    .get_or_insert_with(|| named_material(scene, req, warnings));
                named.unwrap_or_else(|| scene.default_material())
            }
            (None, _) => scene.default_material(),
        }
    }

    /// Ends the mesh: the triangle list trimmed, the attributes kept, the warnings about dropped
    /// triangles given; returns how many triangles the mesh added.
    fn finish(mut self, scene: &mut Scene, face_corners: &FaceCorners) -> usize {
        let req = self.req;
        let added = self.added;
        if added < scene.triangles.capacity() / 2 {
            Arc::make_mut(&mut scene.triangles).shrink_to_fit();
        }
        let textured = scene.triangles[self.first_triangle..].iter().any(|t| {
            scene.material(t.material).diffuse_map.is_some()
                || scene.material(t.material).ambient_map.is_some()
        });
        let mut corners = self.corners;
        corners.partial_normals = face_corners.partial_normals * usize::from(self.file_normals);
        corners.partial_uvs = face_corners.partial_uvs;
        let warnings = &mut self.warnings;
        let groups = self.file_groups.is_some().then_some(&self.groups[..]);
        finish_attributes(scene, req, self.attrs, corners, textured, groups, warnings);
        let (dropped, too_far) = (self.dropped, self.too_far);
        if dropped > 0 {
            let s = if dropped == 1 { "" } else { "s" };
            warnings.push(format!(
                "{}: dropped {dropped} degenerate triangle{s} (zero area or non-finite vertices).",
                req.label
            ));
        }
        if self.turned > 0 {
            let which = match self.turned {
                n if n == added => "its faces are".to_string(),
                1 => "1 face is".to_string(),
                n => format!("{n} faces are"),
            };
            warnings.push(format!(
                "{}: {which} wound clockwise seen from the side their vertex normals (`vn`) \
                 face, as a file converted between left- and right-handed axes is: their front \
                 is taken to be the side the normals face.",
                req.label
            ));
        }
        if too_far > 0 {
            let s = if too_far == 1 { "" } else { "s" };
            warnings.push(format!(
                "{}: dropped {too_far} triangle{s} placed beyond ±1e15, raytree's limit on scene size.",
                req.label
            ));
        }
        if let Some((written, found)) = self.textures_elsewhere.first() {
            let n = self.textures_elsewhere.len();
            let more = match n {
                1 => String::new(),
                n => format!(" and {} more", n - 1),
            };
            warnings.push(format!(
                "{}: {} not where the material library says but found from the OBJ's folder: `{}` as `{}`{more}.",
                req.label,
                if n == 1 { "a texture is".to_string() } else { format!("{n} textures are") },
                short_path(written),
                short_path(found),
            ));
        }
        if !self.black_under_texture.is_empty() {
            let names = &self.black_under_texture;
            let which = match names.len() {
                1 => format!("material {} has", names[0]),
                _ => format!("materials {} have", list_some(names)),
            };
            warnings.push(format!(
                "{}: {which} `Kd 0` under a `map_Kd` (as Maya writes), which would never show the texture: `Kd 1` is taken, the texture being the colour.",
                req.label
            ));
        }
        scene.warnings.extend(self.warnings);
        added
    }
}
