//! Which parts of a segment the scene hides, as seen from a view camera: a depth image of the
//! view (each pixel's centre ray traced to its first surface, exactly as a primary ray would
//! meet it) and the rule that splits a segment into pieces in front of the surfaces and behind
//! them. The window's scene view and the headless `raytree tree --scene-view` both draw by this
//! rule, so a ray reads as hidden in one exactly when it does in the other.
//!
//! The rule: a point of a segment is hidden when it lies farther from the eye than the surfaces
//! of every pixel around the one it projects to (its pixel and the eight neighbours), by more
//! than [`DEPTH_TOLERANCE`] of their distance. A segment is tested at points
//! [`SAMPLE_SPACING_PX`] apart on screen; a piece changes state halfway between two points that
//! disagree. Why so:
//! - A ray of the tree starts and ends ON surfaces (hit points, shadow ray origins); the depth
//!   image measures the surface along pixel centres, not at the point itself, and where a
//!   surface is steep to the view its distance changes fast within a pixel. Taking the farthest
//!   of the 3 × 3 pixels around the point and a relative slack of 1 % reads such points as
//!   visible: 1 % is far above `f32` rounding (about 1e-6 relative) and ray origin offsets, and
//!   covers a surface tilted up to about 70° from the view at 240 pixels and 45°.
//! - Relative, not absolute, so the rule is the same for a scene a millimetre or a kilometre
//!   across.
//! - Along a silhouette the farthest of the neighbours is the background: a ray just behind an
//!   object's outline reads as visible there, a pixel's error at most, which a 2-pixel line
//!   covers anyway.

use glam::Vec3;
use rayon::prelude::*;

use crate::scene::{CameraFrame, primary_ray};
use crate::trace::Tracer;

/// How much farther than the surface (relative to its distance) a point may be and still read
/// as in front of it; see the module's notes.
pub const DEPTH_TOLERANCE: f32 = 0.01;

/// Screen distance in pixels between the points of a segment that are tested.
pub const SAMPLE_SPACING_PX: f32 = 2.0;

/// Most points tested per segment (the part on screen is at most the image's diagonal long).
const MAX_SAMPLES: usize = 8192;

/// The near plane, as a fraction of the view depth of the segment's farther end: what is
/// closer to the eye than that would project thousands of times farther out than the rest.
const NEAR_FRACTION: f32 = 1e-3;

/// Distance along each pixel's centre ray (sample 0) to the first surface, f32::INFINITY where none.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthImage {
    pub width: u32,
    pub height: u32,
    pub t: Vec<f32>,
}

/// A piece of a segment: in front of every surface (`hidden: false`) or behind one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    pub a: Vec3,
    pub b: Vec3,
    pub hidden: bool,
}

impl DepthImage {
    /// Traces the centre ray (sample 0, through [`primary_ray`]) of every pixel of a
    /// `width × height` view with `frame` (made for that size) and keeps the distance to the
    /// closest object or visible light, as [`Tracer::first_hit_t`] finds it. Rows run in
    /// parallel on rayon's pool.
    pub fn of(tracer: &Tracer, frame: &CameraFrame, width: u32, height: u32) -> DepthImage {
        let t = (0..height)
            .into_par_iter()
            .flat_map_iter(|y| {
                (0..width).map(move |x| {
                    tracer
                        .first_hit_t(&primary_ray(frame, x, y, 0))
                        .unwrap_or(f32::INFINITY)
                })
            })
            .collect();
        DepthImage { width, height, t }
    }

