//! Which parts of a segment lie behind the scene's surfaces, seen from a camera whose render's
//! depth is known: the scene view dims those parts rather than hiding them, so a ray that
//! passes behind a sphere still reads as one ray.

use glam::Vec3;

use crate::scene::CameraFrame;

/// Per pixel, the distance along the pixel centre's ray to the first surface (INFINITY where
/// the ray met nothing), row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthImage {
    pub width: u32,
    pub height: u32,
    pub t: Vec<f32>,
}

impl DepthImage {
    /// The distance at image position (`x`, `y`) in pixels, `None` outside the image.
    fn at(&self, x: f32, y: f32) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0 && x < self.width as f32 && y < self.height as f32) {
            return None;
        }
        self.t
            .get(y as usize * self.width as usize + x as usize)
            .copied()
    }
}

/// A piece of a segment, in front of the surfaces (`hidden` false) or behind one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    pub a: Vec3,
    pub b: Vec3,
    pub hidden: bool,
}

/// How much farther than the surface a point must be to count as behind it: a relative
/// tolerance, since rays end exactly on surfaces and depth is sampled at pixel centres.
const TOLERANCE: f32 = 0.02;

/// About one test every this many pixels along the segment on screen.
const STEP_PX: f32 = 3.0;

/// The part of `a..b` in front of the camera of `frame` (whose image is `depth`'s size), cut
/// into pieces in front of and behind the surfaces of `depth`. Points outside the image count
/// as in front. Empty when the whole segment is behind the camera.
pub fn visible_pieces(a: Vec3, b: Vec3, frame: &CameraFrame, depth: &DepthImage) -> Vec<Piece> {
    let eye = frame.ray(depth.width as f32 * 0.5, depth.height as f32 * 0.5);
    let (origin, view) = (eye.origin, eye.dir);
    // Clip to a near plane just in front of the eye, so every point left projects.
    let near = 1e-4 * (a - origin).length().max((b - origin).length()).max(1e-3);
    let (za, zb) = ((a - origin).dot(view), (b - origin).dot(view));
    if za < near && zb < near {
        return Vec::new();
    }
    let (a, b) = match (za < near, zb < near) {
        (true, _) => (a + (b - a) * ((near - za) / (zb - za)), b),
        (_, true) => (a, a + (b - a) * ((near - za) / (zb - za))),
        _ => (a, b),
    };
    let (Some(pa), Some(pb)) = (frame.project(a), frame.project(b)) else {
        return vec![Piece {
            a,
            b,
            hidden: false,
        }];
    };
    let length_px = ((pb.0 - pa.0).powi(2) + (pb.1 - pa.1).powi(2)).sqrt();
    let steps = ((length_px / STEP_PX).ceil() as usize).clamp(1, 512);
    let hidden_at = |s: f32| {
        let p = a + (b - a) * s;
        frame.project(p).is_some_and(|(x, y)| {
            depth
                .at(x, y)
                .is_some_and(|t| (p - origin).length() > t * (1.0 + TOLERANCE))
        })
    };
    let mut out: Vec<Piece> = Vec::new();
    let mut start = 0.0;
    let mut state = hidden_at(0.5 / steps as f32);
    for i in 1..steps {
        let s = (i as f32 + 0.5) / steps as f32;
        let h = hidden_at(s);
        if h != state {
            let cut = i as f32 / steps as f32;
            out.push(Piece {
                a: a + (b - a) * start,
                b: a + (b - a) * cut,
                hidden: state,
            });
            start = cut;
            state = h;
        }
    }
    out.push(Piece {
        a: a + (b - a) * start,
        b,
        hidden: state,
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Camera;

    /// A 40×40 view down −z from z = 5 with a wall at distance 4 (z = 1) over the left half.
    fn setup() -> (CameraFrame, DepthImage) {
        let frame = CameraFrame::new(&Camera::default(), 40, 40);
        let mut t = vec![f32::INFINITY; 1600];
        for y in 0..40 {
            for x in 0..20 {
                let r = frame.ray(x as f32 + 0.5, y as f32 + 0.5);
                t[y * 40 + x] = 4.0 / -r.dir.z;
            }
        }
        (
            frame,
            DepthImage {
                width: 40,
                height: 40,
                t,
            },
        )
    }

    #[test]
    fn a_segment_behind_the_wall_is_hidden_where_the_wall_is() {
        let (frame, depth) = setup();
        let pieces = visible_pieces(
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            &frame,
            &depth,
        );
        assert_eq!(pieces.len(), 2, "{pieces:?}");
        assert!(pieces[0].hidden && !pieces[1].hidden);
        assert!(pieces[0].b.x.abs() < 0.3, "{:?}", pieces[0].b);
        // In front of the wall, nothing is hidden.
        let front = visible_pieces(
            Vec3::new(-1.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 2.0),
            &frame,
            &depth,
        );
        assert!(front.iter().all(|p| !p.hidden), "{front:?}");
    }

    #[test]
    fn the_part_behind_the_camera_is_cut_off() {
        let (frame, depth) = setup();
        let pieces = visible_pieces(
            Vec3::new(0.5, 0.0, 10.0),
            Vec3::new(0.5, 0.0, 2.0),
            &frame,
            &depth,
        );
        assert!(!pieces.is_empty());
        assert!(pieces[0].a.z < 5.0, "{pieces:?}");
        assert!(visible_pieces(Vec3::Z * 6.0, Vec3::Z * 9.0, &frame, &depth).is_empty());
    }
}
