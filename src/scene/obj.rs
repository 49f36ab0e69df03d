//! OBJ meshes and their MTL materials (SPEC §3, §3b): positions, and the `vn` normals and
//! `vt` coordinates a scene uses (read by [`super::obj_parse`], tobj for the unusual), faces
//! triangulated, the Phong material mapped from `Ka`/`Kd`/`Ks`/`Ns`/`Ni`/`d`/`Tr`/`illum`,
//! and the mesh placed by scale, rotation (X then Y then Z, in degrees) and translation.
//! Degenerate triangles are dropped here, at load time, and counted in one warning, so the
//! tracer never meets them. A bare `.obj` opened as a whole scene is in
//! [`super::first_look`].

use std::borrow::Cow;
use std::cell::{Cell, RefCell};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::Once;

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};

use rayon::prelude::*;

use super::budget::{MemoryLimit, memory_limit, mesh_memory_estimate};
use super::diag::{list_and, short, short_path};
use super::obj_corners::{ALL_NORMALS, ALL_UVS};
use super::obj_parse::{self, Facts, Polylines, Scanned};
use super::rules::{MAX_COORDINATE, is_visible_triangle};
use super::texture::decode_texture;
use super::{
    Material, MaterialId, MeshAttributes, NO_INDEX, NormalsMode, ObjectId, ResolveBytesFn,
    ResolveFn, Scene, Texture, TextureId, Triangle,
};

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

/// True if `path` ends in `.obj`, in any case: the only files a `[[mesh]]` may name.
pub(crate) fn is_obj_path(path: &str) -> bool {
    Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// The file name without folder and extension (`models/gem.obj` → `gem`).
pub(crate) fn file_stem(path: &str) -> Option<String> {
    Path::new(path)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
}

/// `name` next to the file `path` (both as written, `/` or `\` separated): the MTL next to
/// its OBJ.
pub(crate) fn sibling(path: &str, name: &str) -> String {
    if name.starts_with('/') || Path::new(name).is_absolute() {
        return name.to_string();
    }
    match path.rfind(['/', '\\']) {
        Some(i) => format!("{}/{name}", &path[..i]),
        None => name.to_string(),
    }
}

/// Why an OBJ could not be read: the `tobj` reason and, when found, the line.
#[derive(Debug)]
pub(crate) struct ObjProblem {
    pub line: Option<usize>,
    pub reason: String,
}

impl ObjProblem {
    /// `:17: reason` or `: reason`, to follow a file name.
    pub fn with_line(&self) -> String {
        match self.line {
            Some(line) => format!(":{line}: {}", self.reason),
            None => format!(": {}", self.reason),
        }
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

fn load_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    }
}

thread_local! {
    /// Set while [`quietly`] runs: the panic hook then prints nothing.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f` with panics caught and not printed. `tobj` is third-party code fed hostile files;
/// a panic in it must become one error sentence (SPEC §9), not a crash or a second line on
/// stderr. The panic hook is wrapped once, and stays silent only on this thread and only while
/// `f` runs, so every other panic is reported as before.
fn quietly<T>(f: impl FnOnce() -> T) -> Result<T, ()> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let outcome = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    outcome.map_err(|_| ())
}

/// Reads OBJ text: the models of the parallel reader's pass `scanned` (the same result as
/// `tobj`, faster), or `tobj` itself on the text without its polylines when that reader left it
/// to tobj; with panics caught, since hostile files must never take the program down (SPEC
/// §9). Each `mtllib` reaches `load_mtl` once, even when the fast reader gives up after it:
/// tobj then gets the recorded results. The flag says whether the models are the fast
/// reader's.
fn load_obj(
    text: &str,
    scanned: Option<Scanned>,
    load_mtl: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<(tobj::LoadResult, bool), String> {
    let failed = |()| "the OBJ reader failed on this file".to_string();
    let recorded = RefCell::new(std::collections::VecDeque::new());
    if let Some(scanned) = scanned {
        let fast = quietly(|| {
            scanned.assemble(|path: &Path| {
                let result = load_mtl(path);
                recorded
                    .borrow_mut()
                    .push_back((path.to_path_buf(), result.clone()));
                result
            })
        })
        .map_err(failed)?;
        if let Some(loaded) = fast {
            return Ok((loaded, true));
        }
    }
    let replay = |path: &Path| {
        let mut recorded = recorded.borrow_mut();
        match recorded.front() {
            Some((p, _)) if p == path => match recorded.pop_front() {
                Some((_, result)) => result,
                None => load_mtl(path),
            },
            _ => load_mtl(path),
        }
    };
    let (text, _) = without_polylines(text);
    quietly(|| tobj::load_obj_buf(&mut text.as_bytes(), &load_options(), replay))
        .map(|loaded| (loaded, false))
        .map_err(failed)
}

/// Reads OBJ text without polylines, as [`add_mesh`] reads it (the error search's reader).
fn read_plain(text: &str) -> Result<tobj::LoadResult, String> {
    let scanned = quietly(|| obj_parse::scan(text, Polylines::Skip))
        .map_err(|()| "the OBJ reader failed on this file".to_string())?;
    load_obj(text, scanned, |_| Ok(Default::default())).map(|(loaded, _)| loaded)
}

/// MTL text as `tobj` can take it, or the line and the reason it cannot. The MTL format lets
/// `Ka`, `Kd`, `Ks` and `Ke` give one number for all three channels (`Kd 0.8`); tobj 4.0.5
/// panics on that (and on zero or two numbers), so one number is spelled out three times here
/// and zero or two are refused with their line.
fn mtl_for_tobj(text: &str) -> Result<Cow<'_, str>, (usize, String)> {
    let mut fixed: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() else {
            if let Some(out) = fixed.as_mut() {
                out.push_str(line);
                out.push('\n');
            }
            continue;
        };
        let values: Vec<&str> = words.collect();
        let parses = values.iter().all(|v| v.parse::<f32>().is_ok());
        match values.len() {
            1 | 2 if !parses => {} // tobj reports the bad number as an error
            0 | 2 => {
                return Err((
                    i + 1,
                    format!(
                        "`{key}` needs one number or three (r g b), got {}",
                        values.len()
                    ),
                ));
            }
            1 => {
                let out = fixed.get_or_insert_with(|| {
                    let mut head = String::with_capacity(text.len() + 64);
                    for earlier in text.lines().take(i) {
                        head.push_str(earlier);
                        head.push('\n');
                    }
                    head
                });
                let v = values[0];
                out.push_str(&format!("{key} {v} {v} {v}\n"));
                continue;
            }
            _ => {}
        }
        if let Some(out) = fixed.as_mut() {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(fixed.map_or(Cow::Borrowed(text), Cow::Owned))
}

/// True for a polyline (`l`) statement.
fn is_polyline(line: &str) -> bool {
    line.split_whitespace().next() == Some("l")
}

/// OBJ text without its polylines, and how many there were. A polyline has no surface to
/// trace, but tobj reads `l` like `f`, so `l 1 2 3` would be drawn as a triangle; each one
/// becomes an empty comment, so line numbers in messages stay right.
fn without_polylines(text: &str) -> (Cow<'_, str>, usize) {
    if !text.lines().any(is_polyline) {
        return (Cow::Borrowed(text), 0);
    }
    let mut out = String::with_capacity(text.len());
    let mut count = 0;
    for line in text.lines() {
        if is_polyline(line) {
            out.push('#');
            count += 1;
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    (Cow::Owned(out), count)
}

/// Vertices (`v`) and triangles (after triangulation; a 1- or 2-corner face counts as one
/// degenerate triangle, as tobj makes it) of OBJ text, counted without parsing numbers.
pub(crate) fn obj_counts(text: &str) -> (u64, u64) {
    let (mut vertices, mut triangles) = (0u64, 0u64);
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertices += 1,
            Some("f") => triangles += (words.count() as u64).saturating_sub(2).max(1),
            _ => {}
        }
    }
    (vertices, triangles)
}

/// The [`Facts`] of OBJ text that the parallel reader leaves to tobj, counted line by line as
/// that reader counts them (polylines skipped).
pub(crate) fn slow_facts(text: &str) -> Facts {
    let (vertices, triangles) = obj_counts(text);
    let mut facts = Facts {
        vertices,
        triangles,
        ..Facts::default()
    };
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("vn") => facts.normals += 1,
            Some("vt") => facts.texcoords += 1,
            Some("l") => facts.polylines += 1,
            _ => {}
        }
        if let Some(rest) = line.trim_start().strip_prefix("usemtl")
            && rest.starts_with([' ', '\t'])
            && !rest.trim().is_empty()
        {
            facts.usemtl.insert(rest.trim().to_string());
        }
    }
    facts
}

