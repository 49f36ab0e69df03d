//! OBJ meshes and their MTL materials, through `tobj` (SPEC §3): positions only (shading is
//! flat, from the triangle's own normal), faces triangulated, the Phong material mapped from
//! `Ka`/`Kd`/`Ks`/`Ns`/`Ni`/`d`/`Tr`/`illum`, and the mesh placed by scale, rotation (X then Y
//! then Z, in degrees) and translation. Degenerate triangles are dropped here, at load time,
//! and counted in one warning, so the tracer never meets them. Also opens a bare `.obj` as a
//! whole scene with a camera framed on it.

use std::cell::RefCell;
use std::collections::BTreeSet;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use glam::{Mat3, Vec3};

use super::load::{ResolveFn, SceneError, check_camera, default_material};
use super::{Camera, Light, Material, MaterialId, Object, ObjectId, ObjectSource, Scene, Triangle};

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

/// True if the triangle can be seen: finite corners and a finite, non-zero cross product.
pub fn is_visible_triangle(v: &[Vec3; 3]) -> bool {
    let cross = (v[1] - v[0]).cross(v[2] - v[0]);
    v.iter().all(|p| p.is_finite()) && cross.is_finite() && cross != Vec3::ZERO
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
    /// A scene material for every face instead of the MTL's.
    pub material_override: Option<MaterialId>,
    pub placement: &'a MeshPlacement,
}

fn load_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    }
}

/// Runs `tobj` with panics caught: hostile files must never take the program down (SPEC §9).
fn load_obj(
    text: &str,
    load_mtl: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<tobj::LoadResult, String> {
    catch_unwind(AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &load_options(), load_mtl)
    }))
    .map_err(|_| "the OBJ reader failed on this file".to_string())
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
        !matches!(load_obj(prefix, |_| Ok(Default::default())), Ok(Ok(_)))
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
    let mtl_warnings = RefCell::new(Vec::new());
    let load_mtl = |path: &Path| -> tobj::MTLLoadResult {
        if req.material_override.is_some() {
            return Ok(Default::default());
        }
        let name = path.to_string_lossy();
        let text = (req.resolve)(&sibling(req.key, &name)).map_err(|reason| {
            mtl_warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` ({reason}); its faces use the default material.",
                req.label
            ));
            tobj::LoadError::OpenFileFailed
        })?;
        tobj::load_mtl_buf(&mut text.as_bytes()).inspect_err(|e| {
            mtl_warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` ({e}); its faces use the default material.",
                req.label
            ));
        })
    };
    let (models, mtl_materials) = match load_obj(req.text, load_mtl) {
        Ok(Ok(loaded)) => loaded,
        Ok(Err(e)) => {
            return Err(ObjProblem {
                line: error_line(req.text),
                reason: e.to_string(),
            });
        }
        Err(reason) => return Err(ObjProblem { line: None, reason }),
    };
    let mtl_materials = mtl_materials.unwrap_or_default();
    let mut warnings = mtl_warnings.into_inner();
    if req.material_override.is_none() && warnings.is_empty() {
        warn_unknown_usemtl(req, &mtl_materials, &mut warnings);
    }

    let linear = req.placement.linear();
    let mirrors = req.placement.mirrors();
    let mut mtl_ids: Vec<Option<MaterialId>> = vec![None; mtl_materials.len()];
    let (mut added, mut dropped) = (0usize, 0usize);
    for model in &models {
        let mesh = &model.mesh;
        let mut material = None;
        let corner = |index: u32| {
            let i = index as usize * 3;
            mesh.positions
                .get(i..i + 3)
                .map_or(Vec3::NAN, |p| Vec3::new(p[0], p[1], p[2]))
        };
        for face in mesh.indices.chunks_exact(3) {
            let mut v =
                [face[0], face[1], face[2]].map(|i| linear * corner(i) + req.placement.translate);
            if mirrors {
                v.swap(1, 2);
            }
            if !is_visible_triangle(&v) {
                dropped += 1;
                continue;
            }
            // Materials are added on first use, so a scene lists only what it shows.
            let id =
                *material.get_or_insert_with(|| match (req.material_override, mesh.material_id) {
                    (Some(id), _) => id,
                    (None, Some(i)) if i < mtl_materials.len() => {
                        *mtl_ids[i].get_or_insert_with(|| {
                            mtl_material(scene, req, &mtl_materials[i], &mut warnings)
                        })
                    }
                    (None, _) => default_material(scene),
                });
            scene.triangles.push(Triangle {
                vertices: v,
                material: id,
                object: req.object,
            });
            added += 1;
        }
    }
    if dropped > 0 {
        let s = if dropped == 1 { "" } else { "s" };
        warnings.push(format!(
            "{}: dropped {dropped} degenerate triangle{s} (zero area or non-finite vertices).",
            req.label
        ));
    }
    scene.warnings.extend(warnings);
    Ok(added)
}

