//! The viewer's input: keyboard shortcuts and dropped files, and the viewport's pointer
//! (drag to orbit or pan, scroll to zoom, click for a pixel's ray tree, shift-click for one
//! more, Ctrl or Alt drag for a grid of a rectangle's pixels, hover for its values),
//! each turned into an edit of the working copy or a [`Command`].

use std::path::PathBuf;

use eframe::egui;

use super::dialog::{BrowseFor, FileBrowser};
use super::paint3d::ScreenView;
use super::viewport::{DisplayCallback, DisplayId};
use super::{Command, ViewerApp, gesture, legend, scene_pane};
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
        let mut avail = ui.available_rect_before_wrap();
        if avail.width() < 1.0 || avail.height() < 1.0 {
            return; // a zero-area window: nothing to draw
        }
        // A mode that maps values to colours gets its scale in a strip beside (or under) the image.
        let scale = super::modes::colour_scale(self.prefs.mode, self.scene.render.max_depth);
        if let Some(scale) = &scale
            && avail.width() > 2.0 * legend::SCALE_WIDTH
            && avail.height() > 2.0 * legend::SCALE_HEIGHT
        {
            let (rw, rh) = self.render_size();
            let (image, strip, below) = legend::place_scale(avail, rw as f32, rh as f32);
            avail = image;
            let length = if below {
                strip.width() * 0.8
            } else {
                strip.height() * 0.6
            };
            ui.scope_builder(
                egui::UiBuilder::new().max_rect(strip.shrink2(egui::vec2(4.0, 6.0))),
                |ui| legend::colour_scale_ui(ui, scale, length, below),
            );
        }
        // The render follows the image area's size (when set); it is drawn fitted, on whole pixels.
        self.observe_pane(ui.ctx(), avail);
        let (w, h) = (
            self.scene.render.width as f32,
            self.scene.render.height as f32,
        );
        let rect = self.image_rect(ui.ctx(), avail);
        let size = rect.size();
        let scale = size.x / w;
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
                let (yaw, pitch) = gesture::orbit_angles(delta, size.x, self.prefs.orbit_degrees);
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
