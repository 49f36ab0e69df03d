//! The first look of a bare `.obj` (docs/design.md, "Scene files"): one object with its MTL
//! materials, a low ambient light (Blender's `Ka 1` read as `Kd`), a key light and a headlight, and
//! a camera framed on the bounds, or standing inside them when the model is a room.

use glam::Vec3;

use super::diag::{SceneError, list_some, short};
use super::obj::{MeshPlacement, MeshRequest, add_mesh, file_stem};
use super::resolve::{ResolveBytesFn, ResolveFn};
use super::rules::{MAX_COORDINATE, check_camera};
use super::{
    Camera, DEFAULT_CREASE_ANGLE_DEG, Light, NormalsMode, Object, ObjectId, ObjectSource, Scene,
    Triangle,
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
    if added.triangles == 0 {
        return Err(SceneError(nothing_to_show(label, text)));
    }
    // A readable first look: a low ambient light, so that Blender's `Ka 1` does
    // not wash everything out, and such an ambient read as the diffuse colour.
    scene.render.ambient_light = Vec3::splat(BARE_OBJ_AMBIENT);
    let prefix = format!("{name}/");
    let own = scene
        .materials
        .iter()
        .filter(|m| m.name.starts_with(&prefix))
        .count();
    // The diffuse colour includes its texture: with `map_Kd` and no `map_Ka`, the ambient term
    // takes the texture too, so a side in shadow shows the texture darkened, not flat grey.
    let mut washed = Vec::new();
    for m in &mut scene.materials {
        let untextured = m.diffuse_map.is_some() && m.ambient_map.is_none();
        let changes = m.diffuse != Vec3::ONE || untextured;
        if m.ambient == Vec3::ONE && changes && m.name.starts_with(&prefix) {
            m.ambient = m.diffuse;
            if untextured {
                m.ambient_map = m.diffuse_map;
                m.ambient_map_placement = m.diffuse_map_placement;
            }
            washed.push(format!("`{}`", short(&m.name[prefix.len()..])));
        }
    }
    if !washed.is_empty() {
        // Blender writes `Ka 1` on every material: "all 40 materials" says more than forty names.
        let which = if washed.len() == own && own > 2 {
            format!("all {own} materials")
        } else {
            list_some(&washed)
        };
        scene.warnings.push(format!(
            "{label}: `Ka 1` (Blender's default) in {which} taken as the diffuse colour `Kd`, under an ambient light of {BARE_OBJ_AMBIENT}."
        ));
    }
    // A material black in every colour it shows (`Kd 0` and `Ka 0` without a texture, neither
    // mirror nor glass; Blender writes that for a model whose look was a node graph or a bump
    // map only, with `d 0.75` when it was a little see-through) leaves the model invisible on
    // the dark background: shown in the default grey, its transparency kept. A material more
    // transparent than opaque is glass, and its look is what it lets through.
    let mut black = Vec::new();
    let grey = super::Material::default();
    for m in &mut scene.materials {
        let shows_nothing = m.diffuse == Vec3::ZERO
            && m.ambient == Vec3::ZERO
            && m.diffuse_map.is_none()
            && m.ambient_map.is_none()
            && m.reflectivity == Vec3::ZERO
            && m.transparency.max_element() < 0.5;
        if shows_nothing && m.name.starts_with(&prefix) {
            m.diffuse = grey.diffuse;
            m.ambient = grey.diffuse;
            black.push(format!("`{}`", short(&m.name[prefix.len()..])));
        }
    }
    if !black.is_empty() {
        scene.warnings.push(format!(
            "{label}: {} black in every colour (`Kd 0`, `Ka 0`, no texture): shown in grey so that the model can be seen.",
            if black.len() == 1 {
                format!("material {} is", black[0])
            } else {
                format!("materials {} are", list_some(&black))
            }
        ));
    }
    // `Ns 0` with a `Ks` is read where every MTL material is (`material_from_mtl` in
    // src/scene/obj/mtl.rs), for a bare OBJ and a scene's `[[mesh]]` alike.
    let (lo, hi) = scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
    let mut up = up_axis(&scene.triangles, lo, hi);
    if up == Vec3::Z {
        scene.warnings.push(format!(
            "{label}: the model stands on a flat base at its lowest z and is tallest in z: +z is taken as up."
        ));
    }
    let aspect = scene.render.width.max(1) as f32 / scene.render.height.max(1) as f32;
    // A model whose detail is a small part of its bounds is framed on its detail.
    let detail = detail(&scene.triangles, lo, hi);
    if scene.spheres.is_empty() {
        // `lo..hi` are the triangles' own bounds: the scene view frames the same detail.
        super::remember_detail_bounds(&scene.triangles, detail.as_ref().map(|d| d.bounds));
    }
    // The Morton order of every triangle, for the rays through the rest of the model.
    let all_order = detail.as_ref().map(|_| morton_order(&scene.triangles));
    let (framed, (lo, hi)) = Detail::framed(&detail, &scene.triangles, (lo, hi));
    let mut look = first_view(framed, lo, hi, up, aspect);
    // Without `vn`, the winding alone says which side of a face is its front. A model that
    // opens as a room but whose faces face inwards and cover little of its bounds' sides (a
    // scanned statue or an animal wound clockwise, where a room's walls, floor and ceiling lie
    // on its bounds), is a thing wound the wrong way round: seen from outside.
    if look.room.is_some() && !added.gives_normals && faces_inward(framed, lo, hi) {
        look = first_view_outside(framed, lo, hi, up, aspect);
        scene.warnings.push(format!(
            "{label}: the model's faces are wound clockwise seen from outside (they face inwards, and no `vn` says otherwise), yet it is no room: it is seen from outside."
        ));
    }
    // A room is wider and longer than it is high. Seen y-up, a room whose z extent is clearly
    // its lowest (below `ROOM_Z_UP` of its y extent) was written z-up (3ds Max, SketchUp's
    // z-up exports, CAD): it is looked at again with +z up, and taken so if it is a room then.
    // So is a tray or a box without a lid, open above once z is up.
    let extent = hi - lo;
    if up == Vec3::Y
        && look.room.is_some()
        && extent.z < ROOM_Z_UP * extent.y
        && extent.z < ROOM_Z_UP * extent.x
    {
        let z_up = first_view(framed, lo, hi, Vec3::Z, aspect);
        let what = match (z_up.room.is_some(), z_up.open_above) {
            (true, _) => Some("the room is lower in z than it is wide and deep (in x and y)"),
            (false, true) => Some(
                "the model is lower in z than it is wide and deep (in x and y), with walls around its middle open towards +z (a tray, a box without a lid)",
            ),
            (false, false) => None,
        };
        if let Some(what) = what {
            (up, look) = (Vec3::Z, z_up);
            scene
                .warnings
                .push(format!("{label}: {what}: +z is taken as up."));
        }
    }
    // Framed on its detail from outside, the camera may stand behind the rest of the model (a
    // tunnel's wall): it moves to where the rest leaves it room to see.
    let outside = |p: Vec3| !(p.cmpge(lo).all() && p.cmple(hi).all());
    if let (Some(d), Some(all_order)) = (&detail, &all_order) {
        let moved = outside(look.camera.position)
            .then(|| d.clear_view(&scene.triangles, all_order, &look.camera, aspect))
            .flatten();
        let how = if let Some(camera) = moved {
            (look.camera, look.room) = (camera, None);
            ", from inside the rest, which hides it from outside"
        } else {
            ""
        };
        scene.warnings.push(format!(
            "{label}: most of the model's faces lie in a small part of its bounds (a model on a ground plane far larger than it, a train in a long tunnel): the camera frames that part{how}."
        ));
    }
    let camera = look.camera;
    if check_camera(&camera).is_err() {
        return Err(SceneError(format!(
            "{label}: cannot frame a camera on the OBJ: its bounds {lo} to {hi} are too large (the camera would stand beyond ±1e15, raytree's limit on scene size) or too small to look at in f32."
        )));
    }
    let forward = (camera.look_at - camera.position).normalize();
    let distance = camera.position.distance(camera.look_at);
    let key = match look.room {
        // Under the ceiling, above the middle of the room (lower when that spot is inside
        // something, a lamp for example).
        Some(room) => room.light,
        // Above the camera and a little in front of it, so the side we see is lit and
        // shadows fall behind and below the model.
        None => {
            let above = camera.position + forward * (0.2 * distance);
            // Framed on its detail, the camera may stand inside the rest (a tunnel): the
            // light stays under what is above it.
            let room = (all_order.as_ref()).map_or(f32::INFINITY, |order| {
                free_run(&scene.triangles, order, above, up)
            });
            above + up * (0.5 * distance).min(0.8 * room)
        }
    };
    scene.lights.push(Light {
        name: "key".into(),
        position: key,
        color: Vec3::splat(KEY),
        radius: 0.0,
        follow_camera: false,
    });
    // A headlight that follows the camera, as model viewers have: what the camera sees is lit.
    scene.lights.push(Light {
        name: "headlight".into(),
        position: camera.position,
        color: Vec3::splat(HEADLIGHT),
        radius: 0.0,
        follow_camera: true,
    });
    if let Some(room) = look.room {
        scene.warnings.push(format!(
            "{label}: {}.",
            match room.entry {
                // Seen from outside: a Cornell box, a stage set, or a thing (a well under its
                // roof) whose middle is walled in but for one side.
                Entry::OpenSide =>
                    "the model has walls around its middle and is open on one side (as a Cornell box or a stage set is): it is seen level through the opening",
                Entry::Doorway =>
                    "the model is closed around its middle (a room) and one wall has an opening: the camera stands in it and looks in",
                Entry::Inside =>
                    "the model is closed around its middle (a room): the camera starts inside it",
            }
        ));
    }
    scene.camera = camera;
    Ok(scene)
}