/// Bytes the per-vertex normals and texture coordinates of an OBJ may keep (SPEC §3b): the
/// file's `vn` and `vt` and an index triple per triangle for each, or computed normals (three
/// per triangle) for `normals = "smooth"`; 0 for a flat mesh without `vt`.
pub(crate) fn attribute_memory_estimate(facts: &Facts, normals: NormalsMode) -> u64 {
    let (vn, vt, faces) = (facts.normals, facts.texcoords, facts.triangles);
    let per_triangle_index = 12u64;
    let normal_bytes = match normals {
        NormalsMode::Flat => 0,
        NormalsMode::File if vn == 0 => 0,
        NormalsMode::File => vn * 12 + faces * per_triangle_index,
        NormalsMode::Smooth => faces * (36 + per_triangle_index),
    };
    let uv_bytes = if vt == 0 {
        0
    } else {
        vt * 8 + faces * per_triangle_index
    };
    normal_bytes.saturating_add(uv_bytes)
}

/// Refuses an OBJ of `text_bytes` bytes and these `facts` whose reading (with the triangles the
/// scene already has) would exceed `limit`, before the models or triangles are made.
pub(crate) fn check_mesh_memory(
    scene: &Scene,
    text_bytes: usize,
    facts: &Facts,
    limit: &MemoryLimit,
) -> Result<(), String> {
    let (vertices, triangles) = (facts.vertices, facts.triangles);
    let estimate = mesh_memory_estimate(
        text_bytes as u64,
        vertices,
        triangles.saturating_add(scene.triangles.len() as u64),
    );
    let noun = |n: u64, one: &'static str, many: &'static str| if n == 1 { one } else { many };
    let mut what = format!(
        "its {vertices} {} and {triangles} {}",
        noun(vertices, "vertex", "vertices"),
        noun(triangles, "triangle", "triangles")
    );
    if !scene.triangles.is_empty() {
        what += &format!(" (with the scene's {} before it)", scene.triangles.len());
    }
    limit.check(what, estimate).map_err(|e| e.to_string())
}

