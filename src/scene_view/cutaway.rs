//! The scene view's cut-away: seeing inside a closed model (a room, a building) from a camera
//! outside it. The walls between the view's eye and the inside are left out of the scene the
//! view renders and measures its depth in, so the rays of a render camera standing in the room
//! are seen with the room around them instead of behind its outer walls.
//!
//! Which triangles go: those whose plane separates the view's eye from the render camera's eye
//! (the inside the user looks at), and which reach into the half of space on the eye's side of
//! the render camera (across the view direction). The plane test does not depend on how a
//! model's faces are wound (rooms are modelled facing in as often as out) and cuts thick walls
//! whole, both faces; the half-space test keeps the far furniture whose side merely faces the
//! eye. Spheres stay: a sphere cannot enclose a room's camera and be a wall. Solid things
//! standing in the room (a bed, a wardrobe: a closed part of a mesh facing every way, not a
//! slab, not holding the render camera) keep all their faces ([`SOLID_SHARE`]): cut, they
//! would be hollow shells whose near faces, where the rays hit them, are missing.
//!
//! A cut triangle is made a point rather than removed, so the triangle indices that the mesh
//! attributes (normals, texture coordinates) refer to stay valid, and a point is never hit.

use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec3;

use crate::scene::{MaterialId, ObjectId, Scene, Triangle};

/// When the scene view cuts walls away.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Cutaway {
    /// When the view's eye is outside the model and the render camera inside it
    /// ([`encloses_render_camera`]).
    #[default]
    Auto,
    On,
    Off,
}

impl Cutaway {
    pub const ALL: [Cutaway; 3] = [Cutaway::Auto, Cutaway::On, Cutaway::Off];

    /// The name the command line and the toolbar use.
    pub fn name(self) -> &'static str {
        match self {
            Cutaway::Auto => "auto",
            Cutaway::On => "on",
            Cutaway::Off => "off",
        }
    }

    /// Whether walls are cut for a view whose eye is at `eye`.
    pub fn active(self, scene: &Scene, eye: Vec3) -> bool {
        match self {
            Cutaway::On => true,
            Cutaway::Off => false,
            Cutaway::Auto => encloses_render_camera(scene, eye),
        }
    }
}

impl std::str::FromStr for Cutaway {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Cutaway::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| format!("the cut-away is auto, on or off, not {s:?}"))
    }
}

/// Whether the scene's model encloses the render camera (its eye lies strictly inside the
/// bounds of the scene's objects) while `eye` lies outside them: the case where a view from
/// outside sees nothing but walls.
pub fn encloses_render_camera(scene: &Scene, eye: Vec3) -> bool {
    let Some((lo, hi)) = scene.bounds() else {
        return false;
    };
    let inside = |p: Vec3| p.cmpgt(lo).all() && p.cmplt(hi).all();
    inside(scene.camera.position) && !inside(eye)
}

/// Whether `t` lies between `eye` and the inside around `camera` ([`cut_triangles`]).
fn is_cut(t: &Triangle, eye: Vec3, camera: Vec3) -> bool {
    let [a, b, c] = t.vertices;
    let n = (b - a).cross(c - a);
    let scale = n.length();
    if !(scale > 0.0 && scale.is_finite()) {
        return false;
    }
    let n = n / scale;
    let (e, k) = (n.dot(eye - a), n.dot(camera - a));
    // A point on the plane (within rounding of the scene's size) is on neither side.
    let slack = 1e-5 * (eye - camera).length().max(1e-6);
    let separates = (e > slack && k < -slack) || (e < -slack && k > slack);
    let towards = eye - camera;
    separates && t.vertices.iter().any(|v| (*v - camera).dot(towards) > 0.0)
}

/// A thing is solid (furniture, a box, a statue; kept whole by the cut-away) when it stands
/// apart from the render camera (its bounds do not hold it) and all three hold:
/// - it is not a slab: its bounds' smallest side is at least [`SOLID_SHARE`] of the largest;
/// - it faces every way: no direction has more than [`SOLID_FACING`] of its area facing along
///   it or against it (the largest eigenvalue of the area-weighted `n nᵀ` over its trace), so a
///   tilted roof or wall, whose bounds are not flat, is still no solid;
/// - it is closed: its faces' area-weighted normals, each turned to face away from the thing's
///   centre (files wind faces both ways, often within one box), nearly cancel (at most
///   [`SOLID_OPEN`] of its area left over), so an open shell (a gabled roof, a canopy) is no
///   solid.
///
/// A room, a wall, a floor or a roof fails one of them and is cut as before.
pub const SOLID_SHARE: f32 = 0.2;
/// See [`SOLID_SHARE`].
pub const SOLID_FACING: f32 = 0.75;
/// See [`SOLID_SHARE`].
pub const SOLID_OPEN: f32 = 0.25;

