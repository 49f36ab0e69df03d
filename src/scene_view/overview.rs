//! Where the scene view first looks from (docs/viewer.md, "The scene view's first look"):
//! across the render camera's rays, from the side where it sees what the render camera sees.
//!
//! The view frames the scene's bounds and the render camera's eye. Its preferred side is to the
//! render camera's right, a little above and behind, where the frustum and the rays are seen
//! across rather than end on. That side fails for a model seen through an opening (a Cornell
//! box, a room without its front wall): from beside it the view sees the outside of a side
//! wall. So each of a few directions, in order of preference, is scored on what the render
//! camera sees: the points it sees on a grid over its image, and points along the rays to them
//! inside the scene's bounds. A direction's score is the share of those points in plain sight
//! of its eye (a surface point also not seen edge on). The rays count because the tree is
//! drawn along them: a view over a wall's top or past its end sees the points of a facade that
//! every view sees, but not the rays that go into the room behind it. The first direction that
//! sees nearly as many as the best one is taken.

use glam::Vec3;

use super::box_corner;
use super::cutaway::Cutaway;
use crate::geometry::Ray;
use crate::scene::camera::FRAME_MARGIN;
use crate::scene::{Camera, CameraFrame};
use crate::trace::Tracer;

/// The directions tried, from the target towards the eye, in the render camera's frame (across
/// to its right, up, back behind it), most preferred first: its right side a little above and
/// behind; the left side; over its right shoulder, a little above it; both sides higher and
/// further behind; high over its shoulder; high above either side.
pub const DIRECTIONS: [[f32; 3]; 8] = [
    [1.0, 0.45, 0.25],
    [-1.0, 0.45, 0.25],
    [0.5, 0.25, 1.0],
    [0.8, 0.7, 1.0],
    [-0.8, 0.7, 1.0],
    [0.3, 0.8, 1.0],
    [1.0, 1.6, 0.25],
    [-1.0, 1.6, 0.25],
];

/// A less preferred direction is taken only when the preferred ones see less than this share
/// of what it sees: a side view that sees most of the scene stays.
const PREFERENCE: f32 = 0.8;

/// A point seen at a cosine below this (more than 78° from face on) is not shown: the view
/// sees its surface edge on.
const GRAZING: f32 = 0.2;

/// The grid of the render camera's image whose points a direction is scored on.
const GRID: (u32, u32) = (32, 24);

/// The part of the scene a view frames ([`crate::scene::Scene::framing_bounds`]).
type Bounds = Option<(Vec3, Vec3)>;

/// The scene view's vertical field of view in the viewer.
pub const FOV_Y_DEG: f32 = 45.0;

/// A direction's camera and the share of the render camera's points its eye sees: unhidden,
/// and for a surface point not within `GRAZING` of edge on.
#[derive(Clone, Debug)]
pub struct Candidate {
    pub camera: Camera,
    pub sees: f32,
}

/// The scene view's first camera for `tracer`'s scene in a view of `aspect` (width over height)
/// with a vertical field of `fov_y_deg`: the first of [`candidates`] that sees at least
/// `PREFERENCE` of what the best sees. When the cut-away would be active from the preferred
/// eye (the render camera inside a closed model), that eye is kept: the cut opens the walls
/// for it.
pub fn overview(tracer: &Tracer, aspect: f32, fov_y_deg: f32, cutaway: Cutaway) -> Camera {
    let bounds = tracer.scene.framing_bounds();
    let framings = framings(tracer, bounds, aspect, fov_y_deg);
    if cutaway.active(&tracer.scene, framings[0].position) {
        return framings[0].clone();
    }
    let all = scored(tracer, bounds, framings);
    let best = all.iter().map(|c| c.sees).fold(0.0f32, f32::max);
    all.iter()
        .find(|c| c.sees >= PREFERENCE * best)
        .unwrap_or(&all[0])
        .camera
        .clone()
}

