//! The pinhole camera of SPEC §2: pixel (x, y), y = 0 at the top, looks through
//! `((2(x+0.5)/W − 1)·a·tan(fov_y/2), (1 − 2(y+0.5)/H)·tan(fov_y/2), −1)` in camera space
//! (a = W/H), camera looking down −z, for the pixel centre.

use glam::{Mat4, Vec3, Vec4};

use crate::geometry::Ray;
use crate::scene::Camera;

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

    /// The primary ray through image position (`x`, `y`) in pixels, where pixel (i, j) covers
    /// `[i, i+1) × [j, j+1)` and its centre is (i + 0.5, j + 0.5).
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let cx = (2.0 * x / self.width - 1.0) * self.aspect * self.tan_half_fov_y;
        let cy = (1.0 - 2.0 * y / self.height) * self.tan_half_fov_y;
        let dir = (cx * self.right + cy * self.up - self.back).normalize();
        Ray::new(self.origin, dir)
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

impl CameraFrame {
    /// The matrix taking world points to wgpu clip space (depth 0..1 between `near` and
    /// `far`) such that the image position of [`CameraFrame::project`] is where the point lands
    /// on screen: the GPU overlay and the CPU projection agree.
    pub fn clip_from_world(&self, near: f32, far: f32) -> Mat4 {
        let o = self.origin;
        let view = Mat4::from_cols(
            Vec4::new(self.right.x, self.up.x, self.back.x, 0.0),
            Vec4::new(self.right.y, self.up.y, self.back.y, 0.0),
            Vec4::new(self.right.z, self.up.z, self.back.z, 0.0),
            Vec4::new(-self.right.dot(o), -self.up.dot(o), -self.back.dot(o), 1.0),
        );
        let sx = 1.0 / (self.aspect * self.tan_half_fov_y);
        let sy = 1.0 / self.tan_half_fov_y;
        let a = far / (near - far);
        let proj = Mat4::from_cols(
            Vec4::new(sx, 0.0, 0.0, 0.0),
            Vec4::new(0.0, sy, 0.0, 0.0),
            Vec4::new(0.0, 0.0, a, -1.0),
            Vec4::new(0.0, 0.0, a * near, 0.0),
        );
        proj * view
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

    #[test]
    fn clip_matrix_agrees_with_project() {
        let cam = Camera {
            position: Vec3::new(0.3, 1.7, 6.5),
            look_at: Vec3::new(0.0, 0.9, 0.0),
            up: Vec3::Y,
            fov_y_deg: 45.0,
        };
        let frame = CameraFrame::new(&cam, 640, 480);
        let m = frame.clip_from_world(0.01, 1000.0);
        for p in [
            Vec3::new(1.0, 1.0, -1.2),
            Vec3::new(-2.0, 0.0, 3.0),
            Vec3::ZERO,
        ] {
            let c = m * p.extend(1.0);
            let (ndc_x, ndc_y, ndc_z) = (c.x / c.w, c.y / c.w, c.z / c.w);
            let x = (ndc_x + 1.0) * 0.5 * 640.0;
            let y = (1.0 - ndc_y) * 0.5 * 480.0;
            let (px, py) = frame.project(p).expect("in front");
            assert!(
                (x - px).abs() < 1e-2 && (y - py).abs() < 1e-2,
                "{x},{y} vs {px},{py}"
            );
            assert!((0.0..=1.0).contains(&ndc_z), "depth {ndc_z}");
        }
    }
}