/// What [`kept_whole`] adds up over a thing's faces.
#[derive(Clone, Copy)]
struct Shape {
    lo: Vec3,
    hi: Vec3,
    /// Σ area · face centre.
    moment: Vec3,
    /// Σ area · n nᵀ, by columns.
    facing: [Vec3; 3],
    area: f32,
}

impl Shape {
    const EMPTY: Shape = Shape {
        lo: Vec3::splat(f32::INFINITY),
        hi: Vec3::splat(f32::NEG_INFINITY),
        moment: Vec3::ZERO,
        facing: [Vec3::ZERO; 3],
        area: 0.0,
    };

    fn add(&mut self, t: &Triangle) {
        let [a, b, c] = t.vertices;
        for v in t.vertices {
            self.lo = self.lo.min(v);
            self.hi = self.hi.max(v);
        }
        let n2 = (b - a).cross(c - a);
        let area = 0.5 * n2.length();
        if !(area > 0.0 && area.is_finite()) {
            return;
        }
        let n = n2.normalize();
        self.moment += area * (a + b + c) / 3.0;
        for (col, k) in self.facing.iter_mut().zip([n.x, n.y, n.z]) {
            *col += area * k * n;
        }
        self.area += area;
    }

    /// The largest share of the area facing along one direction: the largest eigenvalue of
    /// `facing` (power iteration, from its longest column) over its trace, the area.
    fn facing_share(&self) -> f32 {
        let m = self.facing;
        let apply = |v: Vec3| m[0] * v.x + m[1] * v.y + m[2] * v.z;
        let mut v = *m
            .iter()
            .max_by(|p, q| p.length_squared().total_cmp(&q.length_squared()))
            .unwrap_or(&Vec3::X);
        for _ in 0..32 {
            let w = apply(v);
            let len = w.length();
            if len <= 0.0 || !len.is_finite() {
                return 1.0;
            }
            v = w / len;
        }
        v.dot(apply(v)) / self.area
    }

    /// Whether the thing passes the cheap tests of [`SOLID_SHARE`] (all but closed).
    fn may_be_solid(&self, camera: Vec3) -> bool {
        let size = self.hi - self.lo;
        let holds_camera = camera.cmpge(self.lo).all() && camera.cmple(self.hi).all();
        self.area > 0.0
            && size.is_finite()
            && !holds_camera
            && size.min_element() >= SOLID_SHARE * size.max_element()
            && self.facing_share() <= SOLID_FACING
    }

    /// The area-weighted centre of the faces.
    fn centre(&self) -> Vec3 {
        self.moment / self.area
    }
}

/// `t`'s area times its normal turned away from `centre` (zero for a degenerate triangle).
fn outward(t: &Triangle, centre: Vec3) -> Vec3 {
    let [a, b, c] = t.vertices;
    let n2 = 0.5 * (b - a).cross(c - a);
    if !n2.is_finite() {
        return Vec3::ZERO;
    }
    if n2.dot((a + b + c) / 3.0 - centre) < 0.0 {
        -n2
    } else {
        n2
    }
}

/// For each triangle of `scene`, whether it belongs to a solid thing ([`SOLID_SHARE`]), kept
/// whole by the cut-away: cutting such a thing's near faces would leave a hollow shell that the
/// rays seem to enter and end inside. A thing is a named part of a mesh (the OBJ's `o` or `g`
/// faces, all materials of one name) or a mesh's faces outside any part.
fn kept_whole(scene: &Scene) -> Vec<bool> {
    let n = scene.triangles.len();
    // A group per (mesh, part name), then one per mesh for its faces outside any part.
    let mut group = vec![usize::MAX; n];
    let mut groups: HashMap<(u32, &str, bool), usize> = HashMap::new();
    let next = |key, groups: &mut HashMap<_, _>| {
        let len = groups.len();
        *groups.entry(key).or_insert(len)
    };
    for part in scene.parts.iter() {
        let g = next((part.object.0, part.name.as_str(), true), &mut groups);
        let first = part.first_triangle as usize;
        let end = (first + part.triangle_count as usize).min(n);
        for slot in group.get_mut(first..end).into_iter().flatten() {
            *slot = g;
        }
    }
    for (slot, t) in group.iter_mut().zip(scene.triangles.iter()) {
        if *slot == usize::MAX {
            *slot = next((t.object.0, "", false), &mut groups);
        }
    }
    let mut shapes = vec![Shape::EMPTY; groups.len()];
    for (t, &g) in scene.triangles.iter().zip(&group) {
        shapes[g].add(t);
    }
    let camera = scene.camera.position;
    let maybe: Vec<bool> = shapes.iter().map(|s| s.may_be_solid(camera)).collect();
    let mut open = vec![Vec3::ZERO; shapes.len()];
    for (t, &g) in scene.triangles.iter().zip(&group) {
        if maybe[g] {
            open[g] += outward(t, shapes[g].centre());
        }
    }
    let solid: Vec<bool> = (0..shapes.len())
        .map(|g| maybe[g] && open[g].length() <= SOLID_OPEN * shapes[g].area)
        .collect();
    group.into_iter().map(|g| solid[g]).collect()
}

