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
//! eye. Spheres stay: a sphere cannot enclose a room's camera and be a wall.
//!
//! A cut triangle is made a point rather than removed, so the triangle indices that the mesh
//! attributes (normals, texture coordinates) refer to stay valid, and a point is never hit.

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

/// The indices of the triangles of `scene` cut away for a view from `eye`, in order.
pub fn cut_triangles(scene: &Scene, eye: Vec3) -> Vec<u32> {
    let camera = scene.camera.position;
    scene
        .triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| is_cut(t, eye, camera))
        .map(|(i, _)| i as u32)
        .collect()
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
}
