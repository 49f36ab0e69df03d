//! The desktop viewer: the only module that uses egui, eframe and wgpu (docs/design.md,
//! "The viewer").
//!
//! [`ViewerApp`] is a few owned parts, each with its own file: the working copy the panels edit
//! and its history ([`undo::WorkingCopy`]), the progressive render ([`render_view::RenderView`]),
//! the open scene's files ([`scene_files::SceneFiles`]), the messages
//! ([`messages::Messages`]), what is picked ([`selection::TreeSelection`]), the scene view
//! ([`scene_pane::SceneView`]) and the window around them ([`workspace::Workspace`], with the
//! persisted [`Prefs`]). Panels get the parts they need and queue [`Command`]s;
//! [`ViewerApp::apply`] carries them out once, at the end of the frame, where any edit restarts
//! the progressive render with a new generation.

mod dialog;
mod film;
pub mod gesture;
mod input;
mod legend;
pub mod messages;
pub mod modes;
pub mod opening;
mod paint3d;
mod panels;
pub mod render_view;
mod saving;
pub mod scene_files;
pub mod scene_pane;
pub mod selection;
pub mod sweep;
pub mod tree_view;
pub mod undo;
pub mod viewport;
pub mod watch;
pub mod workspace;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use eframe::egui;

use crate::accel::Accel;
use crate::render::session::SessionEvent;
use crate::render::{Image, RenderSettings};
use crate::scene::{self, Scene};
use crate::trace::{TraceSettings, Tracer};
use dialog::BrowseFor;
use messages::Messages;
pub use render_view::PANE_SIZE_DEBOUNCE;
use render_view::{Reach, RenderView};
use scene_files::SceneFiles;
use selection::TreeSelection;
pub use selection::{MAX_TREES, remap_pixel};
use undo::WorkingCopy;
use viewport::GpuDisplay;
pub use workspace::{Prefs, SETTINGS_MIN_WIDTH, VIEWER_SAMPLES, Workspace};

/// Everything a panel can ask for; applied once at the end of the frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// The working copy of the scene or settings changed: render it.
    Restart,
    /// Only the render camera moved: render again, but the scene view's picture (which does
    /// not depend on the render camera) stays.
    MoveCamera,
    /// The scene's geometry or the accelerator changed: rebuild it, then render.
    Rebuild,
    OpenFile(PathBuf),
    OpenBuiltin(String),
    SaveScene(PathBuf),
    Export(PathBuf),
    /// The render with the trees drawn over it, as PNG.
    ExportOverlay(PathBuf),
    /// The scene view at the scene's size, as PNG.
    ExportSceneView(PathBuf),
    ExportTree(PathBuf),
    /// The tree's figure as SVG, to the generations shown.
    ExportDiagram(PathBuf),
    /// Show the ray tree of this pixel and select its material.
    Pick(u32, u32),
    /// Add this pixel's tree to the trees shown (shift-click).
    PickMore(u32, u32),
    /// Add the trees of a sparse grid of the pixels in `x0..=x1 × y0..=y1` (a dragged
    /// rectangle).
    PickRect([u32; 2], [u32; 2]),
    FrameAll,
    Stop,
}

/// The viewer.
pub struct ViewerApp {
    /// The scene and settings the panels edit, and their undo history.
    pub working: WorkingCopy,
    /// The progressive render of the working copy.
    pub render: RenderView,
    /// The open scene's files: its label, the watch for saves, an open under way.
    pub files: SceneFiles,
    /// Errors and notices, and the toasts made from them.
    pub messages: Messages,
    /// The trees shown and what is selected in them.
    pub selection: TreeSelection,
    /// The scene view: its camera, its own render and its filters.
    pub scene_view: scene_pane::SceneView,
    /// The preferences, the settings panel, the file dialog and the windows.
    pub workspace: Workspace,
    pending: Vec<Command>,
}

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