/// Every direction of [`DIRECTIONS`], framed, with the share of the render camera's points its
/// eye sees (0 for all when the render camera sees nothing).
pub fn candidates(tracer: &Tracer, aspect: f32, fov_y_deg: f32) -> Vec<Candidate> {
    let bounds = tracer.scene.framing_bounds();
    scored(tracer, bounds, framings(tracer, bounds, aspect, fov_y_deg))
}

/// The camera of each direction of [`DIRECTIONS`], framed on the scene and the render camera.
fn framings(tracer: &Tracer, bounds: Bounds, aspect: f32, fov_y_deg: f32) -> Vec<Camera> {
    let scene = &tracer.scene;
    let eye = scene.camera.position;
    let view = (scene.camera.look_at - eye).normalize_or(Vec3::NEG_Z);
    let up = scene.camera.up.normalize_or(Vec3::Y);
    let side = view.cross(up).normalize_or(Vec3::X);
    let (lo, hi) = bounds.unwrap_or((eye - Vec3::ONE, eye + Vec3::ONE));
    // What is framed: the bounds' corners and the render camera's eye (not the corners of a
    // box around both, which a far eye would make much larger than either).
    let mut points: Vec<Vec3> = (0..8).map(|k| box_corner(lo, hi, k)).collect();
    points.push(eye);
    let (lo, hi) = (lo.min(eye), hi.max(eye));
    let base = Camera {
        fov_y_deg,
        up,
        ..scene.camera.clone()
    };
    DIRECTIONS
        .iter()
        .map(|&[a, b, c]| {
            let direction = (side * a + up * b - view * c).normalize();
            framed(&base, (lo, hi), &points, direction, aspect)
        })
        .collect()
}

/// Each camera with the share of the render camera's points its eye sees.
fn scored(tracer: &Tracer, bounds: Bounds, cameras: Vec<Camera>) -> Vec<Candidate> {
    let (hits, along) = seen_points(tracer, bounds);
    let total = (hits.len() + along.len()).max(1) as f32;
    cameras
        .into_iter()
        .map(|camera| {
            let eye = camera.position;
            let hits_seen = hits.iter().filter(|&&(p, n)| {
                let cos = n.dot((eye - p).normalize_or_zero()).abs();
                cos >= GRAZING && in_sight(tracer, eye, p)
            });
            let along_seen = along.iter().filter(|&&p| in_sight(tracer, eye, p));
            let sees = (hits_seen.count() + along_seen.count()) as f32 / total;
            Candidate { camera, sees }
        })
        .collect()
}

/// `base` aimed at the centre of the box `lo..hi` from `direction`, as close as `points` allow
/// in both fields of a view of `aspect`.
fn framed(
    base: &Camera,
    (lo, hi): (Vec3, Vec3),
    points: &[Vec3],
    direction: Vec3,
    aspect: f32,
) -> Camera {
    let mut camera = base.framing(lo, hi, direction);
    // `framing` fits the bounding sphere in the vertical field, which leaves a flat scene (a
    // floor and a few objects) small in the pane: the camera comes as close as the points
    // allow, in both fields of the pane (the narrower one across when the pane is narrower
    // than tall), with the same margin.
    let tan_y = (0.5 * camera.fov_y_deg).to_radians().min(1.5).tan();
    let tan_x = aspect * tan_y;
    let center = 0.5 * (lo + hi);
    if let Some(distance) = points_fit(center, points, direction, base.up, tan_x, tan_y) {
        camera.position = camera.look_at + direction * distance;
    }
    camera
}

/// How many points along a ray are scored per length of the scene's bounds' diagonal.
const ALONG: f32 = 16.0;

