//! The first look of a bare `.obj` (SPEC §3b): one object with its MTL materials, a low
//! ambient light (Blender's `Ka 1` read as `Kd`), a key light and a headlight, and a camera
//! framed on the bounds, or standing inside them when the model is a room.

use glam::Vec3;

use super::diag::{SceneError, list_and, short};
use super::obj::{MeshPlacement, MeshRequest, add_mesh, file_stem};
use super::rules::check_camera;
use super::{
    Camera, DEFAULT_CREASE_ANGLE_DEG, Light, NormalsMode, Object, ObjectId, ObjectSource,
    ResolveBytesFn, ResolveFn, Scene, Triangle,
};

/// A bare `.obj` as a scene: one object, its MTL materials, the default render settings, a
/// camera framed on the bounds and one white light named "key". `label` names the file in
/// messages; `key` is its path for the resolver (MTL files are found next to it).
pub(crate) fn load_obj_scene(
    text: &str,
    label: &str,
    key: &str,
    resolve: &ResolveFn<'_>,
    resolve_bytes: &ResolveBytesFn<'_>,
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
            normals: NormalsMode::default(),
            crease_angle_deg: DEFAULT_CREASE_ANGLE_DEG,
        },
    });
    let request = MeshRequest {
        object: ObjectId(0),
        object_name: &name,
        label,
        key,
        text,
        resolve,
        resolve_bytes,
        material_override: None,
        placement: &placement,
        normals: NormalsMode::default(),
        crease_angle_deg: DEFAULT_CREASE_ANGLE_DEG,
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
    // A readable first look (issue 14.4): a low ambient light, so that Blender's `Ka 1` does
    // not wash everything out, and such an ambient read as the diffuse colour.
    scene.render.ambient_light = Vec3::splat(BARE_OBJ_AMBIENT);
    let mut washed = Vec::new();
    for m in &mut scene.materials {
        if m.ambient == Vec3::ONE && m.name.starts_with(&format!("{name}/")) {
            m.ambient = m.diffuse;
            washed.push(format!("`{}`", short(&m.name[name.len() + 1..])));
        }
    }
    if !washed.is_empty() {
        scene.warnings.push(format!(
            "{label}: `Ka 1` (Blender's default) in {} taken as the diffuse colour `Kd`, under an ambient light of {BARE_OBJ_AMBIENT}.",
            list_and(&washed)
        ));
    }
    let (lo, hi) = scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
    let center = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let room = encloses(&scene.triangles, center);
    let camera = if room {
        // Inside a closed model (a room): stand at eye height near the +z wall, looking in.
        Camera {
            position: center + Vec3::new(0.0, 0.0, 0.7 * half.z),
            look_at: center - Vec3::new(0.0, 0.0, half.z),
            fov_y_deg: 60.0,
            ..Camera::default()
        }
    } else {
        // From the +z side, slightly above, the whole model in view.
        Camera::default().framing(lo, hi, Vec3::new(0.0, 0.3, 1.0).normalize())
    };
    if check_camera(&camera).is_err() {
        return Err(SceneError(format!(
            "{label}: cannot frame a camera on the OBJ: its bounds {lo} to {hi} are too large (the camera would stand beyond ±1e15, raytree's limit on scene size) or too small to look at in f32."
        )));
    }
    let forward = (camera.look_at - camera.position).normalize();
    let distance = camera.position.distance(camera.look_at);
    let key = if room {
        // Under the ceiling, above the middle of the room.
        center + Vec3::new(0.0, 0.8 * half.y, 0.0)
    } else {
        // Above the camera and a little in front of it, so the side we see is lit and
        // shadows fall behind and below the model.
        camera.position + Vec3::Y * (0.5 * distance) + forward * (0.2 * distance)
    };
    scene.lights.push(Light {
        name: "key".into(),
        position: key,
        color: Vec3::splat(0.8),
        radius: 0.0,
        follow_camera: false,
    });
    // A headlight that follows the camera, as model viewers have: what the camera sees is lit.
    scene.lights.push(Light {
        name: "headlight".into(),
        position: camera.position,
        color: Vec3::splat(0.35),
        radius: 0.0,
        follow_camera: true,
    });
    if room {
        scene.warnings.push(format!(
            "{label}: the model is closed around its centre (a room): the camera starts inside it."
        ));
    }
    scene.camera = camera;
    Ok(scene)
}

/// The ambient light of a bare OBJ.
pub const BARE_OBJ_AMBIENT: f32 = 0.1;

/// True when the model is a room around `point`: rays from it in 14 directions (the axes and
/// the diagonals) all meet a triangle, and at least 10 of the nearest ones face `point` (the
/// walls face inwards). A closed solid such as a statue also surrounds its middle, but from
/// inside its triangles are seen from the back. Brute force in parallel (a million triangles:
/// 14 million tests, a few tens of milliseconds).
fn encloses(triangles: &[Triangle], point: Vec3) -> bool {
    use rayon::prelude::*;
    let mut dirs: Vec<Vec3> = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for x in [-1.0f32, 1.0] {
        for y in [-1.0f32, 1.0] {
            for z in [-1.0f32, 1.0] {
                dirs.push(Vec3::new(x, y, z).normalize());
            }
        }
    }
    // For each direction: nothing met, or whether the nearest triangle faces `point`.
    let nearest = |d: Vec3| -> Option<bool> {
        let mut best: Option<(f32, bool)> = None;
        for t in triangles {
            // Möller–Trumbore, both sides.
            let [a, b, c] = t.vertices;
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-12 {
                continue;
            }
            let inv = 1.0 / det;
            let s = point - a;
            let u = s.dot(p) * inv;
            let q = s.cross(e1);
            let v = d.dot(q) * inv;
            let dist = e2.dot(q) * inv;
            if u >= 0.0
                && v >= 0.0
                && u + v <= 1.0
                && dist > 0.0
                && best.is_none_or(|(b, _)| dist < b)
            {
                best = Some((dist, e1.cross(e2).dot(d) < 0.0));
            }
        }
        best.map(|(_, facing)| facing)
    };
    let hits: Vec<Option<bool>> = dirs.par_iter().map(|&d| nearest(d)).collect();
    hits.iter().all(Option::is_some) && hits.iter().filter(|h| **h == Some(true)).count() >= 10
}