impl ViewerApp {
    /// The viewer over `scene`, drawing through the wgpu renderer of `cc`.
    pub fn new(
        cc: &eframe::CreationContext<'_>,
        scene: Scene,
        label: String,
    ) -> Result<Self, String> {
        let render_state = cc.wgpu_render_state.as_ref().ok_or_else(|| {
            "the viewer needs the wgpu renderer and no graphics adapter was found; use `raytree render SCENE -o out.png`".to_string()
        })?;
        GpuDisplay::install(render_state);
        let max_side = render_state.device.limits().max_texture_dimension_2d;
        // The preferences of the last run, read before the first render so it uses them.
        let prefs = cc
            .storage
            .and_then(|s| eframe::get_value::<Prefs>(s, eframe::APP_KEY))
            .unwrap_or_default()
            .checked();
        let saved = cc
            .storage
            .is_some_and(|s| s.get_string(eframe::APP_KEY).is_some());
        Self::with_limit(scene, label, max_side, Workspace::new(prefs, saved))
    }

    /// The viewer's state without a window (the GPU display is installed by [`Self::new`]).
    pub fn headless(scene: Scene, label: String) -> Result<Self, String> {
        let workspace = Workspace::new(Prefs::default(), false);
        Self::with_limit(scene, label, scene::rules::MAX_IMAGE_SIZE, workspace)
    }

    fn with_limit(
        scene: Scene,
        label: String,
        max_side: u32,
        workspace: Workspace,
    ) -> Result<Self, String> {
        let settings = RenderSettings::default();
        let edit = scene.clone();
        let render = RenderView::new(Arc::new(scene), settings.trace, settings.threads, max_side)?;
        let scene_view = scene_pane::SceneView::new(settings.threads)?;
        let mut app = Self {
            working: WorkingCopy::new(edit, settings),
            render,
            files: SceneFiles::new(label),
            messages: Messages::default(),
            selection: TreeSelection::default(),
            scene_view,
            workspace,
            pending: Vec::new(),
        };
        for w in app.render.scene().warnings.clone() {
            app.messages.notice(w);
        }
        app.files.watch(&app.working.scene, &mut app.messages);
        app.restart(false, Reach::RenderAndSceneView);
        Ok(app)
    }

    /// The scene rendered now.
    pub fn scene(&self) -> &Scene {
        self.render.scene()
    }

    pub fn generation(&self) -> u64 {
        self.render.generation()
    }

    /// Samples per pixel in every pixel of the current generation (0 before the first full pass).
    pub fn samples_done(&self) -> u32 {
        self.render.progress.samples_done
    }

    /// Whether the current render reached its target and no file is being opened.
    pub fn is_finished(&self) -> bool {
        self.render.progress.finished_secs.is_some() && self.files.opening().is_none()
    }

    /// Samples per pixel the viewer refines to (then it idles).
    pub fn viewer_target(&self) -> u32 {
        self.workspace.prefs.viewer_target()
    }

    /// Sets the viewer's sample target and whether the render follows the pane's size, and
    /// renders again with them.
    pub fn set_view(&mut self, viewer_samples: u32, pane_size: bool) {
        set_view(
            &mut self.workspace.prefs,
            &mut self.render,
            &mut self.pending,
            viewer_samples,
            pane_size,
        );
    }

    /// Rays traced by the current generation so far.
    pub fn rays_traced(&self) -> u64 {
        self.render.session.stats().counts().total()
    }

    /// The size the viewer renders at: the render pane's pixels (when it follows the pane and
    /// the pane has been seen) or the scene's width and height.
    pub fn render_size(&self) -> (u32, u32) {
        self.render.size()
    }

    /// The film as it stands: the mean of the samples done so far.
    pub fn image(&self) -> Image {
        self.render.image()
    }

    /// The accelerator in use.
    pub fn accel(&self) -> &Accel {
        self.render.accel()
    }

    /// Queues a command, as a panel would.
    pub fn command(&mut self, c: Command) {
        self.pending.push(c);
    }

    /// Sets the trace settings of the working copy and renders with them (for callers
    /// outside the UI).
    pub fn set_trace(&mut self, trace: TraceSettings) {
        self.working.settings.trace = trace;
        self.pending.push(Command::Rebuild);
    }