/// A bare OBJ's first look framed again for the image's aspect, after its size changed from
/// the one it was framed for (`raytree render x.obj --width 640 --height 300`): a camera that
/// looks at the model from outside keeps its direction and moves to the distance that fits the
/// new aspect, and the key light, which stood in proportion to that distance, moves with it.
/// A camera inside the model (a room), or a scene that is no bare OBJ, is left alone.
pub fn refit_bare_obj(scene: &mut Scene) {
    let bare = scene
        .source
        .as_ref()
        .and_then(|p| p.extension())
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let Some((lo, hi)) = scene.bounds() else {
        return;
    };
    let camera = scene.camera.clone();
    let outside = !(camera.position.cmpge(lo).all() && camera.position.cmple(hi).all());
    if !bare || !outside {
        return;
    }
    let detail = detail(&scene.triangles, lo, hi);
    let (framed, (lo, hi)) = Detail::framed(&detail, &scene.triangles, (lo, hi));
    let center = 0.5 * (lo + hi);
    if camera.look_at.distance(center) > 1e-4 * (hi - lo).length() {
        return;
    }
    let back = camera.position - center;
    let distance = back.length();
    if !(distance > 0.0 && distance.is_finite()) {
        return;
    }
    let aspect = scene.render.width.max(1) as f32 / scene.render.height.max(1) as f32;
    let refit = frame_outside(framed, center, camera.up, back / distance, 0.0, aspect);
    let scale = refit.position.distance(center) / distance;
    if check_camera(&refit).is_err() || !scale.is_finite() {
        return;
    }
    scene.camera.position = refit.position;
    for light in &mut scene.lights {
        if light.name == "key" && !light.follow_camera {
            light.position = center + (light.position - center) * scale;
        }
    }
}

/// The share of a model's triangles its detail is looked for in ([`detail`]).
const DETAIL: f32 = 0.75;

/// A model whose detail ([`detail`]) spans less than this fraction of its bounds' diagonal is
/// framed on its detail.
const SMALL_DETAIL: f32 = 0.1;

/// Where most of a model's faces lie, when that is a small part of its bounds.
pub(super) struct Detail {
    /// The bounds of `triangles`.
    pub(super) bounds: (Vec3, Vec3),
    /// The triangles in it.
    triangles: Vec<Triangle>,
}

