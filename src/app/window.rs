//! The window: eframe's entry point and the frame, which polls the renders, draws the panels
//! and panes with the parts each needs, and applies the frame's commands at its end.

use std::path::{Path, PathBuf};

use eframe::egui;

use super::dialog::BrowseFor;
use super::{
    Command, ViewerApp, input, lesson_panel, panels, pseudocode_pane, scene_pane, tree_view, watch,
    workspace,
};
use crate::scene;

/// Opens the window and runs the viewer until it is closed.
pub fn run(scene_arg: Option<&str>) -> anyhow::Result<()> {
    // A file is opened in the background once the window is up (a big mesh takes seconds to
    // read and build): the window shows the default scene and the open's progress meanwhile.
    // Built-in scene names and missing files are answered at once.
    let mut background = None;
    let (scene, label) = match scene_arg {
        Some(arg) if Path::new(arg).is_file() => {
            background = Some(PathBuf::from(arg));
            (
                scene::builtin::load_builtin("default")?,
                "default".to_string(),
            )
        }
        Some(arg) => (scene::open_scene_arg(arg)?, arg.to_string()),
        None => (
            scene::builtin::load_builtin("default")?,
            "default".to_string(),
        ),
    };
    let options = eframe::NativeOptions {
        renderer: eframe::Renderer::Wgpu,
        viewport: egui::ViewportBuilder::default()
            .with_title("raytree")
            .with_inner_size([1400.0, 900.0])
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native(
        "raytree",
        options,
        Box::new(move |cc| {
            let mut app = ViewerApp::new(cc, scene, label).map_err(|e| -> Box<dyn std::error::Error + Send + Sync> { e.into() })?;
            if let Some(path) = background {
                app.command(Command::OpenFile(path));
            }
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| {
        anyhow::anyhow!(
            "cannot open the viewer window ({e}); without a display or graphics adapter, use `raytree render SCENE -o out.png`"
        )
    })
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        if !self.files.has_waker() {
            let wake = ctx.clone();
            let waker: watch::Waker = std::sync::Arc::new(move || wake.request_repaint());
            self.files
                .wake_with(waker, &self.working.scene, &mut self.messages);
        }
        self.poll_session();
        self.workspace.scene_dir = self
            .working
            .scene
            .source
            .as_deref()
            .and_then(std::path::Path::parent)
            .filter(|p| !p.as_os_str().is_empty())
            .map(std::path::Path::to_path_buf);
        self.render.poll_export(&mut self.messages);
        input::shortcuts(
            &ctx,
            &mut self.workspace,
            &mut self.working,
            &mut self.pending,
        );
        let toggle = egui::KeyboardShortcut::new(egui::Modifiers::COMMAND, egui::Key::B);
        if ctx.input_mut(|i| i.consume_shortcut(&toggle)) {
            self.workspace.toggle_settings_panel(&mut self.messages);
        }
        // F: focus on the tree, unless a text field takes the key.
        if !ctx.egui_wants_keyboard_input()
            && ctx.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::F))
        {
            if self.selection.tree.is_some() || self.workspace.focused() {
                self.workspace.toggle_focus();
            } else {
                self.messages
                    .notice("focus shows a ray tree: click a pixel in the render first");
            }
        }
        panels::top_bar(
            ui,
            &mut self.workspace,
            &mut self.working,
            &self.files,
            &mut self.messages,
            &mut self.lesson,
            &mut self.pending,
        );
        let finished = self.is_finished();
        let target = self.viewer_target();
        panels::status_bar(
            ui,
            &self.render,
            &mut self.files,
            &self.selection,
            target,
            finished,
            &mut self.pending,
        );
        // Hover is transient: the views set it again while the pointer stays on a node.
        self.selection.tree_state.hovered = None;
        self.selection.tree_state.drawn = Default::default();
        scene_pane::advance_playback(&mut self.scene_view, &mut self.selection, &ctx);
        self.workspace
            .settle_settings_panel(ctx.content_rect().width(), &mut self.messages);
        if !self.workspace.prefs.settings_panel {
            // A slim strip keeps the hidden settings one click away.
            egui::Panel::left("settings strip")
                .resizable(false)
                .exact_size(30.0)
                .show(ui, |ui| {
                    if ui
                        .button("»")
                        .on_hover_text("show the settings (Ctrl+B)")
                        .clicked()
                    {
                        self.workspace.toggle_settings_panel(&mut self.messages);
                    }
                });
        } else {
            egui::Panel::left("settings")
                .resizable(true)
                .default_size(290.0)
                .show(ui, |ui| {
                    ui.with_layout(egui::Layout::right_to_left(egui::Align::Min), |ui| {
                        if ui
                            .small_button("« hide")
                            .on_hover_text("hide the settings (Ctrl+B); the render gets the room")
                            .clicked()
                        {
                            self.workspace.toggle_settings_panel(&mut self.messages);
                        }
                    });
                    // Scrolled both ways: wide content (an opened material) scrolls instead of
                    // widening the panel, which would move and resize the render.
                    egui::ScrollArea::both().show(ui, |ui| {
                        panels::side_panel(
                            ui,
                            &mut self.working,
                            &mut self.workspace.prefs,
                            &mut self.render,
                            &self.selection,
                            &mut self.pending,
                        )
                    });
                });
        }
        lesson_panel::side_panel(self, ui);
        // The panes fill the central panel edge to edge.
        let frame = egui::Frame::central_panel(ui.style()).inner_margin(0);
        egui::CentralPanel::default()
            .frame(frame)
            .show(ui, |ui| workspace::show(self, ui, pane_ui));
        if let Some(command) = self.workspace.show_browser(&ctx) {
            self.pending.push(command);
        }
        tree_window(self, &ctx);
        panels::help_window(&ctx, &mut self.workspace.show_help);
        let has_tree = self.selection.tree.is_some();
        let sizes = panels::ExportSizes {
            shown: self.render.size(),
            done: self.render.progress.samples_done,
            target: self.viewer_target(),
            scene: self.render.scene_size,
            samples: self.working.scene.render.samples,
        };
        panels::export_window(
            &ctx,
            &mut self.workspace,
            has_tree,
            &self.files.file_stem(),
            sizes,
        );
        let working = &mut self.working;
        let sweep = &mut self.workspace.sweep;
        if sweep.open
            && let Some(point) = sweep.show(&ctx, &working.scene, &working.settings.trace)
        {
            // A clicked point: its settings become the viewer's; say what changed.
            if let Some(text) = sweep.applied.clone() {
                self.messages.notice(text);
            }
            self.apply_point(&point);
        }
        self.messages.show(&ctx);
        self.messages.log_window(&ctx);
        self.apply();
        self.working.track(&ctx);
        lesson_panel::after_frame(self, &ctx);
        self.note_pin();
        self.render.follow_display_prefs(&self.workspace.prefs);
        // A background export wakes the UI itself, at each percent and when it is done.
        if !self.is_finished() || !self.scene_view.is_finished() {
            ctx.request_repaint();
        } else if let Some(wait) = self.files.reload_in() {
            // A save settles: one frame when it has, to reload. Otherwise an idle viewer asks
            // for no frame at all; the watcher wakes it on a change of the scene's files.
            ctx.request_repaint_after(wait);
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        let mut prefs = self.workspace.prefs_to_save();
        self.lesson.keep_prefs(&mut prefs);
        eframe::set_value(storage, eframe::APP_KEY, &prefs);
    }
}

/// The diagram toolbar's buttons that rearrange the window: focus mode and the pop-out.
fn tree_tools(ui: &mut egui::Ui, focused: bool, focus: &mut bool, pop: &mut bool) {
    let mut on = focused;
    if ui
        .toggle_value(&mut on, "Focus")
        .on_hover_text("F: the tree's panes get most of the window; again to go back")
        .changed()
    {
        *focus = true;
    }
    if ui
        .button("Pop out")
        .on_hover_text("the diagram and the list in their own window; close it to bring them back")
        .clicked()
    {
        *pop = true;
    }
}

/// The tree's diagram and list in their own native window (an egui viewport), while popped
/// out; closing it (or "Dock back") puts them back in the workspace.
fn tree_window(app: &mut ViewerApp, ctx: &egui::Context) {
    if !app.workspace.popped_out {
        return;
    }
    let builder = egui::ViewportBuilder::default()
        .with_title("raytree: ray tree")
        .with_inner_size([960.0, 640.0]);
    let dock = ctx.show_viewport_immediate(
        egui::ViewportId::from_hash_of("raytree tree window"),
        builder,
        |ui, _class| {
            let mut dock = ui.ctx().input(|i| i.viewport().close_requested());
            egui::CentralPanel::default().show(ui, |ui| {
                let Some(tree) = super::picker::strip(ui, &mut app.selection, &app.render.tracer)
                else {
                    ui.weak("click a pixel in the render view for its ray tree");
                    dock |= ui.button("Dock back").clicked();
                    return;
                };
                let half = ui.available_width() * 0.55;
                ui.horizontal_top(|ui| {
                    ui.allocate_ui(egui::vec2(half, ui.available_height()), |ui| {
                        ui.vertical(|ui| {
                            let mut tools = |ui: &mut egui::Ui| {
                                dock |= ui
                                    .button("Dock back")
                                    .on_hover_text("the panes back into the main window")
                                    .clicked();
                            };
                            let state = &mut app.selection.tree_state;
                            let export = match state.pinned.clone() {
                                Some(pinned) => {
                                    tree_view::compare(ui, &tree, &pinned, state, &mut tools)
                                }
                                None => tree_view::diagram(ui, &tree, state, &mut tools),
                            };
                            if export {
                                let name = format!("tree-{}-{}.svg", tree.pixel[0], tree.pixel[1]);
                                app.workspace.browse(BrowseFor::ExportDiagram, &name);
                            }
                        });
                    });
                    ui.separator();
                    ui.vertical(|ui| {
                        panels::tree_panel(
                            ui,
                            &mut app.selection,
                            &mut app.workspace,
                            &app.render.tracer,
                        );
                    });
                });
            });
            dock
        },
    );
    if dock {
        app.workspace.set_popped_out(false);
    }
}

/// What each pane of the workspace shows.
fn pane_ui(app: &mut ViewerApp, ui: &mut egui::Ui, pane: workspace::Pane) {
    use workspace::Pane;
    match pane {
        Pane::Render => {
            app.messages.corner = Some(ui.max_rect());
            input::render_pane(
                ui,
                &mut app.render,
                &mut app.selection,
                &mut app.working.scene.camera,
                &app.workspace.prefs,
                &app.scene_view.filter,
                app.workspace.focused(),
                &mut app.pending,
            )
        }
        Pane::SceneView => scene_pane::scene_view_ui(
            ui,
            &mut app.scene_view,
            &app.render.tracer,
            &mut app.selection,
            &mut app.working.scene,
            &app.workspace.prefs,
            &mut app.pending,
        ),
        Pane::Diagram => match super::picker::strip(ui, &mut app.selection, &app.render.tracer) {
            Some(tree) => {
                let (mut focus, mut pop) = (false, false);
                let focused = app.workspace.focused();
                let mut tools = |ui: &mut egui::Ui| tree_tools(ui, focused, &mut focus, &mut pop);
                let state = &mut app.selection.tree_state;
                let export = match state.pinned.clone() {
                    Some(pinned) => tree_view::compare(ui, &tree, &pinned, state, &mut tools),
                    None => tree_view::diagram(ui, &tree, state, &mut tools),
                };
                if export {
                    let name = format!("tree-{}-{}.svg", tree.pixel[0], tree.pixel[1]);
                    app.workspace.browse(BrowseFor::ExportDiagram, &name);
                }
                if focus {
                    app.workspace.toggle_focus();
                }
                if pop {
                    app.workspace.set_popped_out(true);
                }
            }
            None => {
                ui.weak("click a pixel in the render view for its ray tree");
            }
        },
        Pane::Pseudocode => {
            super::picker::strip(ui, &mut app.selection, &app.render.tracer);
            pseudocode_pane::ui(ui, &app.selection, &mut app.lesson.code);
        }
        Pane::TreeList => {
            super::picker::strip(ui, &mut app.selection, &app.render.tracer);
            if app.selection.tree.is_some() {
                panels::tree_panel(
                    ui,
                    &mut app.selection,
                    &mut app.workspace,
                    &app.render.tracer,
                );
            } else {
                ui.weak(
                    "click a pixel in the render view for its ray tree; shift-click adds more pixels",
                );
            }
        }
    }
}