/// The indices of the triangles of `scene` cut away for a view from `eye`, in order: those
/// between the eye and the inside (the module's first rule), except the faces of solid things
/// standing apart from the render camera ([`SOLID_SHARE`]).
pub fn cut_triangles(scene: &Scene, eye: Vec3) -> Vec<u32> {
    let camera = scene.camera.position;
    let mut kept: Option<Vec<bool>> = None;
    let mut out = Vec::new();
    for (i, t) in scene.triangles.iter().enumerate() {
        if is_cut(t, eye, camera) && !kept.get_or_insert_with(|| kept_whole(scene))[i] {
            out.push(i as u32);
        }
    }
    out
}

/// `scene` with the triangles `cut` (from [`cut_triangles`]) made points, everything else the
/// same.
pub fn with_cut(scene: &Scene, cut: &[u32]) -> Scene {
    let mut triangles: Vec<Triangle> = scene.triangles.as_ref().clone();
    for &i in cut {
        if let Some(t) = triangles.get_mut(i as usize) {
            t.vertices = [t.vertices[0]; 3];
        }
    }
    Scene {
        triangles: Arc::new(triangles),
        ..scene.clone()
    }
}

/// The twelve triangles of the closed box `lo..hi` in `material`: the smallest room.
pub fn box_triangles(lo: Vec3, hi: Vec3, material: MaterialId) -> Vec<Triangle> {
    let c = |k: usize| crate::scene_view::box_corner(lo, hi, k);
    // Each side as four corners in order around it.
    let sides = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    sides
        .iter()
        .flat_map(|s| [[s[0], s[1], s[2]], [s[0], s[2], s[3]]])
        .map(|[a, b, d]| Triangle {
            vertices: [c(a), c(b), c(d)],
            material,
            object: ObjectId(0),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn room() -> Scene {
        let mut scene = Scene {
            triangles: Arc::new(box_triangles(
                Vec3::splat(-2.0),
                Vec3::splat(2.0),
                MaterialId(0),
            )),
            ..Scene::default()
        };
        scene.camera.position = Vec3::new(0.0, 0.0, 1.0);
        scene.camera.look_at = Vec3::ZERO;
        scene
    }

    /// From outside, above and to the right, the near walls go (right, top, front: six
    /// triangles) and the far ones stay, whichever way the faces are wound.
    #[test]
    fn the_walls_between_the_eye_and_the_inside_are_cut() {
        let mut scene = room();
        let eye = Vec3::new(8.0, 6.0, 9.0);
        assert!(encloses_render_camera(&scene, eye));
        assert!(Cutaway::Auto.active(&scene, eye));
        let cut = cut_triangles(&scene, eye);
        assert_eq!(cut.len(), 6, "{cut:?}");
        for &i in &cut {
            let t = &scene.triangles[i as usize];
            let outer = t.vertices.iter().all(|v| v.x == 2.0)
                || t.vertices.iter().all(|v| v.y == 2.0)
                || t.vertices.iter().all(|v| v.z == 2.0);
            assert!(outer, "cut a far wall: {:?}", t.vertices);
        }
        // Wound the other way: the same walls.
        let flipped: Vec<Triangle> = scene
            .triangles
            .iter()
            .map(|t| Triangle {
                vertices: [t.vertices[0], t.vertices[2], t.vertices[1]],
                ..*t
            })
            .collect();
        scene.triangles = Arc::new(flipped);
        assert_eq!(cut_triangles(&scene, eye), cut);
        let seen = with_cut(&scene, &cut);
        assert_eq!(seen.triangles.len(), 12);
        assert!(cut.iter().all(|&i| {
            let [a, b, c] = seen.triangles[i as usize].vertices;
            a == b && b == c
        }));
    }

    /// Auto cuts only from outside a model around the render camera; on and off are what they
    /// say; the names read back.
    #[test]
    fn auto_cuts_only_from_outside_a_model_around_the_render_camera() {
        let scene = room();
        assert!(!Cutaway::Auto.active(&scene, Vec3::new(0.5, 0.5, 0.5)));
        assert!(Cutaway::On.active(&scene, Vec3::new(0.5, 0.5, 0.5)));
        assert!(!Cutaway::Off.active(&scene, Vec3::new(8.0, 6.0, 9.0)));
        let mut outside = room();
        outside.camera.position = Vec3::new(0.0, 0.0, 5.0);
        assert!(!Cutaway::Auto.active(&outside, Vec3::new(8.0, 6.0, 9.0)));
        assert!(!encloses_render_camera(&Scene::default(), Vec3::ONE));
        for c in Cutaway::ALL {
            assert_eq!(c.name().parse::<Cutaway>(), Ok(c));
        }
        assert!("maybe".parse::<Cutaway>().is_err());
    }

    /// `triangles` as mesh `object`.
    fn as_object(triangles: Vec<Triangle>, object: u32) -> Vec<Triangle> {
        triangles
            .into_iter()
            .map(|t| Triangle {
                object: ObjectId(object),
                ..t
            })
            .collect()
    }

    /// The room of [`room`] with `things` added, each a mesh of its own.
    fn room_with(things: Vec<Vec<Triangle>>) -> Scene {
        let mut scene = room();
        let mut all = scene.triangles.as_ref().clone();
        for (i, t) in things.into_iter().enumerate() {
            all.extend(as_object(t, i as u32 + 1));
        }
        scene.triangles = Arc::new(all);
        scene
    }

    fn cut_of(scene: &Scene, eye: Vec3, object: u32) -> usize {
        cut_triangles(scene, eye)
            .iter()
            .filter(|&&i| scene.triangles[i as usize].object == ObjectId(object))
            .count()
    }

    /// A box standing in the room between the eye and the render camera keeps all its faces
    /// (the rays that hit its near side end on a face the view still shows), whichever way its
    /// faces are wound, one by one; the room's near walls are still cut.
    #[test]
    fn furniture_in_the_room_is_kept_whole() {
        let eye = Vec3::new(8.0, 6.0, 9.0);
        let lo = Vec3::new(0.5, -1.0, 1.3);
        let hi = Vec3::new(1.0, -0.5, 1.8);
        let mut cube = box_triangles(lo, hi, MaterialId(0));
        // Its near faces' planes separate the eye from the render camera: without the rule they
        // would be cut.
        let camera = room().camera.position;
        assert!(cube.iter().any(|t| is_cut(t, eye, camera)));
        for (i, t) in cube.iter_mut().enumerate() {
            if i % 3 == 0 {
                t.vertices.swap(1, 2);
            }
        }
        let scene = room_with(vec![cube]);
        assert_eq!(cut_of(&scene, eye, 0), 6, "the room's near walls");
        assert_eq!(cut_of(&scene, eye, 1), 0, "the box keeps its faces");
        // With the render camera inside the box, the box is a room of its own and is cut.
        let mut inside = scene.clone();
        inside.camera.position = (lo + hi) / 2.0;
        assert!(cut_of(&inside, eye, 1) > 0);
    }

    /// What is no solid thing is cut as a wall: a slab (a thick wall as a mesh of its own), a
    /// tilted slab (a roof, whose bounds are not flat), an open shell (a gabled roof).
    #[test]
    fn slabs_roofs_and_open_shells_are_cut() {
        let eye = Vec3::new(8.0, 6.0, 9.0);
        let camera = room().camera.position;
        // A thick wall across the room in front of the render camera, on the eye's side.
        let wall = box_triangles(
            Vec3::new(-1.9, -1.9, 1.5),
            Vec3::new(1.9, 1.9, 1.8),
            MaterialId(0),
        );
        // A slab tilted 45° about x, above the render camera.
        let tilt = |v: Vec3| Vec3::new(v.x, 1.2 + (v.y + v.z) * 0.7, 0.5 + (v.z - v.y) * 0.7);
        let roof: Vec<Triangle> = box_triangles(
            Vec3::new(-1.5, -0.05, -1.0),
            Vec3::new(1.5, 0.05, 1.0),
            MaterialId(0),
        )
        .into_iter()
        .map(|t| Triangle {
            vertices: t.vertices.map(tilt),
            ..t
        })
        .collect();
        // Two roof planes meeting at a ridge, nothing under them.
        let (a, b, c, d) = (
            Vec3::new(-1.5, 1.0, -1.5),
            Vec3::new(1.5, 1.0, -1.5),
            Vec3::new(-1.5, 1.9, 0.0),
            Vec3::new(1.5, 1.9, 0.0),
        );
        let (e, f) = (Vec3::new(-1.5, 1.0, 1.5), Vec3::new(1.5, 1.0, 1.5));
        let gable: Vec<Triangle> = [[a, b, d], [a, d, c], [c, d, f], [c, f, e]]
            .into_iter()
            .map(|vertices| Triangle {
                vertices,
                material: MaterialId(0),
                object: ObjectId(0),
            })
            .collect();
        for (name, thing) in [("wall", wall), ("roof", roof), ("gable", gable)] {
            assert!(
                thing.iter().any(|t| is_cut(t, eye, camera)),
                "{name} is not between the eye and the camera"
            );
            let scene = room_with(vec![thing]);
            assert!(cut_of(&scene, eye, 1) > 0, "the {name} is kept whole");
        }
    }
}