/// How many bins per axis [`detail`] counts the triangles' centroids in.
const DETAIL_BINS: usize = 1024;

/// A model's detail, when it lies in a small part of its bounds `lo..hi` (a model on a ground
/// plane hundreds of times its size, a train in a tunnel a hundred times its length): per
/// axis, the shortest run of [`DETAIL_BINS`] bins across the bounds that holds [`DETAIL`] of
/// the triangles' centroids; the triangles with every corner in the box of those runs grown by
/// half its size each way. None when that box spans [`SMALL_DETAIL`] of the bounds' diagonal
/// or more.
pub(super) fn detail(triangles: &[Triangle], lo: Vec3, hi: Vec3) -> Option<Detail> {
    use rayon::prelude::*;
    let n = triangles.len();
    let k = (DETAIL * n as f32).ceil() as usize;
    let size = hi - lo;
    if n == 0 || size.length().is_nan() || size.length() <= 0.0 {
        return None;
    }
    let bin = |v: f32, axis: usize| {
        let f = (v - lo[axis]) / size[axis] * DETAIL_BINS as f32;
        (f.max(0.0) as usize).min(DETAIL_BINS - 1)
    };
    let counts = (triangles.par_iter())
        .fold(
            || vec![[0usize; 3]; DETAIL_BINS],
            |mut counts, t| {
                let c = (t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3.0;
                for axis in 0..3 {
                    counts[bin(c[axis], axis)][axis] += 1;
                }
                counts
            },
        )
        .reduce(
            || vec![[0usize; 3]; DETAIL_BINS],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    for axis in 0..3 {
                        x[axis] += y[axis];
                    }
                }
                a
            },
        );
    let (mut a, mut b) = (lo, hi);
    for axis in 0..3 {
        // The shortest run of bins from `start` to `end` (inclusive) holding `k`.
        let (mut start, mut held, mut best) = (0, 0, (0, DETAIL_BINS - 1));
        for end in 0..DETAIL_BINS {
            held += counts[end][axis];
            while held - counts[start][axis] >= k && start < end {
                held -= counts[start][axis];
                start += 1;
            }
            if held >= k && end - start < best.1 - best.0 {
                best = (start, end);
            }
        }
        let width = size[axis] / DETAIL_BINS as f32;
        a[axis] = lo[axis] + best.0 as f32 * width;
        b[axis] = lo[axis] + (best.1 + 1) as f32 * width;
    }
    let small = (b - a).length() < SMALL_DETAIL * size.length();
    if !small {
        return None;
    }
    let grow = 0.5 * (b - a);
    let (a, b) = (a - grow, b + grow);
    let inside: Vec<Triangle> = (triangles.par_iter())
        .filter(|t| {
            t.vertices
                .iter()
                .all(|v| v.cmpge(a).all() && v.cmple(b).all())
        })
        .copied()
        .collect();
    let corners = inside.iter().flat_map(|t| t.vertices);
    let bounds = corners.fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(v), hi.max(v)),
    );
    (!inside.is_empty()).then_some(Detail {
        bounds,
        triangles: inside,
    })
}

impl Detail {
    /// What a first look frames: the detail's triangles and bounds, or else `all` and `bounds`.
    fn framed<'a>(
        detail: &'a Option<Detail>,
        all: &'a [Triangle],
        bounds: (Vec3, Vec3),
    ) -> (&'a [Triangle], (Vec3, Vec3)) {
        detail
            .as_ref()
            .map_or((all, bounds), |d| (&d.triangles[..], d.bounds))
    }

    /// None when nothing else of the model (`all`, in `all_order`, [`morton_order`]) stands
    /// between the eye of `camera`, framed on the detail, and the detail; else a camera that
    /// sees the detail from the first side
    /// (front, back, right, left) where the rest leaves room enough to frame it, or from the
    /// side with the most room, as close as that room allows (a train seen end on, from inside
    /// its tunnel).
    fn clear_view(
        &self,
        all: &[Triangle],
        all_order: &[u32],
        camera: &Camera,
        aspect: f32,
    ) -> Option<Camera> {
        let center = camera.look_at;
        let eye = camera.position;
        let toward = (center - eye).normalize_or_zero();
        if toward == Vec3::ZERO {
            return None;
        }
        let ray = [(eye, toward)];
        let in_front = nearest(all, all_order, &ray)[0].0;
        let order = morton_order(&self.triangles);
        let detail_in_front = nearest(&self.triangles, &order, &ray)[0].0;
        if in_front >= detail_in_front * (1.0 - 1e-3) {
            return None;
        }
        let up = camera.up;
        let front = model_front(up);
        let side = up.cross(front);
        let half = 0.5 * (self.bounds.1 - self.bounds.0);
        let sides = [front, -front, side, -side].map(|d| {
            let framed = frame_outside(&self.triangles, center, up, d, 0.15, aspect);
            let back = (framed.position - center).normalize_or_zero();
            // Where the view's line leaves the detail's box, and how far it runs on from there.
            let exit = (0..3)
                .filter(|&a| back[a] != 0.0)
                .map(|a| half[a] / back[a].abs())
                .fold(f32::INFINITY, f32::min);
            let room = exit + 0.8 * free_run(all, all_order, center + back * exit, back);
            (framed, back, room)
        });
        let fits = sides
            .iter()
            .find(|(framed, _, room)| framed.position.distance(center) <= *room);
        let (framed, back, room) = fits
            .or_else(|| sides.iter().max_by(|x, y| x.2.total_cmp(&y.2)))
            .unwrap_or(&sides[0]);
        let distance = framed.position.distance(center).min(*room);
        Some(Camera {
            position: center + *back * distance,
            ..framed.clone()
        })
    }
}

/// How far from `from` along the unit `dir` a ray runs before it meets any of `all` (in
/// `order`, [`morton_order`]).
fn free_run(all: &[Triangle], order: &[u32], from: Vec3, dir: Vec3) -> f32 {
    nearest(all, order, &[(from, dir)])[0].0
}

