//! The camera, in one place: its data (docs/design.md, "Conventions"), its frame for an image size,
//! the primary ray of pixel (x, y) and sample s that the tiles and the ray tree both trace, framing
//! of bounds, and the orbit / pan / zoom moves of the viewer.
//!
//! Pixel (x, y), y = 0 at the top, looks through
//! `((2(x+0.5)/W − 1)·a·tan(fov_y/2), (1 − 2(y+0.5)/H)·tan(fov_y/2), −1)` in camera space
//! (a = W/H), camera looking down −z, for the pixel centre.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::sampling::sample_offset;
use crate::geometry::Ray;

/// A pinhole camera; the module doc gives the pixel-to-ray mapping.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 45.0,
        }
    }
}

/// A camera with its basis precomputed for an image size.
#[derive(Clone, Copy, Debug)]
pub struct CameraFrame {
    origin: Vec3,
    /// Camera x, y and z axes in world space (z points backwards, away from `look_at`).
    right: Vec3,
    up: Vec3,
    back: Vec3,
    tan_half_fov_y: f32,
    aspect: f32,
    width: f32,
    height: f32,
}

impl CameraFrame {
    /// The frame of `camera` for a `width × height` image.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let back = (camera.position - camera.look_at).normalize();
        let right = camera.up.cross(back).normalize();
        let up = back.cross(right);
        Self {
            origin: camera.position,
            right,
            up,
            back,
            tan_half_fov_y: (camera.fov_y_deg.to_radians() * 0.5).tan(),
            aspect: width as f32 / height as f32,
            width: width as f32,
            height: height as f32,
        }
    }

    /// The image's width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width as u32, self.height as u32)
    }

    /// The primary ray through image position (`x`, `y`) in pixels, where pixel (i, j) covers
    /// `[i, i+1) × [j, j+1)` and its centre is (i + 0.5, j + 0.5).
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let (cx, cy) = self.image_plane(x, y);
        let dir = (cx * self.right + cy * self.up - self.back).normalize();
        Ray::new(self.origin, dir)
    }

    /// Image position (`x`, `y`) in pixels on the camera's image plane at distance 1, in units
    /// of `right` and `up`: the one place [`CameraFrame::ray`] and [`primary_rays`] take it
    /// from.
    #[inline(always)]
    fn image_plane(&self, x: f32, y: f32) -> (f32, f32) {
        let cx = (2.0 * x / self.width - 1.0) * self.aspect * self.tan_half_fov_y;
        let cy = (1.0 - 2.0 * y / self.height) * self.tan_half_fov_y;
        (cx, cy)
    }

    /// Projects a world point to image position in pixels, or `None` when it is behind the
    /// camera. The inverse of [`CameraFrame::ray`], used to draw rays over the image.
    pub fn project(&self, p: Vec3) -> Option<(f32, f32)> {
        let d = p - self.origin;
        let z = -d.dot(self.back);
        if z <= 0.0 {
            return None;
        }
        let cx = d.dot(self.right) / z;
        let cy = d.dot(self.up) / z;
        let x = (cx / (self.aspect * self.tan_half_fov_y) + 1.0) * 0.5 * self.width;
        let y = (1.0 - cy / self.tan_half_fov_y) * 0.5 * self.height;
        Some((x, y))
    }
}

