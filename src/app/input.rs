//! The viewer's input: keyboard shortcuts and dropped files, and the viewport's pointer
//! (drag to orbit or pan, scroll to zoom, click for a pixel's ray tree, shift-click for one
//! more, Ctrl or Alt drag for a grid of a rectangle's pixels, hover for its values),
//! each turned into an edit of the working copy or a [`Command`].

use std::path::PathBuf;

use eframe::egui;

use super::file_browser::{BrowseFor, FileBrowser};
use super::paint3d::ScreenView;
use super::viewport::{DisplayCallback, DisplayId};
use super::{Command, ViewerApp, legend, scene_pane};
use crate::scene::CameraFrame;
use crate::scene_view::Filter;

impl ViewerApp {
    /// Export (Ctrl+S), open (Ctrl+O), help (F1), stop (Escape), undo (Ctrl+Z), redo
    /// (Ctrl+Shift+Z, Ctrl+Y), reset the camera (Home) and a file dropped on the window.
    pub(super) fn shortcuts(&mut self, ctx: &egui::Context) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        let save = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
        let open = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
        let (do_save, do_open, help, stop) = ctx.input_mut(|i| {
            (
                i.consume_shortcut(&save),
                i.consume_shortcut(&open),
                i.consume_key(Modifiers::NONE, Key::F1),
                i.consume_key(Modifiers::NONE, Key::Escape),
            )
        });
        // A text field being typed in keeps its own Ctrl+Z and Home.
        if !ctx.egui_wants_keyboard_input() {
            let redo_shift = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
            let redo_y = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
            let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
            // Ctrl+Shift+Z first: the plain Ctrl+Z pattern would match it too.
            let (redo, undo, home) = ctx.input_mut(|i| {
                let redo = i.consume_shortcut(&redo_shift) | i.consume_shortcut(&redo_y);
                (
                    redo,
                    i.consume_shortcut(&undo),
                    i.consume_key(Modifiers::NONE, Key::Home),
                )
            });
            if redo {
                self.redo();
            }
            if undo {
                self.undo();
            }
            if home {
                self.reset_camera();
            }
        }
        if do_save {
            self.export_choice = true;
        }
        if do_open {
            self.browser = Some(FileBrowser::new(BrowseFor::Open, self.start_dir(), ""));
        }
        if help {
            self.show_help = !self.show_help;
        }
        if stop {
            self.pending.push(Command::Stop);
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        if let Some(path) = dropped.into_iter().next() {
            self.pending.push(Command::OpenFile(path));
        }
    }