/// The ambient light of a bare OBJ.
pub const BARE_OBJ_AMBIENT: f32 = 0.1;

/// The key light's and the headlight's grey levels: with the ambient light they add up to 1,
/// so a white diffuse surface (`Kd 1`, common in real files) facing both is white, not
/// clipped.
const KEY: f32 = 0.65;
const HEADLIGHT: f32 = 0.25;

/// How far towards the bounds (a fraction of the way from the probe point) a wall must stand
/// to count as a room's shell ([`Probe::far`]).
const ROOM_SHELL: f32 = 0.5;

/// A room seen y-up whose z extent is below this fraction of both its x and y extents is taken
/// z-up (see `load_obj_scene`).
const ROOM_Z_UP: f32 = 0.8;

/// The up axis of a bare OBJ: +y (the OBJ convention, and what Blender, Maya and SketchUp
/// write) unless the model clearly stands on z: a flat base at its lowest z (faces facing
/// along z within 2 % of the depth there cover at least a fifth of the bounds' xy area), none
/// at its lowest y, and z its longest extent (scanned busts and bottles from CAD tools).
fn up_axis(triangles: &[Triangle], lo: Vec3, hi: Vec3) -> Vec3 {
    use rayon::prelude::*;
    let extent = hi - lo;
    if !(extent.z > extent.x && extent.z > extent.y) {
        return Vec3::Y;
    }
    // The area of the flat faces at the bottom along `axis`, as a fraction of the bounds'
    // cross-section there.
    let base = |axis: usize| -> f32 {
        let band = lo[axis] + 0.02 * extent[axis];
        let area: f32 = triangles
            .par_iter()
            .map(|t| {
                let [a, b, c] = t.vertices;
                if a[axis] > band || b[axis] > band || c[axis] > band {
                    return 0.0;
                }
                let n = (b - a).cross(c - a);
                let len = n.length();
                if len > 0.0 && n[axis].abs() > 0.95 * len {
                    0.5 * len
                } else {
                    0.0
                }
            })
            .sum();
        let (u, v) = if axis == 1 { (0, 2) } else { (0, 1) };
        let section = extent[u] * extent[v];
        if section > 0.0 { area / section } else { 0.0 }
    };
    if base(2) >= 0.2 && base(1) < 0.05 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// Where the first look stands and, inside a room, where the key light hangs.
struct FirstView {
    camera: Camera,
    room: Option<Room>,
    /// Walls around the middle without a ceiling (a stage set, a tray), seen from above.
    open_above: bool,
}

#[derive(Clone, Copy)]
struct Room {
    /// The key light's position, under the ceiling and not inside anything.
    light: Vec3,
    /// Where the camera stands.
    entry: Entry,
}

/// Where a room's first look stands.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Entry {
    /// Most of one wall is missing (a Cornell box, a stage set): in front of the opening, the
    /// whole room in view.
    OpenSide,
    /// Part of one wall is open (a door, a window, a hole): in the opening, looking in.
    Doorway,
    /// Inside, near one wall.
    Inside,
}

/// The fraction of a wall that must be open for the room to be framed from outside, as a
/// Cornell box is; below it the camera stands in the opening.
const OPEN_SIDE: f32 = 0.6;

/// The fraction of a wall that must be open for it to count as an opening at all (below it,
/// a chink between badly joined walls).
const MIN_OPENING: f32 = 0.04;

/// Rays from outside that run more than this fraction of the room's depth past the bounds
/// before meeting anything pass through an opening (nearer, they met the wall, or something
/// standing out of it).
const WALL_DEPTH: f32 = 0.1;

/// Rays from above that run more than this fraction of the model's height into it before
/// meeting anything pass through an open top (a box without a lid, a bin, a cup): down to
/// its floor, not onto a lid's studs or handles.
const ROOF_DEPTH: f32 = 0.5;

/// How many directions each probe point sends rays in.
const PROBE_DIRS: usize = 48;

/// What the rays from one point met.
#[derive(Clone, Debug, Default)]
struct Probe {
    /// Rays that met a triangle facing the point (a wall seen from inside the room).
    front: usize,
    /// Rays whose first triangle faces away (the point is inside a closed solid).
    back: usize,
    /// Of the `front` rays, those that met their triangle at least [`ROOM_SHELL`] of the way
    /// to the model's bounds: the walls of a room are its outer shell, where a hole through a
    /// part or a pocket of a solid is close around the point.
    far: usize,
    /// Per direction, whether its ray met anything.
    met: Vec<bool>,
}

impl Probe {
    fn hits(&self) -> usize {
        self.front + self.back
    }
    /// Walls on most sides, seen from inside: most rays meet something, and most of what
    /// they meet faces the point.
    fn in_room(&self) -> bool {
        5 * self.hits() >= 3 * PROBE_DIRS
            && 4 * self.front >= 3 * self.hits()
            && 2 * self.far >= self.front
    }
    /// How many of the rays within 60° of `up` met nothing (no ceiling).
    fn open_up(&self, dirs: &[Vec3], up: Vec3) -> usize {
        dirs.iter()
            .zip(&self.met)
            .filter(|(d, m)| d.dot(up) > 0.5 && !**m)
            .count()
    }
    /// Not inside a closed solid (a cabinet, a lamp): no more faces seen from behind than
    /// from the front.
    fn free(&self) -> bool {
        self.back <= self.front
    }
}