    /// Whether a point `distance` from the eye that projects to image position (`x`, `y`) lies
    /// behind the surfaces there (the rule of the module's notes).
    fn sight(&self, x: f32, y: f32, distance: f32) -> Sight {
        let (w, h) = (self.width as f32, self.height as f32);
        if !(x >= 0.0 && y >= 0.0 && x < w && y < h) {
            return Sight::OffImage;
        }
        let (px, py) = (x as i64, y as i64);
        let mut farthest = 0.0f32;
        for ny in (py - 1).max(0)..=(py + 1).min(self.height as i64 - 1) {
            for nx in (px - 1).max(0)..=(px + 1).min(self.width as i64 - 1) {
                farthest = farthest.max(self.t[(ny * self.width as i64 + nx) as usize]);
            }
        }
        if distance > farthest * (1.0 + DEPTH_TOLERANCE) {
            Sight::Hidden
        } else {
            Sight::Seen
        }
    }
}

/// What the depth image says of a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sight {
    /// In front of the surfaces there.
    Seen,
    /// Behind them.
    Hidden,
    /// Behind the camera or off the image: not tested.
    OffImage,
}

impl Sight {
    /// Whether the point is drawn as hidden (a point not tested is not).
    pub fn is_hidden(self) -> bool {
        self == Sight::Hidden
    }
}

/// The eye and the unit view direction of `frame` (the ray through the image's centre).
fn eye_and_view(frame: &CameraFrame, depth: &DepthImage) -> (Vec3, Vec3) {
    let centre = frame.ray(depth.width as f32 * 0.5, depth.height as f32 * 0.5);
    (centre.origin, centre.dir)
}

/// Whether point `p` is hidden from the view, when `slack` of its distance is not counted (the
/// radius of a visible light's ball, whose centre lies behind its own surface). The light
/// markers use it.
pub fn point_sight(p: Vec3, slack: f32, frame: &CameraFrame, depth: &DepthImage) -> Sight {
    let (eye, _) = eye_and_view(frame, depth);
    match frame.project(p) {
        Some((x, y)) => depth.sight(x, y, (p - eye).length() - slack),
        None => Sight::OffImage,
    }
}

/// `a..b` split into pieces in front of the surfaces the depth image saw (hidden: false) and behind them (hidden: true); the part behind the camera's near plane is dropped.
///
/// `depth` must be the depth image of `frame` (same camera and size). Parts off the image are
/// not tested and come out as not hidden. Pieces run from `a` towards `b`.
pub fn visible_pieces(a: Vec3, b: Vec3, frame: &CameraFrame, depth: &DepthImage) -> Vec<Piece> {
    let (eye, view) = eye_and_view(frame, depth);
    let (za, zb) = ((a - eye).dot(view), (b - eye).dot(view));
    let far = za.max(zb);
    if !(far > 0.0 && far.is_finite() && a.is_finite() && b.is_finite()) {
        return Vec::new();
    }
    // Clip to the near plane: the end behind it moves along the segment onto it.
    let near = far * NEAR_FRACTION;
    let on_near =
        |from: Vec3, zf: f32, to: Vec3, zt: f32| from + (to - from) * ((near - zf) / (zt - zf));
    let (a, za) = if za < near {
        (on_near(a, za, b, zb), near)
    } else {
        (a, za)
    };
    let (b, zb) = if zb < near {
        (on_near(b, zb, a, za), near)
    } else {
        (b, zb)
    };
    let (Some(pa), Some(pb)) = (frame.project(a), frame.project(b)) else {
        return Vec::new();
    };
    let (pa, pb) = (glam::Vec2::from(pa), glam::Vec2::from(pb));
    // The point at screen parameter s (linear on screen) is the point at 3D parameter
    // s·za / (s·za + (1 − s)·zb): perspective keeps 1/z linear on screen.
    let at = |s: f32| {
        let t = if s <= 0.0 {
            0.0
        } else if s >= 1.0 {
            1.0
        } else {
            s * za / (s * za + (1.0 - s) * zb)
        };
        a + (b - a) * t
    };
    let Some((s0, s1)) = clip_to_rect(pa, pb, depth.width as f32, depth.height as f32) else {
        return vec![Piece {
            a,
            b,
            hidden: false,
        }];
    };
    let length = (pb - pa).length() * (s1 - s0);
    let n = ((length / SAMPLE_SPACING_PX).ceil() as usize).clamp(1, MAX_SAMPLES);
    // Runs of equal state as (start, end, hidden) in screen parameter.
    let mut runs: Vec<(f32, f32, bool)> = Vec::new();
    let mut push = |from: f32, to: f32, hidden: bool| match runs.last_mut() {
        Some(last) if last.2 == hidden => last.1 = to,
        _ => runs.push((from, to, hidden)),
    };
    if s0 > 0.0 {
        push(0.0, s0, false);
    }
    let mut prev: Option<(f32, bool)> = None;
    for k in 0..=n {
        let s = s0 + (s1 - s0) * k as f32 / n as f32;
        let p = pa + (pb - pa) * s;
        let hidden = depth.sight(p.x, p.y, (at(s) - eye).length()).is_hidden();
        match prev {
            None => push(s0, s, hidden),
            Some((sp, hp)) if hp != hidden => {
                let mid = 0.5 * (sp + s);
                push(sp, mid, hp);
                push(mid, s, hidden);
            }
            Some((sp, hp)) => push(sp, s, hp),
        }
        prev = Some((s, hidden));
    }
    if s1 < 1.0 {
        push(s1, 1.0, false);
    }
    let pieces: Vec<Piece> = runs
        .into_iter()
        .filter(|(from, to, _)| to > from)
        .map(|(from, to, hidden)| Piece {
            a: at(from),
            b: at(to),
            hidden,
        })
        .collect();
    if pieces.is_empty() {
        // Only a corner of the image touched: nothing there to be hidden by.
        return vec![Piece {
            a,
            b,
            hidden: false,
        }];
    }
    pieces
}