    /// Draws the render fitted into `ui`'s space and handles orbit, pan, zoom, click and hover.
    pub(super) fn viewport(&mut self, ui: &mut egui::Ui) {
        let (w, h) = (
            self.scene.render.width as f32,
            self.scene.render.height as f32,
        );
        let mut avail = ui.available_rect_before_wrap();
        if avail.width() < 1.0 || avail.height() < 1.0 {
            return; // a zero-area window: nothing to draw
        }
        // A mode that maps values to colours gets its scale in a strip beside the image.
        let scale = super::modes::colour_scale(self.prefs.mode, self.scene.render.max_depth);
        if let Some(scale) = &scale
            && avail.width() > 3.0 * legend::SCALE_WIDTH
        {
            let strip = egui::Rect::from_min_max(
                egui::pos2(avail.max.x - legend::SCALE_WIDTH, avail.min.y),
                avail.max,
            );
            avail.max.x = strip.min.x;
            let height = strip.height() * 0.6;
            ui.scope_builder(
                egui::UiBuilder::new().max_rect(strip.shrink2(egui::vec2(4.0, 8.0))),
                |ui| legend::colour_scale_ui(ui, scale, height),
            );
        }
        let scale = (avail.width() / w).min(avail.height() / h);
        let size = egui::vec2(w * scale, h * scale);
        let rect = egui::Rect::from_center_size(avail.center(), size);
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        response
            .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "render viewport"));
        ui.painter()
            .add(eframe::egui_wgpu::Callback::new_paint_callback(
                rect,
                DisplayCallback {
                    id: DisplayId::Render,
                    shared: self.display.clone(),
                },
            ));
        // The trees' rays over the image, by the scene view's rules and widths, seen from the
        // render camera; parts behind surfaces (the render's own depth) dimmed.
        if self.tree.is_some() || !self.extra_trees.is_empty() {
            let view = ScreenView {
                rect,
                frame: CameraFrame::new(
                    &self.scene.camera,
                    self.scene.render.width,
                    self.scene.render.height,
                ),
                width: self.scene.render.width,
                height: self.scene.render.height,
            };
            let filter = Filter {
                max_generation: self.tree_state.reveal.unwrap_or(u32::MAX),
                ..self.scene_view.filter.clone()
            };
            let depth = self.film.depth();
            let drawn = scene_pane::draw_trees(self, &ui.painter_at(rect), &view, &depth, &filter);
            legend::ray_key(&ui.painter_at(rect), rect);
            scene_pane::pick_and_hover_only(self, &response, &drawn);
        }
        let to_pixel = |p: egui::Pos2| {
            let x = ((p.x - rect.min.x) / scale).floor();
            let y = ((p.y - rect.min.y) / scale).floor();
            (x >= 0.0 && y >= 0.0 && x < w && y < h).then_some((x as u32, y as u32))
        };
        self.hover = response.hover_pos().and_then(to_pixel);
        let modifiers = ui.input(|i| i.modifiers);
        if response.clicked()
            && let Some((x, y)) = response.interact_pointer_pos().and_then(to_pixel)
        {
            self.pending.push(if modifiers.shift {
                Command::PickMore(x, y)
            } else {
                Command::Pick(x, y)
            });
        }
        // Ctrl (or Alt) and drag: a rectangle of pixels whose trees are traced on release.
        let selecting = modifiers.command || modifiers.alt;
        if selecting && response.dragged_by(egui::PointerButton::Primary) {
            if let (Some(origin), Some(now)) = (
                ui.input(|i| i.pointer.press_origin()),
                response.interact_pointer_pos(),
            ) {
                self.rect_select = Some((origin, now));
                ui.painter_at(rect).rect_stroke(
                    egui::Rect::from_two_pos(origin, now),
                    0.0,
                    egui::Stroke::new(2.0, egui::Color32::from_rgb(255, 120, 255)),
                    egui::StrokeKind::Middle,
                );
            }
            return;
        }
        if let Some((origin, end)) = self.rect_select.take()
            && selecting
            && response.drag_stopped()
        {
            let inside = |p: egui::Pos2| to_pixel(rect.shrink(0.01).clamp(p));
            if let (Some(a), Some(b)) = (inside(origin), inside(end)) {
                self.pending.push(Command::PickRect([a.0, a.1], [b.0, b.1]));
            }
            return;
        }
        let delta = response.drag_delta();
        if delta != egui::Vec2::ZERO {
            if response.dragged_by(egui::PointerButton::Primary) {
                let (yaw, pitch) = orbit_angles(delta, size.x, self.prefs.orbit_degrees);
                self.edit.camera.orbit(yaw, pitch);
                self.pending.push(Command::MoveCamera);
            } else if response.dragged_by(egui::PointerButton::Secondary)
                || response.dragged_by(egui::PointerButton::Middle)
            {
                self.edit.camera.pan(delta.x / size.y, delta.y / size.y);
                self.pending.push(Command::MoveCamera);
            }
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.edit.camera.zoom((-scroll * 0.002).exp());
                self.pending.push(Command::MoveCamera);
            }
        }
    }
}

/// How near (points) a press must be to a light's marker to grab it.
pub const LIGHT_GRAB_RADIUS: f32 = 12.0;

/// A drag that starts on a light's marker in a view seen through `camera` over `rect` moves
/// that light in the plane facing the camera (it stays under the pointer); returns whether
/// the drag is the light's (then the view must not orbit).
pub(super) fn drag_light(
    app: &mut ViewerApp,
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
    if response.drag_started_by(egui::PointerButton::Primary)
        && let Some(origin) = ui.input(|i| i.pointer.press_origin())
    {
        let grabbed = app
            .edit
            .lights
            .iter()
            .enumerate()
            .filter_map(|(i, l)| to_screen(l.position).map(|s| (i, s.distance(origin))))
            .filter(|(_, d)| *d <= LIGHT_GRAB_RADIUS)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i);
        ui.data_mut(|d| match grabbed {
            Some(i) => {
                d.insert_temp(key, i);
            }
            None => d.remove::<usize>(key),
        });
    }
    let Some(i) = ui.data(|d| d.get_temp::<usize>(key)) else {
        return false;
    };
    if !response.dragged_by(egui::PointerButton::Primary) {
        ui.data_mut(|d| d.remove::<usize>(key));
        return response.drag_stopped();
    }
    let delta = response.drag_delta();
    if let Some(light) = app.edit.lights.get_mut(i)
        && delta != egui::Vec2::ZERO
    {
        light.position += plane_move(camera, light.position, delta, rect.height());
        app.selected_light = Some(i);
        app.pending.push(Command::Restart);
    }
    true
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