/// The first line at which the OBJ stops loading, found by bisecting prefixes (tobj's errors
/// carry no position; this runs only on the error path).
fn error_line(text: &str) -> Option<usize> {
    let ends: Vec<usize> = text
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .chain((!text.ends_with('\n')).then_some(text.len()))
        .collect();
    let fails = |lines: usize| {
        let prefix = &text[..ends[lines - 1]];
        !matches!(read_plain(prefix), Ok(Ok(_)))
    };
    let (mut lo, mut hi) = (1, ends.len());
    if hi == 0 || !fails(hi) {
        return None;
    }
    while lo < hi {
        let mid = (lo + hi) / 2;
        if fails(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    Some(lo)
}

/// Adds the OBJ's triangles (placed, degenerate ones dropped) and the MTL materials they use
/// to `scene`; returns how many triangles were added.
pub(crate) fn add_mesh(scene: &mut Scene, req: &MeshRequest) -> Result<usize, ObjProblem> {
    // One pass of the parallel reader counts what the budget and the warnings need; only a
    // text it leaves to tobj is counted line by line.
    let mut scanned =
        quietly(|| obj_parse::scan(req.text, Polylines::Skip)).map_err(|()| ObjProblem {
            line: None,
            reason: "the OBJ reader failed on this file".into(),
        })?;
    // Which faces give `vn`/`vt` at every corner, as that pass saw them.
    let fast_corners = scanned.as_mut().map(Scanned::take_face_corners);
    let facts = match &scanned {
        Some(s) => s.facts().clone(),
        None => slow_facts(req.text),
    };
    check_mesh_memory(scene, req.text.len(), &facts, &memory_limit())
        .map_err(|reason| ObjProblem { line: None, reason })?;
    let attributes = attribute_memory_estimate(&facts, req.normals);
    if attributes > 0 {
        let triangles = facts.triangles;
        let all = mesh_memory_estimate(
            req.text.len() as u64,
            facts.vertices,
            triangles.saturating_add(scene.triangles.len() as u64),
        )
        .saturating_add(attributes);
        memory_limit()
            .check(
                format!("its {triangles} triangles with their normals and texture coordinates"),
                all,
            )
            .map_err(|e| ObjProblem {
                line: None,
                reason: e.to_string(),
            })?;
    }
    let mtl_warnings = RefCell::new(Vec::new());
    // The libraries as read, so that a texture's warning can name its line.
    let mtl_texts: RefCell<Vec<(String, String)>> = RefCell::new(Vec::new());
    let load_mtl = |path: &Path| -> tobj::MTLLoadResult {
        if req.material_override.is_some() {
            return Ok(Default::default());
        }
        let name = short_path(&path.to_string_lossy());
        let text = (req.resolve)(&sibling(req.key, &path.to_string_lossy())).map_err(|reason| {
            mtl_warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` ({reason}); its faces use the default material.",
                req.label
            ));
            tobj::LoadError::OpenFileFailed
        })?;
        mtl_texts.borrow_mut().push((name.clone(), text.clone()));
        let text = mtl_for_tobj(&text).map_err(|(line, reason)| {
            mtl_warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` (line {line}: {reason}); its faces use the default material.",
                req.label
            ));
            tobj::LoadError::MaterialParseError
        })?;
        tobj::load_mtl_buf(&mut text.as_bytes()).inspect_err(|e| {
            mtl_warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` ({e}); its faces use the default material.",
                req.label
            ));
        })
    };
    let polylines = facts.polylines;
    let ((models, mtl_materials), fast) = match load_obj(req.text, scanned, load_mtl) {
        Ok((Ok(loaded), fast)) => (loaded, fast),
        Ok((Err(e), _)) => {
            return Err(ObjProblem {
                line: error_line(req.text),
                reason: e.to_string(),
            });
        }
        Err(reason) => return Err(ObjProblem { line: None, reason }),
    };
    let mtl_materials = mtl_materials.unwrap_or_default();
    // Which faces give `vn`/`vt` at every corner (tobj fills the others from a neighbour).
    let (uvs_in_file, normals_in_file) = models.iter().fold((false, false), |(t, n), m| {
        (
            t || !m.mesh.texcoords.is_empty(),
            n || !m.mesh.normals.is_empty(),
        )
    });
    // The fast reader's pass found them; a file read by tobj is read again for them.
    let face_corners = match (uvs_in_file || normals_in_file, fast_corners) {
        (false, _) => Default::default(),
        (true, Some(found)) if fast => found.only(uvs_in_file, normals_in_file),
        (true, _) => super::obj_corners::face_corners(req.text, uvs_in_file, normals_in_file)
            .map_err(|(line, reason)| ObjProblem {
                line: Some(line),
                reason: reason.into(),
            })?,
    };
    let mut warnings = mtl_warnings.into_inner();
    let mtl_texts = mtl_texts.into_inner();
    if polylines > 0 {
        let s = if polylines == 1 { "" } else { "s" };
        warnings.push(format!(
            "{}: ignored {polylines} polyline{s} (`l`): a line has no surface to show.",
            req.label
        ));
    }
    if req.material_override.is_none() && warnings.is_empty() {
        warn_unknown_usemtl(req.label, &facts, &mtl_materials, &mut warnings);
    }

    let linear = req.placement.linear();
    // Normals go through the inverse transpose, which keeps them perpendicular to the placed
    // surface (and on its outside when a mirroring scale swaps the corners).
    let normal_matrix = linear.inverse().transpose();
    let mirrors = req.placement.mirrors();
    let mut mtl_ids: Vec<Option<MaterialId>> = vec![None; mtl_materials.len()];
    let (mut added, mut dropped, mut too_far) = (0usize, 0usize, 0usize);
    let first_triangle = scene.triangles.len();
    let file_normals = req.normals == NormalsMode::File;
    let mut attrs = MeshAttributes {
        first_triangle: first_triangle as u32,
        ..MeshAttributes::default()
    };
    let mut corners = Corners::default();
    // Which faces give every corner's `vn` (`vt`): flags by triangle in tobj's order, or
    // none when every face does.
    let triangles_read: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    let explicit: &[u8] = match face_corners.triangles.len() == triangles_read {
        true => &face_corners.triangles,
        false => &[],
    };
    let mut triangle_read = 0;
    Arc::make_mut(&mut scene.triangles).reserve(triangles_read);
    for model in &models {
        let mesh = &model.mesh;
        // Per-face normal and texture indices exist only when every face gives them.
        let normal_base = attrs.normals.len() as u32;
        let has_normals = file_normals
            && !mesh.normals.is_empty()
            && mesh.normal_indices.len() == mesh.indices.len();
        if has_normals {
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
        let faces = Faces {
            mesh,
            linear,
            translate: req.placement.translate,
            mirrors,
            normals: has_normals.then_some((&attrs.normals[..], normal_base)),
            uvs: has_uvs.then_some((&attrs.uvs[..], uv_base)),
        };
        // In parallel, straight into the scene's list (then the dropped ones taken out): no
        // per-thread lists, whose memory the allocator would keep after the load.
        let count = mesh.indices.len() / 3;
        let first_read = triangle_read;
        let given = |k: usize, bit: u8| explicit.get(first_read + k).is_none_or(|f| f & bit != 0);
        let start = scene.triangles.len();
        let object = req.object;
        Arc::make_mut(&mut scene.triangles).par_extend(
            (0..count)
                .into_par_iter()
                .map(|k| faces.triangle(k, object)),
        );
        let mut normal_ids: Vec<[u32; 3]> = match faces.normals {
            Some((normals, base)) => {
                let usable = |i: u32| {
                    let n = normals[i as usize];
                    n.is_finite() && n != Vec3::ZERO
                };
                let list = (&mesh.normal_indices[..], base, normals.len() as u32 - base);
                (0..count)
                    .into_par_iter()
                    .map(|k| match given(k, ALL_NORMALS) {
                        true => faces.corner_ids(k, list, &usable),
                        false => [NO_INDEX; 3],
                    })
                    .collect()
            }
            None => Vec::new(),
        };
        let mut uv_ids: Vec<[u32; 3]> = match faces.uvs {
            Some((uvs, base)) => {
                let usable = |i: u32| uvs[i as usize].is_finite();
                let list = (&mesh.texcoord_indices[..], base, uvs.len() as u32 - base);
                (0..count)
                    .into_par_iter()
                    .map(|k| match given(k, ALL_UVS) {
                        true => faces.corner_ids(k, list, &usable),
                        false => [NO_INDEX; 3],
                    })
                    .collect()
            }
            None => Vec::new(),
        };
        // Faces that give an index at every corner, but one out of range or unusable (a face
        // that does not give them all is shaded flat, or untextured, and counted apart).
        let unusable = |ids: &[[u32; 3]], bit: u8| {
            ids.par_iter()
                .enumerate()
                .filter(|&(k, i)| i[0] == NO_INDEX && given(k, bit))
                .count()
        };
        corners.bad_normals += unusable(&normal_ids, ALL_NORMALS);
        corners.bad_uvs += unusable(&uv_ids, ALL_UVS);
        triangle_read += count;
        let fates = |fate: MaterialId| {
            scene.triangles[start..]
                .par_iter()
                .filter(|t| t.material == fate)
                .count()
        };
        let (degenerate, far) = (fates(DEGENERATE), fates(TOO_FAR));
        dropped += degenerate;
        too_far += far;
        let kept = count - degenerate - far;
        // Materials are added on first use, so a scene lists only what it shows.
        let material = (kept > 0).then(|| match (req.material_override, mesh.material_id) {
            (Some(id), _) => id,
            (None, Some(i)) if i < mtl_materials.len() => *mtl_ids[i].get_or_insert_with(|| {
                mtl_material(scene, req, &mtl_materials[i], &mtl_texts, &mut warnings)
            }),
            (None, _) => scene.default_material(),
        });
        if kept < count {
            // Rare: keep the placed ones, in order, with their corner indices.
            let triangles = Arc::make_mut(&mut scene.triangles);
            let mut w = 0;
            for k in 0..count {
                if triangles[start + k].material == PLACED {
                    triangles[start + w] = triangles[start + k];
                    for ids in [&mut normal_ids, &mut uv_ids] {
                        if !ids.is_empty() {
                            ids[w] = ids[k];
                        }
                    }
                    w += 1;
                }
            }
            triangles.truncate(start + w);
            normal_ids.truncate(w);
            uv_ids.truncate(w);
        }
        if let Some(material) = material {
            Arc::make_mut(&mut scene.triangles)[start..]
                .par_iter_mut()
                .for_each(|t| t.material = material);
        }
        for (list, ids) in [
            (&mut corners.normals, normal_ids),
            (&mut corners.uvs, uv_ids),
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
        added += kept;
    }
    if added < scene.triangles.capacity() / 2 {
        Arc::make_mut(&mut scene.triangles).shrink_to_fit();
    }
    let textured = scene.triangles[first_triangle..].iter().any(|t| {
        scene.material(t.material).diffuse_map.is_some()
            || scene.material(t.material).ambient_map.is_some()
    });
    corners.partial_normals = face_corners.partial_normals * usize::from(file_normals);
    corners.partial_uvs = face_corners.partial_uvs;
    finish_attributes(scene, req, attrs, corners, textured, &mut warnings);
    if dropped > 0 {
        let s = if dropped == 1 { "" } else { "s" };
        warnings.push(format!(
            "{}: dropped {dropped} degenerate triangle{s} (zero area or non-finite vertices).",
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
    scene.warnings.extend(warnings);
    Ok(added)
}

/// One model's faces, to be placed in parallel: the model, the placement, and the mesh's
/// normals and texture coordinates so far with the index of this model's first (when its faces
/// give them).
struct Faces<'a> {
    mesh: &'a tobj::Mesh,
    linear: Mat3,
    translate: Vec3,
    mirrors: bool,
    normals: Option<(&'a [Vec3], u32)>,
    uvs: Option<(&'a [Vec2], u32)>,
}

/// The material of a placed triangle until its model's material is known.
const PLACED: MaterialId = MaterialId(u32::MAX);
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
}

/// The normal and texture-coordinate indices of a mesh's kept triangles, while it loads; each
/// list is empty until a model gives some, then as long as the triangles kept up to that
/// model's end ([`finish_attributes`] pads it to the mesh's end).
#[derive(Default)]
struct Corners {
    normals: Vec<[u32; 3]>,
    uvs: Vec<[u32; 3]>,
    /// Faces whose `vn` indices are out of range or name a zero or non-finite normal.
    bad_normals: usize,
    /// Faces whose `vt` indices are out of range or name non-finite coordinates.
    bad_uvs: usize,
    /// Faces with `vn` (`vt`) at some corners only.
    partial_normals: usize,
    partial_uvs: usize,
}

/// Keeps the mesh's normals (from the file, or computed for `normals = "smooth"`) and, when a
/// material of it has a texture, its texture coordinates; adds them to the scene only if there
/// are any, so flat untextured meshes cost nothing. Warns about unusable `vn`/`vt` once each.
fn finish_attributes(
    scene: &mut Scene,
    req: &MeshRequest,
    mut attrs: MeshAttributes,
    corners: Corners,
    textured: bool,
    warnings: &mut Vec<String>,
) {
    let first = attrs.first_triangle as usize;
    let count = scene.triangles.len() - first;
    attrs.triangle_count = count as u32;
    // (count, whether it applies, the verb for one face and for several, what those faces do,
    // and what becomes of them), one warning each.
    let problems = [
        (
            corners.bad_normals,
            true,
            ["names", "name"],
            "normals (`vn`) that are out of range, zero or not finite",
            "shaded flat",
        ),
        (
            corners.partial_normals,
            true,
            ["gives", "give"],
            "normals (`vn`) at some corners only",
            "shaded flat",
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
            warnings.push(faces_warning(
                req.label,
                n,
                [verb_one, verb_many],
                what,
                fate,
            ));
        }
    }
    let mut corners = corners;
    for list in [&mut corners.normals, &mut corners.uvs] {
        if !list.is_empty() {
            list.resize(count, [NO_INDEX; 3]);
        }
    }
    match req.normals {
        NormalsMode::Flat => attrs.normals.clear(),
        NormalsMode::File => {
            if corners.normals.iter().any(|n| n[0] != NO_INDEX) {
                attrs.normal_indices = corners.normals;
            } else {
                attrs.normals.clear();
            }
        }
        NormalsMode::Smooth => {
            let (normals, indices) =
                smooth_normals(&scene.triangles[first..], req.crease_angle_deg);
            attrs.normals = normals;
            attrs.normal_indices = indices;
        }
    }
    if textured && corners.uvs.iter().any(|t| t[0] != NO_INDEX) {
        attrs.uv_indices = corners.uvs;
    } else {
        attrs.uvs.clear();
    }
    attrs.normals.shrink_to_fit();
    attrs.uvs.shrink_to_fit();
    if count > 0 && (!attrs.normal_indices.is_empty() || !attrs.uv_indices.is_empty()) {
        scene.attributes.push(Arc::new(attrs));
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

/// Area-weighted vertex normals for `triangles` (SPEC §3b `normals = "smooth"`): at each corner,
/// the sum of the cross products (twice the area times the unit normal) of the triangles that
/// share the corner's position and whose normal is within `crease_angle_deg` of this
/// triangle's, normalised. Corners are shared by position, so a mesh split into groups or
/// materials is still smooth across them. Returns the normals and each triangle's indices.
pub fn smooth_normals(triangles: &[Triangle], crease_angle_deg: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let key = |p: Vec3| p.to_array().map(|x| (x + 0.0).to_bits());
    let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(triangles.len());
    let corner_ids: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            t.vertices.map(|p| {
                let next = ids.len() as u32;
                *ids.entry(key(p)).or_insert(next)
            })
        })
        .collect();
    // The triangles around each position, as one flat list with offsets.
    let mut start = vec![0u32; ids.len() + 1];
    for c in corner_ids.iter().flatten() {
        start[*c as usize + 1] += 1;
    }
    for i in 0..ids.len() {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; 3 * triangles.len()];
    for (k, c) in corner_ids.iter().enumerate() {
        for &id in c {
            around[fill[id as usize] as usize] = k as u32;
            fill[id as usize] += 1;
        }
    }
    let weighted: Vec<Vec3> = triangles
        .iter()
        .map(|t| (t.vertices[1] - t.vertices[0]).cross(t.vertices[2] - t.vertices[0]))
        .collect();
    let unit: Vec<Vec3> = weighted.iter().map(|w| w.normalize_or_zero()).collect();
    let cos_crease = crease_angle_deg.to_radians().cos();
    let mut normals = Vec::with_capacity(3 * triangles.len());
    let mut indices = Vec::with_capacity(triangles.len());
    for (k, c) in corner_ids.iter().enumerate() {
        let mut idx = [0u32; 3];
        for (slot, &id) in idx.iter_mut().zip(c) {
            let (a, b) = (start[id as usize] as usize, start[id as usize + 1] as usize);
            let mut sum = Vec3::ZERO;
            for &other in &around[a..b] {
                if unit[k].dot(unit[other as usize]) >= cos_crease {
                    sum += weighted[other as usize];
                }
            }
            // The triangle itself is always in its own sum, so this has a direction unless
            // the sum overflowed.
            let n = sum.normalize_or_zero();
            *slot = normals.len() as u32;
            normals.push(if n == Vec3::ZERO { unit[k] } else { n });
        }
        indices.push(idx);
    }
    (normals, indices)
}

/// `usemtl` names ([`Facts::usemtl`]) that no loaded library defines: tobj silently gives
/// those faces no material.
fn warn_unknown_usemtl(
    label: &str,
    facts: &Facts,
    known: &[tobj::Material],
    warnings: &mut Vec<String>,
) {
    let unknown: Vec<&str> = facts
        .usemtl
        .iter()
        .map(String::as_str)
        .filter(|name| !known.iter().any(|m| m.name == *name))
        .collect();
    if !unknown.is_empty() {
        // A handful of names, so that the warning stays one readable sentence.
        let mut names: Vec<String> = unknown
            .iter()
            .take(5)
            .map(|n| format!("`{}`", short(n)))
            .collect();
        if unknown.len() > 5 {
            names.push(format!("{} more", unknown.len() - 5));
        }
        warnings.push(format!(
            "{label}: `usemtl` names materials that no material library defines ({}); their faces use the default material.",
            list_and(&names)
        ));
    }
}

/// The scene material for an MTL material: `<object>/<mtl name>`, reusing a scene material of
/// that name if the scene file defines one (so edited materials survive a save and reload).
fn mtl_material(
    scene: &mut Scene,
    req: &MeshRequest,
    m: &tobj::Material,
    mtl_texts: &[(String, String)],
    warnings: &mut Vec<String>,
) -> MaterialId {
    let name = format!("{}/{}", req.object_name, m.name);
    let id = match scene.materials.iter().position(|x| x.name == name) {
        Some(i) => MaterialId(i as u32),
        None => {
            let material = material_from_mtl(m, name, req.label, warnings);
            scene.materials.push(material);
            MaterialId(scene.materials.len() as u32 - 1)
        }
    };
    // Textures come from the MTL even when a `[[material]]` of this name overrides its
    // colours (a scene file has no texture keys, so a saved scene keeps its textures).
    let mut texture = |key: &str, file: &Option<String>| {
        let file = file.as_deref()?;
        load_texture(scene, req, &m.name, key, file, mtl_texts, warnings)
    };
    let diffuse = texture("map_Kd", &m.diffuse_texture);
    let ambient = texture("map_Ka", &m.ambient_texture);
    let material = &mut scene.materials[id.0 as usize];
    material.diffuse_map = material.diffuse_map.or(diffuse);
    material.ambient_map = material.ambient_map.or(ambient);
    id
}

/// The file a `map_Kd` value names: the value, or its last word when it starts with options
/// (`-s 2 2 1 wood.png`).
fn texture_file(value: &str) -> &str {
    let value = value.trim();
    if value.starts_with('-') {
        value.split_whitespace().last().unwrap_or(value)
    } else {
        value
    }
}

/// The texture `value` of MTL statement `key` of material `material`, loaded once per scene
/// (materials that share a file share the texture); `None` with one warning naming the file
/// and the MTL line when it cannot be read, decoded, or fit in the memory budget.
fn load_texture(
    scene: &mut Scene,
    req: &MeshRequest,
    material: &str,
    key: &str,
    value: &str,
    mtl_texts: &[(String, String)],
    warnings: &mut Vec<String>,
) -> Option<TextureId> {
    let file = texture_file(value);
    let path = sibling(req.key, file);
    if let Some(i) = scene.textures.iter().position(|t| t.name == path) {
        return Some(TextureId(i as u32));
    }
    let place = mtl_texts
        .iter()
        .find_map(|(mtl, text)| {
            text.lines()
                .position(|l| {
                    let l = l.trim_start();
                    l.starts_with(key) && l.contains(file)
                })
                .map(|i| format!("`{mtl}` line {}", i + 1))
        })
        .unwrap_or_else(|| "its material library".into());
    let limit = memory_limit();
    let used: u64 = scene
        .textures
        .iter()
        .map(|t| Texture::bytes(t.width, t.height))
        .sum();
    let left = MemoryLimit {
        bytes: limit.bytes.saturating_sub(used),
        source: limit.source,
    };
    let loaded = (req.resolve_bytes)(&path).and_then(|bytes| {
        quietly(|| decode_texture(&path, &bytes, &left))
            .unwrap_or_else(|()| Err("the image reader failed on it".into()))
    });
    match loaded {
        Ok(texture) => {
            scene.textures.push(Arc::new(texture));
            Some(TextureId(scene.textures.len() as u32 - 1))
        }
        Err(reason) => {
            warnings.push(format!(
                "{}: material `{}` ({place}): cannot use the texture `{}` of `{key}` ({reason}); its flat colour stays.",
                req.label,
                short(material),
                short_path(file)
            ));
            None
        }
    }
}

/// Maps an MTL material to the Phong material: Ka→ambient, Kd→diffuse, Ks→specular,
/// Ns→shininess, Ni→ior, transparency = 1 − d (or Tr); `illum` 3 and 5 (ray-traced
/// reflection) set reflectivity = Ks; 4, 6 and 7 (glass) set reflectivity = Ks and
/// transparency = 1 − d, or 0.9 without `d`. Missing or invalid values fall back to
/// [`Material::default`] (invalid ones with a warning).
pub fn material_from_mtl(
    m: &tobj::Material,
    name: String,
    label: &str,
    warnings: &mut Vec<String>,
) -> Material {
    let d = Material::default();
    let mut invalid = |key: &str, got: String, fallback: String| {
        warnings.push(format!(
            "{label}: material `{}` has an invalid `{key}` {got}; using {fallback}.",
            short(&m.name)
        ));
    };
    let mut rgb = |value: Option<[f32; 3]>, key: &str, fallback: Vec3| match value {
        None => fallback,
        Some(a) => {
            let v = Vec3::from_array(a);
            if v.is_finite() && v.cmpge(Vec3::ZERO).all() {
                v
            } else {
                invalid(key, format!("{a:?}"), format!("{fallback}"));
                fallback
            }
        }
    };
    let ambient = rgb(m.ambient, "Ka", d.ambient);
    let diffuse = rgb(m.diffuse, "Kd", d.diffuse);
    let specular = rgb(m.specular, "Ks", d.specular);
    let mut scalar = |value: Option<f32>, key: &str, ok: fn(f32) -> bool, fallback: f32| match value
    {
        Some(x) if x.is_finite() && ok(x) => Some(x),
        Some(x) => {
            let fb = fallback.to_string();
            warnings.push(format!(
                "{label}: material `{}` has an invalid `{key}` {x}; using {fb}.",
                short(&m.name)
            ));
            None
        }
        None => None,
    };
    let shininess = scalar(m.shininess, "Ns", |x| x >= 0.0, d.shininess).unwrap_or(d.shininess);
    // `Ns 0` with a `Ks` (MeshLab writes `Ns 0` and `Ks 1` meaning "no highlight"): an
    // exponent of 0 would add the whole `Ks` wherever the light falls and wash the model out.
    // The highlight is dropped; a mirror's reflectivity (`Ks`, below) is kept.
    let no_highlight = m.shininess.is_some() && shininess == 0.0 && specular != Vec3::ZERO;
    let ior = scalar(m.optical_density, "Ni", |x| x > 0.0, d.ior).unwrap_or(d.ior);
    let in_unit = |x: f32| (0.0..=1.0).contains(&x);
    let glass = matches!(m.illumination_model, Some(4 | 6 | 7));
    let mut tr_opaque = false;
    let dissolve = scalar(m.dissolve, "d", in_unit, 1.0).or_else(|| {
        let tr = m
            .unknown_param
            .get("Tr")
            .and_then(|t| t.trim().parse::<f32>().ok());
        // `Tr 1` without `d` on a material that is not glass: MeshLab and others write it
        // meaning opaque (Tr as opacity); an invisible material is never what is meant.
        scalar(tr, "Tr", in_unit, 0.0).map(|tr| {
            tr_opaque = tr == 1.0 && !glass;
            if tr_opaque { 1.0 } else { 1.0 - tr }
        })
    });
    if tr_opaque {
        warnings.push(format!(
            "{label}: material `{}` has `Tr 1` (fully transparent) but is not glass; taken as opaque, as MeshLab means it.",
            short(&m.name)
        ));
    }
    if no_highlight {
        warnings.push(format!(
            "{label}: material `{}` has `Ns 0`, which would add all of `Ks` wherever light falls; shown without a highlight (`Ks 0`).",
            short(&m.name)
        ));
    }
    let mirror = glass || matches!(m.illumination_model, Some(3 | 5));
    let transparency = match dissolve {
        Some(dissolve) => 1.0 - dissolve,
        None if glass => 0.9,
        None => 0.0,
    };
    Material {
        name,
        ambient,
        diffuse,
        specular: if no_highlight { Vec3::ZERO } else { specular },
        shininess,
        reflectivity: if mirror { specular } else { Vec3::ZERO },
        transparency: Vec3::splat(transparency),
        ior,
        diffuse_map: None,
        ambient_map: None,
    }
}

#[cfg(test)]
mod tests {

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
    use super::*;

    #[test]
    fn siblings_share_the_folder() {
        assert_eq!(sibling("models/a.obj", "a.mtl"), "models/a.mtl");
        assert_eq!(sibling("a.obj", "a.mtl"), "a.mtl");
        assert_eq!(sibling("../m/a.obj", "x/a.mtl"), "../m/x/a.mtl");
    }

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

    #[test]
    fn error_lines_are_found() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 x\nf 1 2 3\n";
        assert_eq!(error_line(text), Some(4));
    }

    #[test]
    fn mtl_colours_of_one_number_are_spelled_out_and_two_are_refused() {
        let text = "newmtl a\nKd 0.8\nKs 1 2 3\n";
        assert_eq!(
            mtl_for_tobj(text).expect("one number is valid MTL"),
            "newmtl a\nKd 0.8 0.8 0.8\nKs 1 2 3\n"
        );
        assert!(matches!(mtl_for_tobj("Ka 1 2 3\n"), Ok(Cow::Borrowed(_))));
        let e = mtl_for_tobj("newmtl a\n\nKa 1 2\n").expect_err("two numbers");
        assert_eq!(
            e,
            (3, "`Ka` needs one number or three (r g b), got 2".into())
        );
        assert!(mtl_for_tobj("Ke\n").is_err());
        // Not numbers: tobj's own error, not ours.
        assert!(mtl_for_tobj("Kd x y\n").is_ok());
        // tobj itself panics on these; through `mtl_for_tobj` it never sees them.
        for bad in ["newmtl a\nKd 1 2\n", "newmtl a\nKs\n"] {
            assert!(quietly(|| tobj::load_mtl_buf(&mut bad.as_bytes())).is_err());
        }
    }

    #[test]
    fn panics_in_quietly_are_caught_and_others_still_reported() {
        assert_eq!(quietly(|| 7), Ok(7));
        assert_eq!(quietly(|| -> i32 { panic!("hostile") }), Err(()));
        assert!(!QUIET.with(Cell::get), "the flag is reset after the panic");
    }

    #[test]
    fn meshes_over_the_memory_limit_are_refused_before_reading() {
        let limit = MemoryLimit {
            bytes: 1 << 20,
            source: "a test".into(),
        };
        let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
        assert_eq!(obj_counts("f 1 2 3 4 5\nl 1 2\nf 1\nv 1 1 1\n"), (1, 4));
        let (stripped, n) = without_polylines("v 0 0 0\n l 1 2 3\nf 1 1 1\n");
        assert_eq!((stripped.as_ref(), n), ("v 0 0 0\n#\nf 1 1 1\n", 1));
        let check = |text: &str| {
            let facts = obj_parse::scan(text, Polylines::Skip).expect("the fast reader takes it");
            assert_eq!(*facts.facts(), slow_facts(text));
            check_mesh_memory(&Scene::default(), text.len(), facts.facts(), &limit)
        };
        assert!(check(&text).is_ok());
        text += &"f 1 2 3\n".repeat(3000);
        let e = check(&text).expect_err("over 1 MiB");
        assert_eq!(
            e,
            "its 3 vertices and 3000 triangles would need about 1.3 MiB, more than the memory \
             limit of 1.0 MiB (a test)"
        );
    }

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
}
