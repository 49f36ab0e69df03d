//! Pointer gestures shared by the views: the orbit's rate (degrees per view width) and dragging
//! a light's marker to move it in the plane facing the camera.

use eframe::egui;

use super::Command;
use crate::scene::{CameraFrame, Scene};

/// How near (points) a press must be to a light's marker to grab it.
pub const LIGHT_GRAB_RADIUS: f32 = 12.0;

/// A drag that starts on a light's marker in a view seen through `camera` over `rect` moves
/// that light in the plane facing the camera (it stays under the pointer); returns whether
/// the drag is the light's (then the view must not orbit). The light moved becomes the
/// `selected_light`.
pub fn drag_light(
    edit: &mut Scene,
    selected_light: &mut Option<usize>,
    pending: &mut Vec<Command>,
    ui: &egui::Ui,
    response: &egui::Response,
    camera: &crate::scene::Camera,
    rect: egui::Rect,
) -> bool {
    let key = response.id.with("dragged light");
    let (w, h) = (rect.width().max(1.0), rect.height().max(1.0));
    let frame = CameraFrame::new(camera, w as u32, h as u32);
    let to_screen = |p: glam::Vec3| {
        frame
            .project(p)
            .map(|(x, y)| rect.min + egui::vec2(x / w * rect.width(), y / h * rect.height()))
    };
    let i = match held(ui, response, key, || {
        let origin = ui.input(|i| i.pointer.press_origin())?;
        edit.lights
            .iter()
            .enumerate()
            // A headlight stays at the eye: it is moved with the camera, not dragged.
            .filter(|(_, l)| !l.follow_camera)
            .filter_map(|(i, l)| to_screen(l.position).map(|s| (i, s.distance(origin))))
            .filter(|(_, d)| *d <= LIGHT_GRAB_RADIUS)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }) {
        Ok(i) => i,
        Err(ours) => return ours,
    };
    let delta = response.drag_delta();
    if let Some(light) = edit.lights.get_mut(i)
        && delta != egui::Vec2::ZERO
    {
        light.position += plane_move(camera, light.position, delta, rect.height());
        *selected_light = Some(i);
        pending.push(Command::Restart);
    }
    true
}