/// The points the render camera sees at the centres of a `GRID` over its image, with the
/// normals there; and points along the rays to them, inside the scene's bounds, evenly spaced.
fn seen_points(tracer: &Tracer, bounds: Bounds) -> (Vec<(Vec3, Vec3)>, Vec<Vec3>) {
    let scene = &tracer.scene;
    let (w, h) = (scene.render.width.max(1), scene.render.height.max(1));
    let frame = CameraFrame::new(&scene.camera, w, h);
    let Some((lo, hi)) = bounds else {
        return (Vec::new(), Vec::new());
    };
    let spacing = (hi - lo).length() / ALONG;
    let (gx, gy) = GRID;
    let mut hits = Vec::with_capacity((gx * gy) as usize);
    let mut along = Vec::new();
    for j in 0..gy {
        for i in 0..gx {
            let x = (i as f32 + 0.5) * w as f32 / gx as f32;
            let y = (j as f32 + 0.5) * h as f32 / gy as f32;
            let ray = frame.ray(x, y);
            let Some((t, normal)) = tracer.first_hit_normal(&ray) else {
                continue;
            };
            let p = ray.origin + ray.dir * t;
            if !p.is_finite() {
                continue;
            }
            hits.push((p, normal));
            // Counted rather than stepped: far from a small scene, a step of its spacing may
            // not move `t` at all in f32. No ray runs longer inside the box than its diagonal.
            let start = entry(ray.origin, ray.dir, lo, hi);
            let count = ((t - start) / spacing).clamp(0.0, 2.0 * ALONG) as usize;
            for k in 0..count {
                along.push(ray.origin + ray.dir * (start + (k as f32 + 0.5) * spacing));
            }
        }
    }
    (hits, along)
}

/// Where the ray `o + t·d` (t ≥ 0) enters the box `lo..hi`.
fn entry(o: Vec3, d: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    let mut t = 0.0f32;
    for axis in 0..3 {
        if d[axis] != 0.0 {
            let (a, b) = (
                (lo[axis] - o[axis]) / d[axis],
                (hi[axis] - o[axis]) / d[axis],
            );
            t = t.max(a.min(b));
        }
    }
    t
}

/// Whether nothing stands between `eye` and the surface point `p` (a hit short of it by more
/// than a thousandth of the way is something in front).
fn in_sight(tracer: &Tracer, eye: Vec3, p: Vec3) -> bool {
    let to = p - eye;
    let distance = to.length();
    if !(distance > 0.0 && distance.is_finite()) {
        return false;
    }
    let ray = Ray::new(eye, to / distance);
    tracer
        .first_hit_t(&ray)
        .is_none_or(|t| t >= distance * (1.0 - 1e-3))
}

/// The distance from the centre of `lo..hi` along the unit `direction` (from the centre towards
/// the eye) at which every corner of the box lies inside a view whose half fields have
/// tangents `tan_x` across and `tan_y` up, with [`FRAME_MARGIN`]; `None` for a degenerate view.
pub fn corner_fit(
    lo: Vec3,
    hi: Vec3,
    direction: Vec3,
    up: Vec3,
    tan_x: f32,
    tan_y: f32,
) -> Option<f32> {
    let corners: Vec<Vec3> = (0..8).map(|k| box_corner(lo, hi, k)).collect();
    points_fit(0.5 * (lo + hi), &corners, direction, up, tan_x, tan_y)
}