    /// The render's pixel under the pointer, where the render starts its tiles.
    fn focus(&self) -> Option<(f32, f32)> {
        self.selection.hover.map(|(x, y)| (x as f32, y as f32))
    }

    /// Starts a new generation from the working copy; `rebuild` also rebuilds the accelerator.
    fn restart(&mut self, rebuild: bool, reach: Reach) {
        if let Err(e) = self
            .render
            .session
            .set_threads(self.working.settings.threads)
        {
            self.messages.error(e);
        }
        let edit = &mut self.working.scene;
        // An edit is held to the loader's rules; a bad one is refused and the scene stays.
        if let Err(e) = scene::rules::check_scene(edit, rebuild) {
            self.messages.error(format!("{e}; the edit was undone"));
            // The scene rendered may be at the pane's size: the scene's own size comes back.
            *edit = (**self.render.scene()).clone();
            (edit.render.width, edit.render.height) = self.render.scene_size;
            if self.render.generation() > 0 {
                return;
            }
        }
        // Headlights stand at the camera's eye, wherever it went (the one rule for it).
        edit.place_lights();
        // The viewer's buffers must fit the GPU's largest texture and the memory budget: a
        // larger render is shown scaled down (with a message); `raytree render` does full size.
        let pane = self.render.pane(&self.workspace.prefs);
        let fit = opening::fit_render(
            (edit.render.width, edit.render.height),
            pane,
            self.render.max_side,
        );
        if let Some(message) = fit.message {
            self.messages.error(message);
        }
        (edit.render.width, edit.render.height) = fit.scene;
        self.render.scene_size = fit.scene;
        let mut render_scene = edit.clone();
        (render_scene.render.width, render_scene.render.height) = fit.render;
        let scene = Arc::new(render_scene);
        let trace = self.working.settings.trace;
        if rebuild
            || self.render.pending_build.is_some()
            || self.render.tracer.settings.accel != trace.accel
        {
            let (target, focus) = (self.viewer_target(), self.focus());
            self.render.start_build(scene, trace, target, focus, reach);
            return;
        }
        let accel = self.render.tracer.accel.clone();
        self.start_generation(Arc::new(Tracer::with_accel(scene, trace, accel)), reach);
    }

    /// Starts a generation of `tracer` (its accelerator built) and makes it the current one.
    fn start_generation(&mut self, tracer: Arc<Tracer>, reach: Reach) {
        let (target, focus) = (self.viewer_target(), self.focus());
        self.render.start(tracer.clone(), target, focus);
        self.install_tracer(tracer, reach);
    }

    /// Makes the tracer of the generation just started (`start`ed, or built and handed out)
    /// the current one: film and display at its size, trees re-traced, and the scene view
    /// restarted when `reach` has it.
    fn install_tracer(&mut self, tracer: Arc<Tracer>, reach: Reach) {
        let old = self.render.install(tracer.clone());
        // The trees follow the scene: re-traced with the new settings.
        self.selection.follow(&tracer, old);
        if reach == Reach::RenderAndSceneView {
            if let Err(e) = self.scene_view.set_threads(self.working.settings.threads) {
                self.messages.error(e);
            }
            self.scene_view.restart(&tracer);
        }
    }

    /// Installs the tracer the session built, once it is handed out; true when it was.
    fn take_built(&mut self) -> bool {
        match self.render.take_built() {
            Some((tracer, reach)) => {
                self.install_tracer(tracer, reach);
                true
            }
            None => false,
        }
    }

    /// True while a saved change waits for its reload (the UI keeps polling).
    pub fn reload_pending(&self) -> bool {
        self.files.reload_pending()
    }