/// The sphere of `spheres` the ray through screen point `at` of a view seen through `camera`
/// over `rect` meets first, if any.
pub fn sphere_at(
    spheres: &[crate::scene::Sphere],
    camera: &crate::scene::Camera,
    rect: egui::Rect,
    at: egui::Pos2,
) -> Option<usize> {
    let (w, h) = (rect.width().max(1.0), rect.height().max(1.0));
    let frame = CameraFrame::new(camera, w as u32, h as u32);
    let ray = frame.ray(at.x - rect.min.x, at.y - rect.min.y);
    let d = ray.dir.normalize_or(glam::Vec3::NEG_Z);
    spheres
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            let oc = ray.origin - s.center;
            let b = oc.dot(d);
            let c = oc.length_squared() - s.radius * s.radius;
            let disc = b * b - c;
            if disc < 0.0 {
                return None;
            }
            let t = -b - disc.sqrt();
            let t = if t > 0.0 { t } else { -b + disc.sqrt() };
            (t > 0.0).then_some((i, t))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// Shift and a drag that starts on a sphere in a view seen through `camera` over `rect` moves
/// the sphere in the plane facing the camera (the accelerator is rebuilt as it moves); returns
/// whether the drag is the sphere's.
pub fn drag_sphere(
    edit: &mut Scene,
    pending: &mut Vec<Command>,
    ui: &egui::Ui,
    response: &egui::Response,
    camera: &crate::scene::Camera,
    rect: egui::Rect,
) -> bool {
    let key = response.id.with("dragged sphere");
    let i = match held(ui, response, key, || {
        let shift = ui.input(|i| i.modifiers.shift);
        ui.input(|i| i.pointer.press_origin())
            .filter(|_| shift)
            .and_then(|origin| sphere_at(&edit.spheres, camera, rect, origin))
    }) {
        Ok(i) => i,
        Err(ours) => return ours,
    };
    let delta = response.drag_delta();
    if let Some(sphere) = edit.spheres.get_mut(i)
        && delta != egui::Vec2::ZERO
    {
        sphere.center += plane_move(camera, sphere.center, delta, rect.height());
        pending.push(Command::Rebuild);
    }
    true
}

/// The item a primary drag holds, kept under `key` from the frame the drag starts (`grab`
/// picks it, or nothing) until it ends: `Ok(index)` while the drag goes on, else `Err` of
/// whether this frame's input was the item's (the frame its drag stopped).
fn held(
    ui: &egui::Ui,
    response: &egui::Response,
    key: egui::Id,
    grab: impl FnOnce() -> Option<usize>,
) -> Result<usize, bool> {
    if response.drag_started_by(egui::PointerButton::Primary) {
        let grabbed = grab();
        ui.data_mut(|d| match grabbed {
            Some(i) => {
                d.insert_temp(key, i);
            }
            None => d.remove::<usize>(key),
        });
    }
    let Some(i) = ui.data(|d| d.get_temp::<usize>(key)) else {
        return Err(false);
    };
    if !response.dragged_by(egui::PointerButton::Primary) {
        ui.data_mut(|d| d.remove::<usize>(key));
        return Err(response.drag_stopped());
    }
    Ok(i)
}

/// The world move of a point at `p` dragged by `delta` points in a view `height` points tall
/// seen through `camera`: in the plane through `p` facing the camera, so the point stays under
/// the pointer.
pub fn plane_move(
    camera: &crate::scene::Camera,
    p: glam::Vec3,
    delta: egui::Vec2,
    height: f32,
) -> glam::Vec3 {
    let forward = (camera.look_at - camera.position).normalize_or(glam::Vec3::NEG_Z);
    let right = forward.cross(camera.up).normalize_or(glam::Vec3::X);
    let up = right.cross(forward);
    let depth = (p - camera.position).dot(forward).max(1e-4);
    let per_point = 2.0 * depth * (camera.fov_y_deg.to_radians() * 0.5).tan() / height.max(1.0);
    (right * delta.x - up * delta.y) * per_point
}

/// The orbit (yaw, pitch in radians) of a drag by `delta` points over a view `width` points wide,
/// turning `degrees` for a drag across the whole width (the same rate up and down), so the
/// speed follows the view's size on screen.
pub fn orbit_angles(delta: egui::Vec2, width: f32, degrees: f32) -> (f32, f32) {
    let per_point = degrees.to_radians() / width.max(1.0);
    (delta.x * per_point, delta.y * per_point)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dragged_point_stays_under_the_pointer() {
        let camera = crate::scene::Camera {
            position: glam::Vec3::new(0.0, 0.0, 5.0),
            look_at: glam::Vec3::ZERO,
            up: glam::Vec3::Y,
            fov_y_deg: 60.0,
        };
        let (w, h) = (400u32, 300u32);
        let frame = CameraFrame::new(&camera, w, h);
        let p = glam::Vec3::new(0.5, 0.3, -1.0);
        let (x0, y0) = frame.project(p).expect("in view");
        let moved = p + plane_move(&camera, p, egui::vec2(40.0, -25.0), h as f32);
        let (x1, y1) = frame.project(moved).expect("in view");
        assert!((x1 - x0 - 40.0).abs() < 1e-2 && (y1 - y0 + 25.0).abs() < 1e-2);
        // In the plane facing the camera: the depth stays.
        assert!((moved.z - p.z).abs() < 1e-5);
    }

    #[test]
    fn a_drag_across_the_width_turns_the_set_angle() {
        let (yaw, pitch) = orbit_angles(egui::vec2(640.0, 0.0), 640.0, 180.0);
        assert!((yaw - std::f32::consts::PI).abs() < 1e-6);
        assert_eq!(pitch, 0.0);
        // A quarter of the width: a quarter of 180°.
        let (yaw, _) = orbit_angles(egui::vec2(320.0, 0.0), 1280.0, 180.0);
        assert!((yaw.to_degrees() - 45.0).abs() < 1e-4);
        let (_, pitch) = orbit_angles(egui::vec2(0.0, -100.0), 400.0, 90.0);
        assert!((pitch.to_degrees() + 22.5).abs() < 1e-4);
    }
}