/// [`primary_ray`] of sample `sample` for the first `n` pixels of `pixels` (`(x, y)` each)
/// into `out`, the same rays bit for bit, formed lane by lane across the pixels: the
/// normalisations' square roots and divisions go eight (AVX2) or four (SSE) to one
/// instruction, where one pixel at a time pays a scalar square root and division each. All
/// `K` lanes are formed (fixed trip counts vectorise); only the first `n` are written.
#[inline(always)]
pub fn primary_rays<const K: usize>(
    frame: &CameraFrame,
    pixels: &[(u32, u32); K],
    n: usize,
    sample: u32,
    out: &mut [Ray; K],
) {
    let (mut x, mut y) = ([0f32; K], [0f32; K]);
    for (k, &(px, py)) in pixels.iter().enumerate().take(n) {
        let (u, v) = sample_offset(px, py, sample);
        (x[k], y[k]) = (px as f32 + u, py as f32 + v);
    }
    let f = frame;
    let (r, up, back) = (f.right, f.up, f.back);
    let (mut dx, mut dy, mut dz) = ([0f32; K], [0f32; K], [0f32; K]);
    for k in 0..K {
        // `CameraFrame::ray`'s arithmetic, operation for operation (glam's `Vec3` is scalar:
        // `cx * right + cy * up - back` rounds each component in this order).
        let (cx, cy) = f.image_plane(x[k], y[k]);
        dx[k] = (cx * r.x + cy * up.x) - back.x;
        dy[k] = (cx * r.y + cy * up.y) - back.y;
        dz[k] = (cx * r.z + cy * up.z) - back.z;
    }
    // `Vec3::normalize`: times `1 / sqrt(x·x + y·y + z·z)`, the dot product left to right.
    let mut inv = [0f32; K];
    for k in 0..K {
        inv[k] = 1.0 / (dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]).sqrt();
    }
    for k in 0..n.min(K) {
        let dir = Vec3::new(dx[k] * inv[k], dy[k] * inv[k], dz[k] * inv[k]);
        out[k] = Ray::new(f.origin, dir);
    }
}

/// The primary ray of sample `sample` of pixel (`x`, `y`): sample 0 looks through the pixel
/// centre, the others through [`sample_offset`]. Tiles and the ray tree both call this, so a
/// clicked pixel's tree is exactly the 1-sample render of that pixel.
pub fn primary_ray(frame: &CameraFrame, x: u32, y: u32, sample: u32) -> Ray {
    let (u, v) = sample_offset(x, y, sample);
    frame.ray(x as f32 + u, y as f32 + v)
}

/// How far outside the bounding sphere a framed camera stands: 1.1 leaves a tenth of the
/// field of view free around the scene.
pub const FRAME_MARGIN: f32 = 1.1;

impl Camera {
    /// This camera moved along the unit vector `direction` (from the target towards the eye) so
    /// that the bounding sphere of `lo..hi` fills the vertical field of view with [`FRAME_MARGIN`],
    /// aimed at its centre; `up` and `fov_y_deg` are kept.
    pub fn framing(&self, lo: Vec3, hi: Vec3, direction: Vec3) -> Camera {
        let center = 0.5 * (lo + hi);
        let radius = 0.5 * (hi - lo).length();
        // Beyond about 172° the sine flattens and the distance would run away.
        let half = (0.5 * self.fov_y_deg).to_radians().min(1.5);
        let distance = FRAME_MARGIN * radius / half.sin();
        Camera {
            position: center + direction * distance,
            look_at: center,
            ..self.clone()
        }
    }

    /// This camera framed on `lo..hi` from the direction it looks now (the viewer's "frame
    /// all").
    pub fn framing_all(&self, lo: Vec3, hi: Vec3) -> Camera {
        self.framing(lo, hi, (self.position - self.look_at).normalize_or(Vec3::Z))
    }

    /// Turns the camera about its target: `yaw` radians about the up axis, `pitch` about its
    /// right axis. Never flips over the pole: stops 1° short of the up axis.
    pub fn orbit(&mut self, yaw: f32, pitch: f32) {
        let offset = self.position - self.look_at;
        let up = self.up.normalize_or(Vec3::Y);
        let radius = offset.length();
        let yawed = glam::Quat::from_axis_angle(up, -yaw) * offset;
        let right = up.cross(-yawed).normalize_or(Vec3::X);
        let pitched = glam::Quat::from_axis_angle(right, -pitch) * yawed;
        let cos = pitched.normalize().dot(up);
        let next = if cos.abs() < 0.9998 { pitched } else { yawed };
        self.position = self.look_at + next.normalize() * radius;
    }