/// `usemtl` names that no loaded library defines: tobj silently gives those faces no material.
fn warn_unknown_usemtl(req: &MeshRequest, known: &[tobj::Material], warnings: &mut Vec<String>) {
    let unknown: BTreeSet<&str> = req
        .text
        .lines()
        .filter_map(|line| line.trim_start().strip_prefix("usemtl"))
        .filter(|rest| rest.starts_with([' ', '\t']))
        .map(str::trim)
        .filter(|name| !name.is_empty() && !known.iter().any(|m| m.name == *name))
        .collect();
    if !unknown.is_empty() {
        let names: Vec<String> = unknown.iter().map(|n| format!("`{n}`")).collect();
        warnings.push(format!(
            "{}: `usemtl` names materials that no material library defines ({}); their faces use the default material.",
            req.label,
            super::load::list_and(&names)
        ));
    }
}

/// The scene material for an MTL material: `<object>/<mtl name>`, reusing a scene material of
/// that name if the scene file defines one (so edited materials survive a save and reload).
fn mtl_material(
    scene: &mut Scene,
    req: &MeshRequest,
    m: &tobj::Material,
    warnings: &mut Vec<String>,
) -> MaterialId {
    let name = format!("{}/{}", req.object_name, m.name);
    if let Some(i) = scene.materials.iter().position(|x| x.name == name) {
        return MaterialId(i as u32);
    }
    let material = material_from_mtl(m, name, req.label, warnings);
    scene.materials.push(material);
    MaterialId(scene.materials.len() as u32 - 1)
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
            m.name
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
                m.name
            ));
            None
        }
        None => None,
    };
    let shininess = scalar(m.shininess, "Ns", |x| x >= 0.0, d.shininess).unwrap_or(d.shininess);
    let ior = scalar(m.optical_density, "Ni", |x| x > 0.0, d.ior).unwrap_or(d.ior);
    let in_unit = |x: f32| (0.0..=1.0).contains(&x);
    let dissolve = scalar(m.dissolve, "d", in_unit, 1.0).or_else(|| {
        let tr = m
            .unknown_param
            .get("Tr")
            .and_then(|t| t.trim().parse::<f32>().ok());
        scalar(tr, "Tr", in_unit, 0.0).map(|tr| 1.0 - tr)
    });
    let glass = matches!(m.illumination_model, Some(4 | 6 | 7));
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
        specular,
        shininess,
        reflectivity: if mirror { specular } else { Vec3::ZERO },
        transparency: Vec3::splat(transparency),
        ior,
    }
}

/// A bare `.obj` as a scene: one object, its MTL materials, the default render settings, a
/// camera framed on the bounds and one white light named "key". `label` names the file in
/// messages; `key` is its path for the resolver (MTL files are found next to it).
pub(crate) fn load_obj_scene(
    text: &str,
    label: &str,
    key: &str,
    resolve: &ResolveFn<'_>,
) -> Result<Scene, SceneError> {
    let name = file_stem(key).unwrap_or_else(|| "mesh".into());
    let placement = MeshPlacement::default();
    let mut scene = Scene::default();
    scene.objects.push(Object {
        name: name.clone(),
        source: ObjectSource::Mesh {
            file: key.to_string(),
            material: None,
            translate: placement.translate,
            rotate_deg: placement.rotate_deg,
            scale: placement.scale,
        },
    });
    let request = MeshRequest {
        object: ObjectId(0),
        object_name: &name,
        label,
        key,
        text,
        resolve,
        material_override: None,
        placement: &placement,
    };
    let added = add_mesh(&mut scene, &request).map_err(|p| {
        let at = p.line.map(|l| format!(":{l}")).unwrap_or_default();
        SceneError(format!("{label}{at}: cannot load the OBJ: {}.", p.reason))
    })?;
    if added == 0 {
        return Err(SceneError(format!(
            "{label}: the OBJ has no triangles to show (it has no faces, or only degenerate ones)."
        )));
    }
    let (lo, hi) = scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
    let camera = frame(lo, hi, Camera::default().fov_y_deg);
    if check_camera(&camera).is_err() || !camera.position.is_finite() {
        return Err(SceneError(format!(
            "{label}: cannot frame a camera on the OBJ: its bounds {lo} to {hi} are too large or too small to look at in f32."
        )));
    }
    let forward = (camera.look_at - camera.position).normalize();
    let distance = camera.position.distance(camera.look_at);
    scene.lights.push(Light {
        name: "key".into(),
        // Above the camera and a little in front of it, so the side we see is lit and
        // shadows fall behind and below the model.
        position: camera.position + Vec3::Y * (0.5 * distance) + forward * (0.2 * distance),
        color: Vec3::ONE,
        radius: 0.0,
    });
    scene.camera = camera;
    Ok(scene)
}

/// A camera on the +z side, slightly above, looking at the bounds' centre from far enough that
/// the bounding sphere fits the vertical field of view (with a small margin).
pub fn frame(lo: Vec3, hi: Vec3, fov_y_deg: f32) -> Camera {
    let center = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    let distance = 1.1 * radius / (0.5 * fov_y_deg).to_radians().sin();
    let direction = Vec3::new(0.0, 0.3, 1.0).normalize();
    Camera {
        position: center + direction * distance,
        look_at: center,
        up: Vec3::Y,
        fov_y_deg,
    }
}

#[cfg(test)]
mod tests {
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