/// The first view of a model whose bounds are `lo..hi`, `up` being its up axis: when it is a
/// room (walls and a ceiling around a point near its middle), inside it, in the opening of a
/// wall with a door or a hole, or in front of a side that is open; else from the front and a
/// little above (higher for a room without a ceiling), as close as the whole model allows.
fn first_view(triangles: &[Triangle], lo: Vec3, hi: Vec3, up: Vec3, aspect: f32) -> FirstView {
    let center = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    // The horizontal axes: one across, and the model's front ([`model_front`]).
    let (side, front) = (Vec3::X, model_front(up));
    let extent = |axis: Vec3| (half * axis).length();
    let dirs = directions(PROBE_DIRS);
    let curve = morton_order(triangles);
    // Probe points: the centre, and halfway to each horizontal wall (the middle of a room is
    // often a table or a bed).
    let mut points = vec![center];
    for axis in [side, front] {
        for sign in [1.0, -1.0] {
            points.push(center + axis * (sign * 0.5 * extent(axis)));
        }
    }
    let probes = probe_points(triangles, &curve, &points, &dirs, (lo, hi));
    let inside: Vec<(Vec3, &Probe)> = points
        .iter()
        .zip(&probes)
        .filter(|(_, p)| p.in_room())
        .map(|(&point, p)| (point, p))
        .collect();
    let outside = || first_view_outside(triangles, lo, hi, up, aspect);
    if inside.is_empty() || through_tube(triangles, &curve, center, (lo, hi)) {
        return outside();
    }
    // Open above (walls without a ceiling, a stage set, a tray, a box without a lid): of the
    // rays upwards from the points inside, at least half meet nothing (a cover over part of
    // it, a shelf or a lid half on, notwithstanding). Seen from outside and higher up, so the
    // key light above shines in and the inside shows.
    let skyward = dirs.iter().filter(|d| d.dot(up) > 0.5).count();
    let sky: usize = inside.iter().map(|(_, p)| p.open_up(&dirs, up)).sum();
    let roofless = 4 * sky >= skyward * inside.len()
        && opening(triangles, &curve, up, (lo, hi), ROOF_DEPTH).0 >= OPEN_SIDE;
    if roofless || 2 * sky >= skyward * inside.len() {
        return FirstView {
            camera: frame_outside(triangles, center, up, front, 0.8, aspect),
            room: None,
            open_above: true,
        };
    }
    // Which wall the camera stands at: the most open one if a wall has an opening, else the
    // far end of the longer horizontal axis, looking along it.
    let walls = [side, -side, front, -front];
    let open_wall = walls
        .into_iter()
        .map(|w| (w, opening(triangles, &curve, w, (lo, hi), WALL_DEPTH)))
        .filter(|(_, (fraction, _))| *fraction >= MIN_OPENING)
        .max_by(|a, b| a.1.0.total_cmp(&b.1.0));
    let long = if extent(front) >= extent(side) {
        front
    } else {
        side
    };
    let order: Vec<Vec3> = match open_wall {
        Some((w, _)) => vec![w, -w, long, -long],
        None => vec![long, -long, long.cross(up), -long.cross(up)],
    };
    // Camera candidates, best first: in the opening (or near the wall), then closer in. Each
    // must be free (not inside furniture) and see across the room: its view towards the
    // opposite wall runs at least half the room before meeting anything.
    let fractions = [0.85f32, 0.6, 0.35];
    let mut candidates = Vec::new();
    for f in fractions {
        for &wall in &order {
            candidates.push((center + wall * (f * extent(wall)), -wall));
        }
    }
    // Key light candidates: under the ceiling, then lower.
    let lights: Vec<Vec3> = [0.8f32, 0.6, 0.4, 0.2]
        .iter()
        .map(|f| center + up * (f * extent(up)))
        .collect();
    let mut points: Vec<Vec3> = candidates.iter().map(|c| c.0).collect();
    points.extend(&lights);
    let free = probe_points(triangles, &curve, &points, &dirs, (lo, hi));
    let light = lights
        .iter()
        .zip(&free[candidates.len()..])
        .find(|(_, p)| p.free())
        .map(|(l, _)| *l)
        .unwrap_or(center);
    if let Some((wall, (fraction, _))) = open_wall
        && fraction >= OPEN_SIDE
    {
        // Open on one side (a Cornell box, a stage set): seen through the opening, level,
        // the whole room in view, as the Cornell box's own camera does.
        return FirstView {
            camera: frame_outside(triangles, center, up, wall, 0.0, aspect),
            room: Some(Room {
                light,
                entry: Entry::OpenSide,
            }),
            open_above: false,
        };
    }
    // The camera would stand inside. A room stands on a floor: straight down from most of the
    // points inside it, the ray meets something. A shell open below (a toy brick, a bell, a
    // cup upside down) is a thing, seen from outside.
    let down: Vec<(Vec3, Vec3)> = inside.iter().map(|&(point, _)| (point, -up)).collect();
    let floored = nearest(triangles, &curve, &down)
        .iter()
        .filter(|(t, _)| t.is_finite())
        .count();
    if 2 * floored < inside.len() {
        return outside();
    }
    // A door or a hole in part of the wall: framing the box from outside would show mostly the
    // wall beside it, so the camera stands in the opening, looking at the middle of the room,
    // if nothing stands right in front of it.
    if let Some((_, (_, Some(door)))) = open_wall {
        let toward = (center - door).normalize_or_zero();
        let sight = nearest(triangles, &curve, &[(door, toward)])[0].0;
        if toward != Vec3::ZERO && sight >= 0.5 * door.distance(center) {
            return FirstView {
                camera: Camera {
                    position: door,
                    look_at: center,
                    up,
                    fov_y_deg: 60.0,
                },
                room: Some(Room {
                    light,
                    entry: Entry::Doorway,
                }),
                open_above: false,
            };
        }
    }
    let views: Vec<(Vec3, Vec3)> = candidates.clone();
    let ahead = nearest(triangles, &curve, &views);
    // The first free candidate that sees a quarter of the room ahead, else the free one that
    // sees farthest.
    let usable = candidates.iter().zip(&free).zip(&ahead);
    let camera = usable
        .clone()
        .find(|((c, p), a)| p.free() && a.0 >= 0.5 * extent(c.1))
        .or_else(|| {
            usable
                .filter(|((_, p), _)| p.free())
                .max_by(|x, y| x.1.0.total_cmp(&y.1.0))
        })
        .map(|((c, _), _)| *c)
        .unwrap_or((center, -order[0]));
    let (position, toward) = camera;
    FirstView {
        camera: Camera {
            position,
            look_at: position + toward * extent(toward).max(1e-6),
            up,
            fov_y_deg: 60.0,
        },
        room: Some(Room {
            light,
            entry: Entry::Inside,
        }),
        open_above: false,
    }
}