    /// Opens `path` (or reloads it after a save, `reload`) in the background: read, parse and
    /// build off the UI thread, the scene shown staying up until the new one is ready. Cancels
    /// an open already under way (its result is never installed). A reload of the same
    /// geometry keeps the camera (as moved in the viewer), the trees and the accelerator.
    fn start_open(&mut self, path: PathBuf, reload: bool) {
        let request = opening::Request {
            path,
            settings: self.working.settings.trace,
            pane: self.render.pane(&self.workspace.prefs),
            max_side: self.render.max_side,
            reload: reload.then(|| {
                (
                    self.render.tracer.clone(),
                    self.working.scene.camera.clone(),
                )
            }),
            hook: None,
        };
        self.files
            .start(request, &self.working.scene, &mut self.messages);
    }

    /// Takes the result of the background open, when it is ready.
    fn poll_open(&mut self) {
        let Some((job, outcome)) = self.files.take_finished() else {
            return;
        };
        match outcome {
            opening::Outcome::Opened(opened) => self.install_opened(&job.path, job.reload, *opened),
            // The message names the file, place and field; the old scene stays.
            opening::Outcome::Failed(e) if job.reload => self.messages.error(format!(
                "{e} (after a save; the last good scene stays until the file loads again)"
            )),
            opening::Outcome::Failed(e) => {
                self.messages.error(e);
                // The scene shown is watched again.
                self.files.watch(&self.working.scene, &mut self.messages);
            }
        }
    }

    /// Makes an opened (or reloaded) scene the one shown and rendered.
    fn install_opened(&mut self, path: &Path, reload: bool, opened: opening::Opened) {
        let opening::Opened {
            edit,
            tracer,
            fit,
            same_geometry,
            timings,
        } = opened;
        let reloaded = format!("reloaded {} after a save", path.display());
        if same_geometry {
            for w in &edit.warnings {
                self.messages.notice(w.clone());
            }
            // The camera as it is now (it may have moved while the file was read), the
            // accelerator shown kept: rendered as any edit is.
            let camera = self.working.scene.camera.clone();
            self.working.scene = edit;
            self.working.scene.camera = camera;
            self.messages.notice(reloaded);
            self.files.learn(timings);
            self.files.watch(&self.working.scene, &mut self.messages);
            self.restart(false, Reach::RenderAndSceneView);
            return;
        }
        self.replace_scene(edit, path.display().to_string());
        if reload {
            self.messages.notice(reloaded);
        }
        if let Some(message) = fit.message {
            self.messages.error(message);
        }
        self.render.scene_size = fit.scene;
        self.files.learn(timings);
        self.files.watch(&self.working.scene, &mut self.messages);
        self.render.pending_build = None;
        self.start_generation(tracer, Reach::RenderAndSceneView);
    }

    /// Takes the tiles that arrived, within a time budget so the UI stays responsive.
    pub fn poll_session(&mut self) {
        if self.files.saved()
            && let Some(path) = self.working.scene.source.clone()
        {
            self.start_open(path, true);
        }
        self.poll_open();
        // A tracer built off the UI thread comes before its generation's first tile.
        if !self.take_built() {
            let triangles = self.working.scene.triangles.len() as u64;
            self.render
                .show_build_progress(self.files.build_secs(triangles));
        }
        self.scene_view.poll();
        let budget = Instant::now();
        let shared = self.render.display.clone();
        let mut display = crate::sync::lock(&shared);
        let mode = self.workspace.prefs.mode;
        let generation = self.render.generation();
        while let Some(event) =
            self.render
                .session
                .next_within(generation, budget, Duration::from_millis(8))
        {
            match event {
                SessionEvent::Tile(tile) => {
                    // The build finished after `take_built` above was asked: its tracer (and
                    // the film at its size) comes before its first tile.
                    if self.render.pending_build.is_some() {
                        drop(display);
                        self.take_built();
                        display = crate::sync::lock(&shared);
                    }
                    if self.render.film.holds(tile.rect) {
                        let max_depth = self.render.scene().render.max_depth;
                        self.render
                            .film
                            .write_tile(&tile, mode, max_depth, &mut display);
                    }
                }
                SessionEvent::PassDone { pass, .. } => self.render.progress.pass_done(pass),
                SessionEvent::Finished { secs, .. } => {
                    self.render.progress.finished_secs = Some(secs);
                }
                SessionEvent::Failed { message, .. } => {
                    drop(display);
                    self.render.progress.pass_label = "stopped".into();
                    self.messages
                        .error(format!("{message}; the render stopped"));
                    return;
                }
            }
        }
    }