/// The part of the screen segment `pa..pb` inside the `width × height` image, as the
/// parameters (s0, s1) of its ends (Liang–Barsky); `None` when it misses the image.
pub fn clip_to_rect(pa: glam::Vec2, pb: glam::Vec2, width: f32, height: f32) -> Option<(f32, f32)> {
    let d = pb - pa;
    let (mut s0, mut s1) = (0.0f32, 1.0f32);
    for (p, q) in [
        (-d.x, pa.x),
        (d.x, width - pa.x),
        (-d.y, pa.y),
        (d.y, height - pa.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                s0 = s0.max(r);
            } else {
                s1 = s1.min(r);
            }
        }
    }
    (s0 <= s1 && s0.is_finite() && s1.is_finite()).then_some((s0, s1))
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::scene::{Camera, Scene, Sphere};
    use crate::trace::TraceSettings;

    /// A unit sphere at the origin seen from +z at distance 5, 160 × 120.
    fn view() -> (Tracer, CameraFrame, DepthImage) {
        let mut scene = Scene::default();
        let material = scene.default_material();
        scene.objects.push(crate::scene::Object {
            name: "ball".into(),
            source: crate::scene::ObjectSource::Sphere,
        });
        scene.spheres.push(Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            material,
            object: crate::scene::ObjectId(0),
        });
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let frame = CameraFrame::new(&Camera::default(), 160, 120);
        let depth = DepthImage::of(&tracer, &frame, 160, 120);
        (tracer, frame, depth)
    }

    fn states(pieces: &[Piece]) -> Vec<bool> {
        pieces.iter().map(|p| p.hidden).collect()
    }

    #[test]
    fn the_depth_image_sees_the_sphere_and_nothing_around_it() {
        let (_, _, depth) = view();
        let centre = depth.t[(60 * 160 + 80) as usize];
        assert!((centre - 4.0).abs() < 1e-3, "{centre}");
        assert_eq!(depth.t[0], f32::INFINITY);
    }

    #[test]
    fn a_visible_light_is_a_surface_a_point_light_is_not() {
        let frame = CameraFrame::new(&Camera::default(), 17, 13);
        let mut scene = Scene::default();
        for (radius, x) in [(0.5, 0.0), (0.0, 1.5)] {
            scene.lights.push(crate::scene::Light {
                name: format!("light at {x}"),
                position: Vec3::new(x, 0.0, 0.0),
                color: Vec3::ONE,
                radius,
                follow_camera: false,
            });
        }
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let depth = DepthImage::of(&tracer, &frame, 17, 13);
        // The centre pixel looks straight at the ball, 5 − 0.5 away.
        let centre = depth.t[6 * 17 + 8];
        assert!((centre - 4.5).abs() < 1e-4, "{centre}");
        // The point light at x = 1.5 projects to pixel (13, 6): nothing there.
        let (x, y) = frame.project(Vec3::new(1.5, 0.0, 0.0)).expect("in front");
        assert_eq!((x as usize, y as usize), (13, 6));
        assert_eq!(depth.t[6 * 17 + 13], f32::INFINITY);
    }

    #[test]
    fn in_front_is_visible_behind_is_hidden_on_the_surface_is_visible() {
        let (_, frame, depth) = view();
        // Across the sphere, in front of it.
        let front = visible_pieces(
            Vec3::new(-0.5, 0.0, 2.0),
            Vec3::new(0.5, 0.0, 2.0),
            &frame,
            &depth,
        );
        assert_eq!(states(&front), [false]);
        // Across it, behind it: hidden where the sphere covers it, visible past its outline.
        let behind = visible_pieces(
            Vec3::new(-3.0, 0.0, -2.0),
            Vec3::new(3.0, 0.0, -2.0),
            &frame,
            &depth,
        );
        assert_eq!(states(&behind), [false, true, false]);
        let middle = behind[1];
        assert!(middle.a.x > -2.0 && middle.a.x < -0.5, "{}", middle.a);
        assert!(middle.b.x > 0.5 && middle.b.x < 2.0, "{}", middle.b);
        // A primary ray from the eye to the sphere's front: visible to its end on the surface.
        let to_surface = visible_pieces(
            Vec3::new(0.0, 0.0, 4.5),
            Vec3::new(0.3, 0.2, 0.9).normalize(),
            &frame,
            &depth,
        );
        assert_eq!(states(&to_surface), [false]);
        // A shadow ray starting at a hit point on the front, leaving at a grazing angle.
        let hit = Vec3::new(0.6, 0.0, 0.8);
        let grazing = visible_pieces(hit, hit + Vec3::new(0.8, 0.1, -0.55), &frame, &depth);
        assert_eq!(states(&grazing), [false]);
        // One ending on the sphere's back, seen through it: hidden.
        let back = visible_pieces(
            Vec3::new(0.0, 0.0, -3.0),
            Vec3::new(0.0, 0.0, -1.0),
            &frame,
            &depth,
        );
        assert_eq!(states(&back), [true]);
    }

    #[test]
    fn behind_the_eye_is_dropped_and_the_rest_kept() {
        let (_, frame, depth) = view();
        assert!(
            visible_pieces(
                Vec3::new(0.0, 0.0, 6.0),
                Vec3::new(1.0, 0.0, 7.0),
                &frame,
                &depth
            )
            .is_empty()
        );
        let through = visible_pieces(
            Vec3::new(2.0, 0.0, 8.0),
            Vec3::new(2.0, 0.0, 0.0),
            &frame,
            &depth,
        );
        assert!(!through.is_empty());
        assert!(through.iter().all(|p| p.a.z < 5.0 && !p.hidden));
        assert_eq!(through.last().map(|p| p.b), Some(Vec3::new(2.0, 0.0, 0.0)));
    }

    #[test]
    fn a_light_inside_its_ball_is_not_hidden_by_it() {
        let (_, frame, depth) = view();
        // The sphere's centre is 1 behind its own front surface.
        assert_eq!(point_sight(Vec3::ZERO, 1.0, &frame, &depth), Sight::Seen);
        assert_eq!(point_sight(Vec3::ZERO, 0.0, &frame, &depth), Sight::Hidden);
        assert_eq!(
            point_sight(Vec3::new(0.0, 0.0, 9.0), 0.0, &frame, &depth),
            Sight::OffImage
        );
    }
}
