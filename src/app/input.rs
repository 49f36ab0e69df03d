//! The viewer's input: keyboard shortcuts and dropped files, and the viewport's pointer
//! (drag to orbit or pan, scroll to zoom, click for a pixel's ray tree, hover for its values),
//! each turned into an edit of the working copy or a [`Command`].

use std::path::PathBuf;
use std::sync::Arc;

use eframe::egui;

use super::file_browser::{BrowseFor, FileBrowser};
use super::viewport::DisplayCallback;
use super::{Command, ViewerApp, tree_view, viewport};

impl ViewerApp {
    /// Export (Ctrl+S), open (Ctrl+O), help (F1), stop (Escape) and a file dropped on the
    /// window.
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
        if do_save {
            let name = format!("{}.png", self.file_stem());
            self.browser = Some(FileBrowser::new(BrowseFor::Export, self.start_dir(), &name));
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
        let avail = ui.available_rect_before_wrap();
        if avail.width() < 1.0 || avail.height() < 1.0 {
            return; // a zero-area window: nothing to draw
        }
        let scale = (avail.width() / w).min(avail.height() / h);
        let size = egui::vec2(w * scale, h * scale);
        let rect = egui::Rect::from_center_size(avail.center(), size);
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        response
            .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "render viewport"));
        // The tree's rays over the image: drawn by shaders/overlay.wgsl with the render
        // camera's projection, one colour per ray kind, the hovered or selected node in white.
        let overlay = self.tree.as_ref().map(|tree| {
            let extent = self
                .scene
                .bounds()
                .map(|(lo, hi)| (hi - lo).length())
                .unwrap_or(10.0)
                .max(1e-3);
            let frame = crate::scene::CameraFrame::new(
                &self.scene.camera,
                self.scene.render.width,
                self.scene.render.height,
            );
            Arc::new(viewport::Overlay {
                clip_from_world: frame.clip_from_world(extent * 1e-5, extent * 1e5),
                vertices: tree_view::overlay_vertices(tree, &self.tree_state, extent),
            })
        });
        ui.painter()
            .add(eframe::egui_wgpu::Callback::new_paint_callback(
                rect,
                DisplayCallback {
                    shared: self.display.clone(),
                    overlay,
                },
            ));
        let to_pixel = |p: egui::Pos2| {
            let x = ((p.x - rect.min.x) / scale).floor();
            let y = ((p.y - rect.min.y) / scale).floor();
            (x >= 0.0 && y >= 0.0 && x < w && y < h).then_some((x as u32, y as u32))
        };
        self.hover = response.hover_pos().and_then(to_pixel);
        if response.clicked()
            && let Some((x, y)) = response.interact_pointer_pos().and_then(to_pixel)
        {
            self.pending.push(Command::Pick(x, y));
        }
        let delta = response.drag_delta();
        if delta != egui::Vec2::ZERO {
            if response.dragged_by(egui::PointerButton::Primary) {
                self.edit.camera.orbit(delta.x * 0.01, delta.y * 0.01);
                self.pending.push(Command::Restart);
            } else if response.dragged_by(egui::PointerButton::Secondary)
                || response.dragged_by(egui::PointerButton::Middle)
            {
                self.edit.camera.pan(delta.x / size.y, delta.y / size.y);
                self.pending.push(Command::Restart);
            }
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.edit.camera.zoom((-scroll * 0.002).exp());
                self.pending.push(Command::Restart);
            }
        }
    }
}