    /// Carries out the queued commands.
    pub fn apply(&mut self) {
        let commands = std::mem::take(&mut self.pending);
        let mut restart = false;
        let mut rebuild = false;
        let mut camera_only = true;
        for c in commands {
            if !matches!(c, Command::MoveCamera) {
                camera_only = false;
            }
            match c {
                Command::Restart | Command::MoveCamera => restart = true,
                Command::Rebuild => {
                    restart = true;
                    rebuild = true;
                }
                // Read, parsed and built in the background ([`opening`]).
                Command::OpenFile(path) => self.start_open(path, false),
                Command::OpenBuiltin(name) => match scene::builtin::load_builtin(&name) {
                    Ok(s) => {
                        // Built-in scenes are tiny: opened at once, superseding any open.
                        self.files.cancel();
                        self.replace_scene(s, name);
                        self.files.unwatch();
                        rebuild = true;
                        restart = true;
                    }
                    Err(e) => self.messages.error(e.to_string()),
                },
                Command::SaveScene(path) => self.save_scene(&path),
                Command::Export(path) => self.export(&path),
                Command::ExportOverlay(path) => self.export_drawn(&path, false),
                Command::ExportSceneView(path) => self.export_drawn(&path, true),
                Command::ExportTree(path) => self.export_tree(&path),
                Command::ExportDiagram(path) => self.export_diagram(&path),
                Command::PickMore(x, y) => {
                    self.selection
                        .add(&self.render.tracer, x, y, &mut self.messages);
                }
                Command::PickRect(a, b) => {
                    self.selection
                        .add_rect(&self.render.tracer, a, b, &mut self.messages);
                }
                Command::Pick(x, y) => self.selection.pick(&self.render.tracer, x, y),
                Command::FrameAll => {
                    let edit = &mut self.working.scene;
                    if let Some((lo, hi)) = edit.bounds() {
                        edit.camera = edit.camera.framing_all(lo, hi);
                    }
                    restart = true;
                }
                Command::Stop => {
                    // Esc stops an open under way too; the scene shown stays (and is watched).
                    self.files.stop(&self.working.scene, &mut self.messages);
                    self.render.stop();
                }
            }
        }
        // An accelerator change while a file opens: the open starts again with it (the
        // first one is cancelled and never installed).
        if rebuild
            && let Some(job) = self.files.job()
            && job.accel != self.working.settings.trace.accel
        {
            let (path, reload) = (job.path.clone(), job.reload);
            self.start_open(path, reload);
        }
        if restart {
            let reach = if camera_only {
                Reach::Render
            } else {
                Reach::RenderAndSceneView
            };
            self.restart(rebuild, reach);
        }
    }

    /// Makes `s` the working copy, named `label`: nothing of the old scene stays picked, the
    /// scene view frames the new one, and the history starts over.
    fn replace_scene(&mut self, s: Scene, label: String) {
        for w in &s.warnings {
            self.messages.notice(w.clone());
        }
        self.working.scene = s;
        self.working.history = undo::History::default();
        self.files.label = label;
        self.selection.clear();
        self.scene_view.unframe();
    }
}