/// A model's front, the side the camera looks from: +z for y-up OBJ files, -y for z-up ones.
fn model_front(up: Vec3) -> Vec3 {
    if up == Vec3::Z { -Vec3::Y } else { Vec3::Z }
}

/// The first view of a model seen from outside: from its front and a little above, or square
/// to it when it is flat ([`flat_front`]).
fn first_view_outside(
    triangles: &[Triangle],
    lo: Vec3,
    hi: Vec3,
    up: Vec3,
    aspect: f32,
) -> FirstView {
    let (front, elevation) = flat_front(triangles, 0.5 * (hi - lo), up, model_front(up));
    FirstView {
        camera: frame_outside(triangles, 0.5 * (lo + hi), up, front, elevation, aspect),
        room: None,
        open_above: false,
    }
}

/// The model's enclosed volume, signed by its faces' winding, must be at least this fraction
/// of its bounds' volume below zero for it to face inwards ([`faces_inward`]).
const INWARD_VOLUME: f64 = 0.05;

/// A room's walls, floor and ceiling lie on its bounds: a model whose faces cover at least
/// this fraction of its bounds' six sides faces inwards as a room does ([`faces_inward`]).
const ON_BOUNDS: f64 = 0.15;

/// Whether the faces face inwards the way a thing turned inside out does: the volume their
/// winding encloses (about the bounds' centre) is clearly negative, and the faces lying on
/// the bounds' six sides (within 1 % of the largest extent), where a room's shell lies, cover
/// less than [`ON_BOUNDS`] of them. (Measured against the sides, not the model's own area, so
/// that a room full of furniture still counts as a room.)
fn faces_inward(triangles: &[Triangle], lo: Vec3, hi: Vec3) -> bool {
    use rayon::prelude::*;
    let extent = (hi - lo).as_dvec3();
    let bounds_volume = extent.x * extent.y * extent.z;
    let sides = 2.0 * (extent.x * extent.y + extent.y * extent.z + extent.z * extent.x);
    if !(bounds_volume > 0.0 && bounds_volume.is_finite()) {
        return false;
    }
    let center = (0.5 * (lo + hi)).as_dvec3();
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let near = 0.01 * extent.max_element();
    let (volume, on_bounds) = triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.vertices.map(|v| v.as_dvec3() - center);
            let area = 0.5 * (b - a).cross(c - a).length();
            let on = (0..3).any(|axis| {
                let all = |plane: f64| {
                    t.vertices
                        .iter()
                        .all(|v| (f64::from(v[axis]) - plane).abs() <= near)
                };
                all(lo[axis]) || all(hi[axis])
            });
            (a.dot(b.cross(c)) / 6.0, if on { area } else { 0.0 })
        })
        .reduce(|| (0.0, 0.0), |x, y| (x.0 + y.0, x.1 + y.1));
    volume < -INWARD_VOLUME * bounds_volume && on_bounds < ON_BOUNDS * sides
}

/// A hole through the model's middle whose width, both ways across, is under this fraction of
/// the model's length along it makes it a tube ([`through_tube`]).
const TUBE: f32 = 0.25;

/// A hollow tube (a pipe, a bushing, a shaft open at both ends): from the bounds' `center`, the
/// rays both ways along one axis meet nothing, and across that axis, both ways, the hole is
/// under [`TUBE`] of the model's length along it. Its hole's walls face the middle as a
/// room's walls do, but from inside it one would see only the wall in front: it is seen from
/// outside.
fn through_tube(triangles: &[Triangle], order: &[u32], center: Vec3, bounds: (Vec3, Vec3)) -> bool {
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    let rays: Vec<(Vec3, Vec3)> = axes
        .iter()
        .flat_map(|&a| [(center, a), (center, -a)])
        .collect();
    let met = nearest(triangles, order, &rays);
    let both = |i: usize| (met[2 * i].0, met[2 * i + 1].0);
    let size = bounds.1 - bounds.0;
    (0..3).any(|i| {
        let (ahead, behind) = both(i);
        ahead.is_infinite()
            && behind.is_infinite()
            && (0..3).filter(|&j| j != i).all(|j| {
                let (ahead, behind) = both(j);
                ahead + behind < TUBE * size[i]
            })
    })
}

/// How open the bounds' face towards `wall` (a horizontal axis, signed) is: the fraction of a
/// grid of rays sent in from just outside it, square to it, that pass [`WALL_DEPTH`] of the
/// room's depth without meeting anything; and where to stand in the opening, the open grid
/// point nearest the open points' centroid, just inside the face (none when nothing is open).
fn opening(
    triangles: &[Triangle],
    order: &[u32],
    wall: Vec3,
    (lo, hi): (Vec3, Vec3),
    past: f32,
) -> (f32, Option<Vec3>) {
    const GRID: usize = 16;
    let axis = wall.abs().max_position();
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let depth = hi[axis] - lo[axis];
    let face = if wall[axis] > 0.0 { hi[axis] } else { lo[axis] };
    let outside = 0.01 * depth;
    let points: Vec<Vec3> = (0..GRID * GRID)
        .map(|k| {
            let (i, j) = (k % GRID, k / GRID);
            let mut p = Vec3::ZERO;
            p[axis] = face;
            p[u] = lo[u] + (hi[u] - lo[u]) * (i as f32 + 0.5) / GRID as f32;
            p[v] = lo[v] + (hi[v] - lo[v]) * (j as f32 + 0.5) / GRID as f32;
            p
        })
        .collect();
    let rays: Vec<(Vec3, Vec3)> = points
        .iter()
        .map(|&p| (p + wall * outside, -wall))
        .collect();
    let open: Vec<Vec3> = nearest(triangles, order, &rays)
        .iter()
        .zip(&points)
        .filter(|((dist, _), _)| *dist > outside + past * depth)
        .map(|(_, &p)| p)
        .collect();
    if open.is_empty() {
        return (0.0, None);
    }
    let centroid = open.iter().sum::<Vec3>() / open.len() as f32;
    // Just inside the face, so the camera is within the model's bounds (the scene view cuts
    // the walls away around a camera inside them).
    let door = open
        .iter()
        .copied()
        .min_by(|a, b| a.distance(centroid).total_cmp(&b.distance(centroid)))
        .map(|p| p - wall * (0.02 * depth));
    (open.len() as f32 / points.len() as f32, door)
}