    /// Moves camera and target together by fractions of the image height (`dx` right, `dy`
    /// down on screen, so a drag moves the scene with the pointer).
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let back = self.position - self.look_at;
        let dist = back.length();
        let right = self.up.cross(back).normalize_or(Vec3::X);
        let up = back.cross(right).normalize_or(Vec3::Y);
        let span = 2.0 * dist * (self.fov_y_deg.to_radians() * 0.5).tan();
        let shift = (-dx * right + dy * up) * span;
        self.position += shift;
        self.look_at += shift;
    }

    /// Moves the camera towards (`factor` < 1) or away from its target, staying between 1e-4
    /// and 1e7 from it.
    pub fn zoom(&mut self, factor: f32) {
        let back = self.position - self.look_at;
        let len = (back.length() * factor).clamp(1e-4, 1e7);
        self.position = self.look_at + back.normalize_or(Vec3::Z) * len;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_at_target() {
        let cam = Camera {
            position: Vec3::new(1.0, 2.0, 3.0),
            look_at: Vec3::new(1.0, 2.0, -7.0),
            up: Vec3::Y,
            fov_y_deg: 60.0,
        };
        let frame = CameraFrame::new(&cam, 101, 51);
        let r = frame.ray(50.5, 25.5);
        assert!((r.dir - Vec3::NEG_Z).length() < 1e-6, "{}", r.dir);
        // The top-left corner is at tan(30°) up and aspect·tan(30°) left.
        let t = (30f32).to_radians().tan();
        let c = frame.ray(0.0, 0.0).dir;
        let expect = Vec3::new(-t * 101.0 / 51.0, t, -1.0).normalize();
        assert!((c - expect).length() < 1e-6, "{c} vs {expect}");
        let (x, y) = frame
            .project(Vec3::new(1.0, 2.0, 3.0) + 5.0 * c)
            .expect("in front");
        assert!(x.abs() < 1e-3 && y.abs() < 1e-3, "{x} {y}");
    }

    /// The batched rays are [`primary_ray`]'s, bit for bit: random cameras (fields of view
    /// from narrow to wide, odd image sizes), pixels anywhere, samples 0 to 9, every count of
    /// lanes written.
    #[test]
    fn primary_rays_are_primary_ray_bit_for_bit() {
        let mut rnd = crate::rng::signed(7);
        for case in 0..400 {
            let cam = Camera {
                position: Vec3::new(rnd(), rnd(), rnd()) * 50.0,
                look_at: Vec3::new(rnd(), rnd(), rnd()) * 3.0,
                up: Vec3::new(rnd() * 0.3, 1.0, rnd() * 0.3),
                fov_y_deg: 1.0 + 89.0 * (rnd() + 1.0),
            };
            let (w, h) = (1 + case * 7 % 1999, 1 + case * 13 % 1103);
            let frame = CameraFrame::new(&cam, w as u32, h as u32);
            let mut pixels = [(0u32, 0u32); 32];
            for p in pixels.iter_mut() {
                let x = ((rnd() + 1.0) * 0.5 * w as f32) as u32;
                let y = ((rnd() + 1.0) * 0.5 * h as f32) as u32;
                *p = (x.min(w as u32 - 1), y.min(h as u32 - 1));
            }
            let n = 1 + case % 32;
            let sample = (case % 10) as u32;
            let unset = Ray::new(Vec3::splat(7.0), Vec3::splat(7.0));
            let mut out = [unset; 32];
            primary_rays(&frame, &pixels, n, sample, &mut out);
            for (k, &(x, y)) in pixels.iter().enumerate() {
                let got = out[k];
                if k >= n {
                    assert_eq!(got.origin, unset.origin, "lane {k} past {n} written");
                    continue;
                }
                let want = primary_ray(&frame, x, y, sample);
                let bits = |r: Ray| [r.origin, r.dir].map(|v| v.to_array().map(f32::to_bits));
                assert_eq!(
                    bits(got),
                    bits(want),
                    "case {case}, pixel ({x}, {y}), lane {k}"
                );
            }
        }
    }

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 45.0,
        }
    }

    #[test]
    fn primary_ray_of_sample_zero_is_the_pixel_centre() {
        let frame = CameraFrame::new(&camera(), 64, 48);
        assert_eq!(primary_ray(&frame, 10, 20, 0), frame.ray(10.5, 20.5));
        let (u, v) = sample_offset(10, 20, 3);
        assert_eq!(
            primary_ray(&frame, 10, 20, 3),
            frame.ray(10.0 + u, 20.0 + v)
        );
    }

    #[test]
    fn orbit_keeps_the_distance_and_turns_by_the_angle() {
        let mut c = camera();
        c.orbit(std::f32::consts::FRAC_PI_2, 0.0);
        // A quarter turn about +y, seen from above clockwise: the eye goes from +z to -x.
        assert!(
            c.position.abs_diff_eq(Vec3::new(-5.0, 0.0, 0.0), 1e-5),
            "{}",
            c.position
        );
        assert_eq!(c.look_at, Vec3::ZERO);
        let mut c = camera();
        c.orbit(0.0, 0.3);
        assert!((c.position.length() - 5.0).abs() < 1e-5);
        let angle = c.position.normalize().dot(Vec3::Z).acos();
        assert!((angle - 0.3).abs() < 1e-5, "{angle}");
        // Pitching past the pole stops short of it instead of flipping.
        let mut c = camera();
        c.orbit(0.0, 2.0);
        assert!(c.position.normalize().dot(Vec3::Y).abs() < 0.9998);
        assert!(c.position.is_finite());
    }

    #[test]
    fn pan_moves_eye_and_target_by_fractions_of_the_view() {
        let mut c = camera();
        c.pan(0.5, 0.0);
        // Half the image height at distance 5 and 45°: 0.5 · 2 · 5 · tan(22.5°).
        let span = 5.0 * (22.5f32).to_radians().tan();
        assert!(
            c.look_at.abs_diff_eq(Vec3::new(-span, 0.0, 0.0), 1e-5),
            "{}",
            c.look_at
        );
        assert!((c.position - c.look_at).abs_diff_eq(Vec3::new(0.0, 0.0, 5.0), 1e-5));
        let mut c = camera();
        c.pan(0.0, 0.25);
        assert!(c.look_at.y > 0.0 && c.look_at.x.abs() < 1e-6);
    }

    #[test]
    fn zoom_scales_the_distance_within_bounds() {
        let mut c = camera();
        c.zoom(0.5);
        assert!(c.position.abs_diff_eq(Vec3::new(0.0, 0.0, 2.5), 1e-6));
        c.zoom(1e-12);
        assert!((c.position.length() - 1e-4).abs() < 1e-9);
        c.zoom(1e30);
        assert!((c.position.length() - 1e7).abs() < 1.0);
    }

    #[test]
    fn framing_puts_the_whole_bounding_sphere_in_view() {
        let (lo, hi) = (Vec3::new(-1.0, -2.0, -3.0), Vec3::new(3.0, 2.0, 1.0));
        let c = camera().framing_all(lo, hi);
        assert_eq!(c.look_at, Vec3::new(1.0, 0.0, -1.0));
        let radius = 0.5 * (hi - lo).length();
        // The bounding sphere subtends the field of view less the margin.
        let dist = c.position.distance(c.look_at);
        let half_angle = (radius / dist).asin().to_degrees();
        assert!(
            (half_angle * 2.0 - 45.0 / FRAME_MARGIN).abs() < 2.5,
            "{half_angle}"
        );
        assert!((dist * (22.5f32).to_radians().sin() / radius - FRAME_MARGIN).abs() < 1e-5);
        // From the direction it looked before.
        assert!(
            (c.position - c.look_at)
                .normalize()
                .abs_diff_eq(Vec3::Z, 1e-6)
        );
        // Every corner projects inside the image.
        let frame = CameraFrame::new(&c, 64, 48);
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let (x, y) = frame.project(p).expect("in front");
            assert!(
                (0.0..64.0).contains(&x) && (0.0..48.0).contains(&y),
                "{p}: {x} {y}"
            );
        }
    }
}