/// The distance from `center` along the unit `direction` at which every one of `points` lies
/// inside a view aimed at `center` whose half fields have tangents `tan_x` across and `tan_y`
/// up, with [`FRAME_MARGIN`], and outside the sphere about `center` through the farthest
/// point; `None` for a degenerate view.
fn points_fit(
    center: Vec3,
    points: &[Vec3],
    direction: Vec3,
    up: Vec3,
    tan_x: f32,
    tan_y: f32,
) -> Option<f32> {
    let right = up.cross(direction).normalize_or_zero();
    let upward = direction.cross(right);
    if right == Vec3::ZERO || !(tan_x > 0.0 && tan_y > 0.0) {
        return None;
    }
    let (mut distance, mut radius) = (0.0f32, 0.0f32);
    for &p in points {
        let q = p - center;
        // The point's depth in front of an eye at `distance` is `distance − q·direction`.
        let across = q.dot(direction) + FRAME_MARGIN * q.dot(right).abs() / tan_x;
        let upwards = q.dot(direction) + FRAME_MARGIN * q.dot(upward).abs() / tan_y;
        distance = distance.max(across).max(upwards);
        radius = radius.max(q.length());
    }
    // Never inside that sphere, where the near points would pass the eye.
    let distance = distance.max(1.05 * radius);
    (distance.is_finite() && distance > 0.0).then_some(distance)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where a point lands in a view from `eye` towards `target`: tangents across and up.
    fn tangents(eye: Vec3, target: Vec3, up: Vec3, p: Vec3) -> (f32, f32) {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        let upward = right.cross(forward);
        let d = p - eye;
        let depth = d.dot(forward);
        assert!(depth > 0.0, "{p} is behind the eye");
        (d.dot(right) / depth, d.dot(upward) / depth)
    }

    /// A flat floor with a few objects, seen from above at an angle: every corner lies inside
    /// the view with the margin, one of them on its edge (the fit is tight), and the camera is
    /// closer than framing the bounding sphere would put it.
    #[test]
    fn corner_fit_frames_a_flat_box_tightly() {
        let (lo, hi) = (Vec3::new(-12.0, 0.0, -12.0), Vec3::new(12.0, 2.0, 12.0));
        let direction = Vec3::new(1.0, 0.45, 0.25).normalize();
        let center = 0.5 * (lo + hi);
        for (tan_x, tan_y) in [(0.41, 0.41), (0.25, 0.41), (0.7, 0.41)] {
            let d = corner_fit(lo, hi, direction, Vec3::Y, tan_x, tan_y).expect("a distance");
            let eye = center + direction * d;
            let mut widest = 0.0f32;
            for k in 0..8 {
                let c = box_corner(lo, hi, k);
                let (x, y) = tangents(eye, center, Vec3::Y, c);
                let (fx, fy) = (
                    x.abs() * FRAME_MARGIN / tan_x,
                    y.abs() * FRAME_MARGIN / tan_y,
                );
                assert!(
                    fx <= 1.0 + 1e-4 && fy <= 1.0 + 1e-4,
                    "corner {c}: {fx} {fy}"
                );
                widest = widest.max(fx).max(fy);
            }
            assert!(
                widest > 0.999,
                "not tight: the widest corner fills {widest} of the view"
            );
            // The sphere's framing, in the narrower of the two fields.
            let half = tan_x.min(tan_y).atan();
            let sphere = FRAME_MARGIN * 0.5 * (hi - lo).length() / half.sin();
            assert!(d < sphere, "{d} against the sphere's {sphere}");
        }
        assert_eq!(corner_fit(lo, hi, Vec3::Y, Vec3::Y, 0.4, 0.4), None);
    }

    /// A box and an eye far in front of it, framed as points: every point in the view, and
    /// the camera closer than framing the box around both, whose far corners beside the eye
    /// are not there.
    #[test]
    fn points_fit_frames_a_far_eye_closer_than_the_box_around_it() {
        let (lo, hi) = (Vec3::ZERO, Vec3::splat(5.5));
        let eye = Vec3::new(2.75, 2.75, -20.0);
        let mut points: Vec<Vec3> = (0..8).map(|k| box_corner(lo, hi, k)).collect();
        points.push(eye);
        let (blo, bhi) = (lo.min(eye), hi.max(eye));
        let center = 0.5 * (blo + bhi);
        let direction = Vec3::new(0.5, 0.25, -1.0).normalize();
        let (tan_x, tan_y) = (0.55, 0.41);
        let d = points_fit(center, &points, direction, Vec3::Y, tan_x, tan_y).expect("a distance");
        let view_eye = center + direction * d;
        for &p in &points {
            let (x, y) = tangents(view_eye, center, Vec3::Y, p);
            assert!(
                x.abs() * FRAME_MARGIN <= tan_x * (1.0 + 1e-4)
                    && y.abs() * FRAME_MARGIN <= tan_y * (1.0 + 1e-4),
                "{p} is outside the view"
            );
        }
        let boxed = corner_fit(blo, bhi, direction, Vec3::Y, tan_x, tan_y).expect("a distance");
        assert!(d < 0.9 * boxed, "{d} against the box's {boxed}");
    }
}