/// Sets the viewer's sample target and whether the render follows the pane's size, and asks
/// for a render with them.
fn set_view(
    prefs: &mut Prefs,
    render: &mut RenderView,
    pending: &mut Vec<Command>,
    viewer_samples: u32,
    pane_size: bool,
) {
    prefs.viewer_samples = viewer_samples.clamp(1, scene::rules::MAX_SAMPLES);
    prefs.pane_size = pane_size;
    if !pane_size {
        render.unfollow_pane();
    }
    pending.push(Command::Restart);
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.poll_session();
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
        panels::top_bar(
            ui,
            &mut self.workspace,
            &mut self.working,
            &self.files,
            &mut self.messages,
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
        );
        // Hover is transient: the views set it again while the pointer stays on a node.
        self.selection.tree_state.hovered = None;
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
        // The panes fill the central panel edge to edge.
        let frame = egui::Frame::central_panel(ui.style()).inner_margin(0);
        egui::CentralPanel::default()
            .frame(frame)
            .show(ui, |ui| workspace::show(self, ui, pane_ui));
        if let Some(command) = self.workspace.show_browser(&ctx) {
            self.pending.push(command);
        }
        panels::help_window(&ctx, &mut self.workspace.show_help);
        let has_tree = self.selection.tree.is_some();
        panels::export_window(&ctx, &mut self.workspace, has_tree, &self.files.file_stem());
        let working = &mut self.working;
        let sweep = &mut self.workspace.sweep;
        if sweep.open
            && let Some(point) = sweep.show(&ctx, &working.scene, &working.settings.trace)
        {
            // A clicked point: its settings become the viewer's; say what changed.
            if let Some(text) = sweep.applied.clone() {
                self.messages.notice(text);
            }
            working.scene.render.max_depth = point.max_depth;
            working.scene.render.samples = point.samples;
            working.settings.trace = point.trace;
            self.pending.push(Command::Rebuild);
        }
        self.messages.show(&ctx);
        self.apply();
        self.working.track(&ctx);
        self.render.follow_display_prefs(&self.workspace.prefs);
        if !self.is_finished() || !self.scene_view.is_finished() || self.render.export_job.is_some()
        {
            ctx.request_repaint();
        } else if self.files.is_watched() {
            // Idle: wake up now and then to see whether the scene was saved.
            ctx.request_repaint_after(watch::DEBOUNCE);
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, eframe::APP_KEY, &self.workspace.prefs);
    }
}

/// What each pane of the workspace shows.
fn pane_ui(app: &mut ViewerApp, ui: &mut egui::Ui, pane: workspace::Pane) {
    use workspace::Pane;
    match pane {
        Pane::Render => input::render_pane(
            ui,
            &mut app.render,
            &mut app.selection,
            &mut app.working.scene.camera,
            &app.workspace.prefs,
            &app.scene_view.filter,
            &mut app.pending,
        ),
        Pane::SceneView => scene_pane::scene_view_ui(
            ui,
            &mut app.scene_view,
            &app.render.tracer,
            &mut app.selection,
            &mut app.working.scene,
            &app.workspace.prefs,
            &mut app.pending,
        ),
        Pane::Diagram => match app.selection.tree.clone() {
            Some(tree) => {
                if tree_view::diagram(ui, &tree, &mut app.selection.tree_state) {
                    let name = format!("tree-{}-{}.svg", tree.pixel[0], tree.pixel[1]);
                    app.workspace.browse(BrowseFor::ExportDiagram, &name);
                }
            }
            None => {
                ui.weak("click a pixel in the render view for its ray tree");
            }
        },
        Pane::TreeList => {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preferences_saved_before_layout_versions_get_the_new_layout() {
        let old: Prefs = serde_json::from_str(r#"{"exposure": 2.0}"#).expect("old prefs");
        assert_eq!(old.layout_version, 0);
        assert_eq!(old.exposure, 2.0);
        assert_eq!(old.viewer_samples, VIEWER_SAMPLES);
        assert!(old.pane_size);
        let now = Prefs::default();
        assert_eq!(now.layout_version, workspace::LAYOUT_VERSION);
        assert_eq!(old.checked().layout_version, workspace::LAYOUT_VERSION);
    }

    #[test]
    fn the_tonemap_is_saved_as_the_number_the_shader_reads() {
        let prefs: Prefs = serde_json::from_str(r#"{"tonemap": 2}"#).expect("prefs");
        assert_eq!(prefs.tonemap, viewport::Tonemap::Aces);
        let json = serde_json::to_value(&prefs).expect("serialises");
        assert_eq!(json["tonemap"], 2);
    }
}