/// A model this flat (its vertices within twice this fraction of its bounds' largest half extent
/// of a plane) is looked at as a flat thing ([`flat_front`]).
const FLAT: f32 = 0.01;

/// A flat model seen from its front at more than this angle from square (the cosine: 60°) is
/// looked at square to its plane instead ([`flat_front`]).
const GRAZING: f32 = 0.5;

/// The side a model seen from outside is looked at from, and how high (the camera's rise over
/// its run): its `front`, a little from above (0.3), unless it is flat, in whatever plane. A
/// flat model lying within 45° of level (a floor plan, a terrain patch) is looked at from
/// higher up (1.0, 45°). A flat model that view or the plain front view would see at a grazing
/// angle (a sign or a cut-out polygon standing sideways, a single slanted triangle) is looked
/// at square to its plane, from the side its faces face (by their winding, summed by area; the
/// positive side when they cancel), raised as the front view is.
fn flat_front(triangles: &[Triangle], half: Vec3, up: Vec3, front: Vec3) -> (Vec3, f32) {
    let largest = half.max_element();
    if largest <= 0.0 || !largest.is_finite() {
        return (front, 0.3);
    }
    let Some((normal, facing)) = plane(triangles, 2.0 * FLAT * largest) else {
        return (front, 0.3);
    };
    let elevation = if normal.dot(up).abs() >= std::f32::consts::FRAC_1_SQRT_2 {
        1.0
    } else {
        0.3
    };
    if (front + elevation * up).normalize().dot(normal).abs() >= GRAZING {
        return (front, elevation);
    }
    let toward = if facing < 0.0 { -normal } else { normal };
    let rise = (up - up.dot(toward) * toward).normalize_or_zero();
    let back = (toward + 0.3 * rise).normalize();
    let level = back - back.dot(up) * up;
    if level.length() < 1e-3 {
        return (front, elevation);
    }
    (level.normalize(), back.dot(up) / level.length())
}

/// The plane a model lies in, when it lies in one: its unit normal and the model's faces'
/// area along it (twice, signed by their winding), if every vertex lies within `thickness` of
/// every other along that normal. The normal is the faces' normals summed by area, each turned
/// to the side of the largest face's, so faces wound either way do not cancel.
fn plane(triangles: &[Triangle], thickness: f32) -> Option<(Vec3, f32)> {
    use rayon::prelude::*;
    let area = |t: &Triangle| {
        let [a, b, c] = t.vertices;
        (b - a).cross(c - a)
    };
    let largest = triangles.par_iter().map(area).reduce(
        || Vec3::ZERO,
        |x, y| {
            if y.length_squared() > x.length_squared() {
                y
            } else {
                x
            }
        },
    );
    let normal = triangles
        .par_iter()
        .map(|t| {
            let n = area(t);
            if n.dot(largest) < 0.0 { -n } else { n }
        })
        .reduce(|| Vec3::ZERO, |x, y| x + y)
        .normalize_or_zero();
    if normal == Vec3::ZERO || !normal.is_finite() {
        return None;
    }
    let (low, high) = triangles
        .par_iter()
        .flat_map_iter(|t| t.vertices.map(|v| v.dot(normal)))
        .fold(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |(lo, hi), d| (lo.min(d), hi.max(d)),
        )
        .reduce(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let spread = high - low;
    if !spread.is_finite() || spread > thickness {
        return None;
    }
    let facing = triangles.par_iter().map(|t| area(t).dot(normal)).sum();
    Some((normal, facing))
}

/// The camera in front of the model (from `front`, raised by `elevation`: 0.3 is about 17°), aimed
/// at the bounds' centre, as close as keeps every vertex inside the image with a 5 % margin on each
/// side.
fn frame_outside(
    triangles: &[Triangle],
    center: Vec3,
    up: Vec3,
    front: Vec3,
    elevation: f32,
    aspect: f32,
) -> Camera {
    use rayon::prelude::*;
    let fov_y_deg = Camera::default().fov_y_deg;
    let back = (front + elevation * up).normalize();
    let right = up.cross(back).normalize();
    let cam_up = back.cross(right);
    let tan_v = 0.9 * (0.5 * fov_y_deg).to_radians().tan();
    let tan_h = tan_v * aspect.max(0.1);
    // The distance from the centre that puts a point at the image's edge: its sideways
    // offset over the tangent, less how far it stands towards the camera.
    let needed = |p: Vec3| -> f32 {
        let d = p - center;
        let toward = d.dot(back);
        let fit = (d.dot(right).abs() / tan_h).max(d.dot(cam_up).abs() / tan_v);
        fit + toward
    };
    let distance = triangles
        .par_iter()
        .map(|t| t.vertices.iter().map(|&v| needed(v)).fold(0.0f32, f32::max))
        .reduce(|| 0.0, f32::max);
    // Never on the model's centre: a flat or point-like model still gets some distance.
    let distance = if distance > 0.0 && distance.is_finite() {
        distance
    } else {
        1.0
    };
    Camera {
        position: center + back * distance,
        look_at: center,
        up,
        fov_y_deg,
    }
}

/// `n` directions spread evenly over the sphere (a Fibonacci spiral: none along an axis or a
/// box diagonal, so rays never run exactly into a box's edges or corners).
fn directions(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f32 + 1.0) / n as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), z, r * phi.sin())
        })
        .collect()
}

