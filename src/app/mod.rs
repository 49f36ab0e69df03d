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

mod changes;
mod dialog;
mod film;
pub mod gesture;
mod input;
mod legend;
pub mod lesson_panel;
pub mod messages;
pub mod modes;
mod open_scene;
pub mod opening;
mod paint3d;
mod panels;
pub mod picker;
pub mod pseudocode_pane;
pub mod render_view;
mod saving;
pub mod scene_files;
pub mod scene_pane;
pub mod selection;
pub mod sweep;
pub mod tree_picks;
pub mod tree_view;
pub mod undo;
pub mod viewport;
pub mod watch;
mod window;
pub mod workspace;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::accel::Accel;
use crate::render::session::SessionEvent;
use crate::render::{Image, RenderSettings};
use crate::scene::{self, Scene};
use crate::trace::{TraceSettings, Tracer};
use messages::Messages;
pub use render_view::PANE_SIZE_DEBOUNCE;
use render_view::{Reach, RenderView};
use saving::Drawn;
use scene_files::SceneFiles;
use selection::TreeSelection;
pub use selection::{MAX_TREES, remap_pixel};
use undo::WorkingCopy;
use viewport::GpuDisplay;
pub use window::run;
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
    /// The render as shown in the pane (its size, its samples, the display's colours).
    Export(PathBuf),
    /// The render at the scene's own size and samples, rendered in the background.
    ExportFull(PathBuf),
    /// Stop the export rendering in the background.
    CancelExport,
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
    /// Open a lesson (or resume it when it is the one under way): its scene, then its first
    /// step ([`lesson_panel`]).
    OpenLesson(LessonArg),
}

/// A lesson to open: a shipped one by name, or a file.
#[derive(Clone, Debug, PartialEq)]
pub enum LessonArg {
    Shipped(String),
    File(PathBuf),
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
    /// The lesson under way and its panel.
    pub lesson: lesson_panel::LessonState,
    pending: Vec<Command>,
    /// A scene just opened whose first look is still to be framed for the render pane, once
    /// the pane's size is known ([`opening::frame_for_pane`]).
    frame_on_pane: bool,
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
        Self::with_limit(scene, label, max_side, Workspace::new(prefs))
    }

    /// The viewer's state without a window (the GPU display is installed by [`Self::new`]).
    pub fn headless(scene: Scene, label: String) -> Result<Self, String> {
        let workspace = Workspace::new(Prefs::default());
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
            lesson: Default::default(),
            pending: Vec::new(),
            frame_on_pane: true,
        };
        // A built-in scene without notes needs no word at start; a file gets its summary.
        let scene = app.render.scene();
        if scene.source.is_some() || !scene.warnings.is_empty() {
            let first = open_scene::opened_message(scene, &app.files.label, None);
            app.messages.push(first);
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
        self.render.set_view(
            &mut self.workspace.prefs,
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
        if let Some(pane) = self.render.pane(&self.workspace.prefs)
            && std::mem::take(&mut self.frame_on_pane)
        {
            opening::frame_for_pane(&mut self.working.scene, pane);
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
        if reach == Reach::RenderAndSceneView
            || self.scene_view.follows_render_camera(&tracer.scene)
        {
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

    /// Takes the tiles that arrived, within a time budget so the UI stays responsive.
    pub fn poll_session(&mut self) {
        if self.files.saved()
            && let Some(path) = self.working.scene.source.clone()
        {
            self.start_open(path, opening::OpenKind::Reload);
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

    /// A point of the speed-vs-accuracy chart applied: its settings become the viewer's, and
    /// its sample count the viewer's own target too, so the image shown refines to it.
    pub fn apply_point(&mut self, point: &crate::experiments::sweep::PointSettings) {
        let scene = &mut self.working.scene;
        scene.render.max_depth = point.max_depth;
        scene.render.samples = point.samples;
        self.working.settings.trace = point.trace;
        self.pending.push(Command::Rebuild);
        let pane_size = self.workspace.prefs.pane_size;
        self.set_view(point.samples, pane_size);
    }

    /// Keeps the edits of the moment a tree was pinned, and names what changed since.
    fn note_pin(&mut self) {
        let state = &mut self.selection.tree_state;
        if state.pinned.is_none() {
            state.pinned_edits = None;
            state.edited_since_pin.clear();
            return;
        }
        let now = self.working.edits();
        let before = state.pinned_edits.get_or_insert_with(|| now.clone());
        state.edited_since_pin = changes::between(before, &now, &self.working.scene);
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
                Command::OpenFile(path) => self.start_open(path, opening::OpenKind::Open),
                Command::OpenBuiltin(name) => match scene::builtin::load_builtin(&name) {
                    Ok(s) => {
                        // Built-in scenes are tiny: opened at once, superseding any open.
                        self.files.cancel();
                        self.replace_scene(s, name, None);
                        self.files.unwatch();
                        rebuild = true;
                        restart = true;
                    }
                    Err(e) => self.messages.error(e.to_string()),
                },
                Command::SaveScene(path) => self.save_scene(&path),
                Command::Export(path) => self.export(&path),
                Command::ExportFull(path) => self.export_at_scene_size(&path),
                Command::CancelExport => {
                    if let Some(job) = self.render.export_job() {
                        job.stop();
                    }
                }
                Command::ExportOverlay(path) => self.export_drawn(&path, Drawn::Overlay),
                Command::ExportSceneView(path) => self.export_drawn(&path, Drawn::SceneView),
                Command::ExportTree(path) => self.export_tree(&path),
                Command::ExportDiagram(path) => self.export_diagram(&path),
                Command::PickMore(x, y) => {
                    // The pixel just clicked is the one the list, detail and diagram show;
                    // the others stay drawn beside it.
                    if self
                        .selection
                        .add(&self.render.tracer, x, y, &mut self.messages)
                    {
                        self.selection.select_pixel([x, y]);
                    }
                }
                Command::PickRect(a, b) => {
                    self.selection
                        .add_rect(&self.render.tracer, a, b, &mut self.messages);
                }
                Command::Pick(x, y) => {
                    self.selection.pick(&self.render.tracer, x, y);
                    // The answer to a lesson's pixel task, when one is asked.
                    self.lesson_clicked(x, y);
                }
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
                Command::OpenLesson(arg) => self.open_lesson(arg),
            }
        }
        // An accelerator change while a file opens: the open starts again with it (the
        // first one is cancelled and never installed).
        if rebuild
            && let Some(job) = self.files.job()
            && job.accel != self.working.settings.trace.accel
        {
            let (path, kind) = (job.path.clone(), job.kind);
            self.start_open(path, kind);
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
}