/// Rays from each of `points` in each of `dirs`: what each point's rays met first; `bounds`
/// are the model's (for [`Probe::far`]).
fn probe_points(
    triangles: &[Triangle],
    order: &[u32],
    points: &[Vec3],
    dirs: &[Vec3],
    (lo, hi): (Vec3, Vec3),
) -> Vec<Probe> {
    let rays: Vec<(Vec3, Vec3)> = points
        .iter()
        .flat_map(|&p| dirs.iter().map(move |&d| (p, d)))
        .collect();
    nearest(triangles, order, &rays)
        .chunks(dirs.len())
        .zip(points)
        .map(|(per_point, &p)| {
            let mut probe = Probe::default();
            for (&(dist, facing), &d) in per_point.iter().zip(dirs) {
                probe.met.push(dist.is_finite());
                if !dist.is_finite() {
                    continue;
                }
                if facing {
                    probe.front += 1;
                    // How far the ray runs inside the bounds from `p`.
                    let to_wall = (0..3)
                        .filter(|&a| d[a] != 0.0)
                        .map(|a| (if d[a] > 0.0 { hi[a] } else { lo[a] } - p[a]) / d[a])
                        .fold(f32::INFINITY, f32::min);
                    if dist >= ROOM_SHELL * to_wall {
                        probe.far += 1;
                    }
                } else {
                    probe.back += 1;
                }
            }
            probe
        })
        .collect()
}

/// For each ray (origin, unit direction): the distance to the first triangle it meets
/// (infinite when none) and whether that triangle faces the origin. Brute force in parallel
/// over runs of 64 triangles in `order` (a Morton curve), each run skipped as a whole when the
/// ray misses its box: a million triangles cost tens of milliseconds.
fn nearest(triangles: &[Triangle], order: &[u32], rays: &[(Vec3, Vec3)]) -> Vec<(f32, bool)> {
    use rayon::prelude::*;
    const RUN: usize = 64;
    let rays: Vec<(Vec3, Vec3, Vec3)> = rays.iter().map(|&(o, d)| (o, d, d.recip())).collect();
    let none = || vec![(f32::INFINITY, false); rays.len()];
    order
        .par_chunks(RUN)
        .fold(none, |mut best, run| {
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for &i in run {
                for v in triangles[i as usize].vertices {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            for (k, &(o, d, inv)) in rays.iter().enumerate() {
                // Slab test against the run's box, up to the nearest hit so far.
                let (t0, t1) = ((lo - o) * inv, (hi - o) * inv);
                let near = t0.min(t1).max_element().max(0.0);
                let far = t0.max(t1).min_element().min(best[k].0);
                if near > far || far.is_nan() {
                    continue;
                }
                for &i in run {
                    // Möller–Trumbore, both sides.
                    let [a, b, c] = triangles[i as usize].vertices;
                    let (e1, e2) = (b - a, c - a);
                    let p = d.cross(e2);
                    let det = e1.dot(p);
                    if det.abs() < 1e-12 {
                        continue;
                    }
                    let inv_det = 1.0 / det;
                    let s = o - a;
                    let u = s.dot(p) * inv_det;
                    let q = s.cross(e1);
                    let v = d.dot(q) * inv_det;
                    let dist = e2.dot(q) * inv_det;
                    if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0 && dist < best[k].0 {
                        best[k] = (dist, e1.cross(e2).dot(d) < 0.0);
                    }
                }
            }
            best
        })
        .reduce(none, |a, b| {
            a.into_iter()
                .zip(b)
                .map(|(x, y)| if y.0 < x.0 { y } else { x })
                .collect()
        })
}

/// The triangles' indices sorted by the Morton code of their centroids (10 bits an axis in
/// the bounds), so that consecutive ones lie close together.
fn morton_order(triangles: &[Triangle]) -> Vec<u32> {
    use rayon::prelude::*;
    let centroid = |t: &Triangle| (t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3.0;
    let (lo, hi) = triangles
        .par_iter()
        .map(|t| (centroid(t), centroid(t)))
        .reduce(
            || (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let scale = Vec3::splat(1023.0) / (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
    // Two zero bits after each of the 10 bits of `x`.
    let spread = |x: u32| -> u64 {
        let mut x = u64::from(x & 0x3ff);
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    // The code in the high bits, the index in the low 32: one u64 to sort.
    let mut keyed: Vec<u64> = triangles
        .par_iter()
        .enumerate()
        .map(|(i, t)| {
            let q = ((centroid(t) - lo) * scale).clamp(Vec3::ZERO, Vec3::splat(1023.0));
            let code = spread(q.x as u32) | (spread(q.y as u32) << 1) | (spread(q.z as u32) << 2);
            (code << 32) | i as u64
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|k| k as u32).collect()
}

/// The error for an OBJ none of whose faces can be shown, saying why: no faces at all, or
/// the first vertex (line and axis) that is not finite or lies beyond the scene-size limit,
/// or else faces of zero area. Only called on that error, so it reads the text once more.
fn nothing_to_show(label: &str, text: &str) -> String {
    let lead = "the OBJ has no triangles to show";
    let lines_of = |keyword: &'static str| {
        text.lines().enumerate().filter_map(move |(i, l)| {
            let mut words = l.split_whitespace();
            (words.next() == Some(keyword)).then_some((i + 1, words))
        })
    };
    let faces = lines_of("f").count();
    if faces == 0 {
        return format!("{label}: {lead}: it has no faces (`f` lines).");
    }
    let mut far = None;
    for (line, words) in lines_of("v") {
        for (axis, word) in ["x", "y", "z"].into_iter().zip(words) {
            let Ok(x) = word.parse::<f32>() else { continue };
            if !x.is_finite() {
                return format!(
                    "{label}:{line}: {lead}: vertex {axis} is `{word}`, not a finite 32-bit number, and every face is degenerate or uses such a vertex."
                );
            }
            if far.is_none() && x.abs() > MAX_COORDINATE {
                far = Some((line, axis, word.to_string()));
            }
        }
    }
    match far {
        Some((line, axis, word)) => format!(
            "{label}:{line}: {lead}: vertex {axis} is `{word}`, beyond ±1e15 (raytree's limit on scene size), and every face is degenerate or beyond it."
        ),
        None if faces == 1 => {
            format!("{label}: {lead}: its one face has zero area or fewer than three corners.")
        }
        None => format!(
            "{label}: {lead}: its {faces} faces all have zero area or fewer than three corners."
        ),
    }
}
