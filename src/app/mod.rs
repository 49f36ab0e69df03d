//! The desktop viewer (SPEC §5): the only module that uses egui, eframe and wgpu.
//!
//! State is split as egui apps do: [`Prefs`] is persisted UI state (serde); the session, the
//! GPU display and the tracer are runtime resources. Panels edit a working copy of the scene
//! and the settings and return [`Command`]s; [`ViewerApp::apply`] carries them out once, at the
//! end of the frame, where any edit restarts the progressive render with a new generation.

mod dialog;
mod film;
pub mod gesture;
mod input;
mod legend;
pub mod modes;
pub mod opening;
mod paint3d;
mod panels;
pub mod scene_pane;
pub mod sweep;
pub mod tree_view;
pub mod undo;
pub mod viewport;
pub mod watch;
pub mod workspace;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use eframe::egui;
use egui_notify::ToastLevel;
use serde::{Deserialize, Serialize};

use crate::accel::Accel;
use crate::export;
use crate::ray_tree::{RayTree, pixel_tree};
use crate::render::session::{Pass, Session, SessionEvent};
use crate::render::{Image, RenderSettings};
use crate::scene::{self, Scene};
use crate::trace::{TraceSettings, Tracer};
use dialog::{BrowseFor, FileBrowser};
use film::Film;
use modes::ImageMode;
use viewport::{DisplayState, GpuDisplay, SharedDisplay};

/// UI state kept between runs.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default)]
pub struct Prefs {
    pub exposure: f32,
    /// 0: clamp, 1: Reinhard, 2: ACES.
    pub tonemap: u32,
    pub mode: ImageMode,
    pub last_dir: Option<PathBuf>,
    /// The panes' arrangement (replaced by the default when unusable).
    pub layout: workspace::Layout,
    /// Degrees the camera orbits for a drag across the whole image width.
    pub orbit_degrees: f32,
    /// The version of the default layout `layout` grew from: an older one is replaced (the
    /// preferences of a run before versions were kept read as 0).
    #[serde(default)]
    pub layout_version: u32,
    /// Samples per pixel the viewer refines to before it idles (the scene's `samples` is the
    /// batch render's, for export and the command line).
    pub viewer_samples: u32,
    /// Render at the render pane's pixel size (the scene's width and height are kept for
    /// export and saving); off: render at the scene's size.
    pub pane_size: bool,
    /// Whether the settings panel on the left is shown (F9).
    pub settings_panel: bool,
}

/// The viewer's default sample target.
pub const VIEWER_SAMPLES: u32 = 64;

/// The narrowest window (points) whose first run shows the settings panel: below it the render
/// would get less than half the window, so the panel starts hidden (Ctrl+B shows it).
pub const SETTINGS_MIN_WIDTH: f32 = 1300.0;

/// How long the render pane's size must hold before the render follows it.
pub const PANE_SIZE_DEBOUNCE: Duration = Duration::from_millis(250);

impl Default for Prefs {
    fn default() -> Self {
        Self {
            exposure: 1.0,
            tonemap: 0,
            mode: ImageMode::Render,
            last_dir: None,
            layout: workspace::default_layout(),
            orbit_degrees: 180.0,
            layout_version: workspace::LAYOUT_VERSION,
            viewer_samples: VIEWER_SAMPLES,
            pane_size: true,
            settings_panel: true,
        }
    }
}

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

/// Progress of the current generation, as the UI saw it.
#[derive(Clone, Debug, Default)]
struct Progress {
    started: Option<Instant>,
    /// Samples per pixel of the last complete pass (0: only the preview, or nothing yet).
    samples_done: u32,
    preview_done: bool,
    finished_secs: Option<f64>,
    /// What the status bar says of the pass under way: "preview", "4 samples", "stopped".
    pass_label: String,
    /// The largest build percentage shown, so it never goes back.
    build_percent: f64,
}

/// The viewer.
pub struct ViewerApp {
    pub prefs: Prefs,
    /// The scene being rendered and its working copy in the panels.
    scene: Arc<Scene>,
    pub edit: Scene,
    pub settings: RenderSettings,
    scene_label: String,
    tracer: Arc<Tracer>,
    session: Session,
    /// The open scene's files, watched for saves (`None` for built-in scenes).
    watch: Option<watch::SceneWatch>,
    /// A file being opened (or reloaded) in the background; the scene shown stays until it
    /// is ready.
    opening: Option<opening::OpenJob>,
    /// Called by background opens at each stage (the tests hold an open with it).
    open_hook: Option<Arc<opening::OpenHook>>,
    /// Rates of the stages of the last open, for the next one's progress estimate.
    rates: opening::Rates,
    /// Times of the last open, for the record (benchmarks print them).
    pub last_open: Option<opening::Timings>,
    /// A build asked of the session and not yet installed (`Some(restart the scene view)`);
    /// while it is, the current tracer's accelerator does not fit the working copy, so every
    /// restart builds (a stop in the middle of a build drops it).
    pending_build: Option<bool>,
    generation: u64,
    progress: Progress,
    /// The film as the latest tiles left it: linear colour and sample-0 facts per pixel.
    film: Film,
    display: SharedDisplay,
    /// Errors (true) and notices, newest last: the log the toasts are made from.
    pub messages: Vec<(bool, String)>,
    /// The toasts over the window (they never move the layout), and how many of `messages`
    /// they have shown.
    toasts: egui_notify::Toasts,
    toasted: usize,
    /// The render pane's size in pixels as last seen, and since when it has held.
    pane_seen: Option<((u32, u32), Instant)>,
    /// The size the render follows (`None`: the scene's), set once [`Self::pane_seen`] held.
    pane_px: Option<(u32, u32)>,
    /// The scene's own width and height (the working copy's, kept when an edit is refused).
    scene_size: (u32, u32),
    /// Whether the settings panel's visibility is settled: by the saved preferences, or on
    /// the first frame by the window's width (shown from [`SETTINGS_MIN_WIDTH`] up).
    settings_settled: bool,
    /// An export rendering at the scene's size in the background: its message when done.
    export_job: Option<std::sync::mpsc::Receiver<(bool, String)>>,
    pub selected_material: Option<usize>,
    pub selected_light: Option<usize>,
    pub tree: Option<RayTree>,
    /// More pixels' trees, drawn beside the current one (shift-click, a dragged rectangle);
    /// at most [`MAX_TREES`] with the current one.
    pub extra_trees: Vec<RayTree>,
    /// The scene view: its camera, its own render and its filters.
    pub scene_view: scene_pane::SceneView,
    /// Whether the tree's panes were last opened (true) or closed for want of a tree.
    tree_panes_shown: Option<bool>,
    /// The rectangle being dragged over the render with Ctrl or Alt (screen points).
    rect_select: Option<(egui::Pos2, egui::Pos2)>,
    /// Selection, hover and the pinned tree, shared by the tree's views.
    pub tree_state: tree_view::TreeState,
    hover: Option<(u32, u32)>,
    browser: Option<FileBrowser>,
    show_help: bool,
    /// The Ctrl+S window: which picture to export.
    export_choice: bool,
    /// The "Speed vs accuracy" window and its background sweep.
    pub sweep: sweep::SweepWindow,
    /// The largest texture side the GPU allows: the render is never larger on screen.
    max_side: u32,
    last_mode: ImageMode,
    pending: Vec<Command>,
    /// Undo and redo of the edits ([`undo`]).
    pub history: undo::History,
}

/// Pixel `p` of a `from`-sized image as the pixel at the same place of a `to`-sized one.
pub fn remap_pixel(p: [u32; 2], from: (u32, u32), to: (u32, u32)) -> [u32; 2] {
    let axis = |v: u32, a: u32, b: u32| {
        (((v as f64 + 0.5) * b as f64 / a.max(1) as f64) as u32).min(b.saturating_sub(1))
    };
    [axis(p[0], from.0, to.0), axis(p[1], from.1, to.1)]
}

/// The most trees shown at once (the current one and the extra ones).
pub const MAX_TREES: usize = 64;

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
        let mut prefs = cc
            .storage
            .and_then(|s| eframe::get_value::<Prefs>(s, eframe::APP_KEY))
            .unwrap_or_default();
        if prefs.layout_version != workspace::LAYOUT_VERSION {
            prefs.layout = workspace::default_layout();
            prefs.layout_version = workspace::LAYOUT_VERSION;
        }
        prefs.viewer_samples = prefs.viewer_samples.clamp(1, scene::rules::MAX_SAMPLES);
        let saved = cc
            .storage
            .is_some_and(|s| s.get_string(eframe::APP_KEY).is_some());
        let mut app = Self::with_limit(scene, label, max_side, prefs)?;
        app.settings_settled = saved;
        Ok(app)
    }

    /// The viewer's state without a window (the GPU display is installed by [`Self::new`]).
    pub fn headless(scene: Scene, label: String) -> Result<Self, String> {
        Self::with_limit(scene, label, scene::rules::MAX_IMAGE_SIZE, Prefs::default())
    }

    fn with_limit(
        scene: Scene,
        label: String,
        max_side: u32,
        prefs: Prefs,
    ) -> Result<Self, String> {
        let settings = RenderSettings::default();
        let session = Session::new(settings.threads)?;
        let scene_view = scene_pane::SceneView::new(settings.threads)?;
        let scene = Arc::new(scene);
        let tracer = Arc::new(Tracer::new(scene.clone(), settings.trace));
        let (w, h) = (scene.render.width, scene.render.height);
        let mut app = Self {
            prefs,
            edit: (*scene).clone(),
            scene,
            settings,
            scene_label: label,
            tracer,
            session,
            pending_build: None,
            watch: None,
            opening: None,
            open_hook: None,
            rates: opening::Rates::default(),
            last_open: None,
            generation: 0,
            progress: Progress::default(),
            film: Film::new(w, h),
            display: Arc::new(Mutex::new(DisplayState::new(w, h))),
            messages: Vec::new(),
            toasts: new_toasts(),
            toasted: 0,
            pane_seen: None,
            pane_px: None,
            scene_size: (w, h),
            export_job: None,
            settings_settled: false,
            selected_material: None,
            selected_light: None,
            tree: None,
            extra_trees: Vec::new(),
            scene_view,
            tree_panes_shown: None,
            rect_select: None,
            tree_state: tree_view::TreeState::default(),
            hover: None,
            browser: None,
            show_help: false,
            export_choice: false,
            sweep: sweep::SweepWindow::default(),
            max_side: max_side.max(1),
            last_mode: ImageMode::Render,
            pending: Vec::new(),
            history: undo::History::default(),
        };
        for w in app.scene.warnings.clone() {
            app.messages.push((false, w));
        }
        app.watch_scene();
        app.restart(false);
        Ok(app)
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Samples per pixel in every pixel of the current generation (0 before the first full pass).
    pub fn samples_done(&self) -> u32 {
        self.progress.samples_done
    }

    /// Whether the current render reached its target and no file is being opened.
    pub fn is_finished(&self) -> bool {
        self.progress.finished_secs.is_some() && self.opening.is_none()
    }

    /// Samples per pixel the viewer refines to (then it idles).
    pub fn viewer_target(&self) -> u32 {
        self.prefs.viewer_samples.max(1)
    }

    /// Sets the viewer's sample target and whether the render follows the pane's size, and
    /// renders again with them.
    pub fn set_view(&mut self, viewer_samples: u32, pane_size: bool) {
        self.prefs.viewer_samples = viewer_samples.clamp(1, scene::rules::MAX_SAMPLES);
        self.prefs.pane_size = pane_size;
        if !pane_size {
            self.pane_px = None;
        }
        self.pending.push(Command::Restart);
    }

    /// Shows or hides the settings panel (whatever the window's width).
    pub fn set_settings_panel(&mut self, shown: bool) {
        self.prefs.settings_panel = shown;
        self.settings_settled = true;
    }

    /// Rays traced by the current generation so far.
    pub fn rays_traced(&self) -> u64 {
        self.session.stats().counts().total()
    }

    /// The render pane's size in pixels as last drawn (`None`: not drawn yet, or the render
    /// does not follow it).
    pub fn pane_pixels(&self) -> Option<(u32, u32)> {
        self.pane_seen
            .map(|(px, _)| px)
            .filter(|_| self.prefs.pane_size)
    }

    /// The size the viewer renders at: the render pane's pixels (when it follows the pane and
    /// the pane has been seen) or the scene's width and height.
    pub fn render_size(&self) -> (u32, u32) {
        (self.scene.render.width, self.scene.render.height)
    }

    /// The film as it stands: the mean of the samples done so far.
    pub fn image(&self) -> Image {
        self.film.image()
    }

    /// Queues a command, as a panel would.
    pub fn command(&mut self, c: Command) {
        self.pending.push(c);
    }

    fn error(&mut self, message: impl Into<String>) {
        self.messages.push((true, message.into()));
    }

    /// Starts a new generation from the working copy; `rebuild` also rebuilds the accelerator.
    fn restart(&mut self, rebuild: bool) {
        self.restart_views(rebuild, true);
    }

    /// [`Self::restart`], restarting the scene view's render too when `scene_view`.
    fn restart_views(&mut self, rebuild: bool, scene_view: bool) {
        if let Err(e) = self.session.set_threads(self.settings.threads) {
            self.error(e);
        }
        // An edit is held to the loader's rules; a bad one is refused and the scene stays.
        if let Err(e) = scene::rules::check_scene(&self.edit, rebuild) {
            self.error(format!("{e}; the edit was undone"));
            // The scene rendered may be at the pane's size: the scene's own size comes back.
            self.edit = (*self.scene).clone();
            (self.edit.render.width, self.edit.render.height) = self.scene_size;
            if self.generation > 0 {
                return;
            }
        }
        self.scene_size = (self.edit.render.width, self.edit.render.height);
        // Headlights stand at the camera's eye, wherever it went (the one rule for it).
        self.edit.place_lights();
        // The viewer's buffers must fit the GPU's largest texture and the memory budget: a
        // larger render is shown scaled down (with a message); `raytree render` does full size.
        let pane = self.pane_px.filter(|_| self.prefs.pane_size);
        let fit = opening::fit_render(self.scene_size, pane, self.max_side);
        if let Some(message) = fit.message {
            self.error(message);
        }
        (self.edit.render.width, self.edit.render.height) = fit.scene;
        self.scene_size = fit.scene;
        let mut render_scene = self.edit.clone();
        (render_scene.render.width, render_scene.render.height) = fit.render;
        let scene = Arc::new(render_scene);
        let target = self.viewer_target();
        let focus = self.hover.map(|(x, y)| (x as f32, y as f32));
        if rebuild
            || self.pending_build.is_some()
            || self.tracer.settings.accel != self.settings.trace.accel
        {
            // Built on the session's coordinator thread: the previous image stays up, with
            // "building BVH…", until the new tracer is handed out by `poll_session`.
            self.generation = self
                .session
                .start_build(scene, self.settings.trace, target, focus);
            self.progress = Progress {
                started: Some(Instant::now()),
                pass_label: "building BVH…".into(),
                ..Progress::default()
            };
            self.pending_build = Some(self.pending_build.unwrap_or(false) || scene_view);
            return;
        }
        let tracer = Arc::new(Tracer::with_accel(
            scene,
            self.settings.trace,
            self.tracer.accel.clone(),
        ));
        self.generation = self.session.start(tracer.clone(), target, focus);
        self.progress = Progress {
            started: Some(Instant::now()),
            pass_label: "preview".into(),
            ..Progress::default()
        };
        self.install_tracer(tracer, scene_view);
    }

    /// Makes the tracer of the generation just started (`start`ed, or built and handed out)
    /// the current one: film and display at its size, trees re-traced, scene view restarted.
    fn install_tracer(&mut self, tracer: Arc<Tracer>, scene_view: bool) {
        self.tracer = tracer;
        let scene = self.tracer.scene.clone();
        let (w, h) = (scene.render.width, scene.render.height);
        // Pixels picked at another render size keep their place in the image.
        let old = (self.scene.render.width, self.scene.render.height);
        if old != (w, h) {
            let map = |[x, y]: [u32; 2]| remap_pixel([x, y], old, (w, h));
            for t in self.tree.iter_mut().chain(self.extra_trees.iter_mut()) {
                t.pixel = map(t.pixel);
            }
            self.hover = None;
        }
        self.film.resize(w, h);
        self.scene = scene;
        crate::sync::lock(&self.display).resize(w, h);
        // The tree follows the scene: re-trace the clicked pixel with the new settings.
        if let Some(tree) = &self.tree {
            let [x, y] = tree.pixel;
            self.tree = pixel_tree(&self.tracer, x, y);
        }
        let tracer = self.tracer.clone();
        self.extra_trees = self
            .extra_trees
            .iter()
            .filter_map(|t| pixel_tree(&tracer, t.pixel[0], t.pixel[1]))
            .collect();
        if scene_view {
            if let Err(e) = self.scene_view.set_threads(self.settings.threads) {
                self.error(e);
            }
            self.scene_view.restart(&tracer);
        }
    }

    /// The trees shown: the current one first, then the extra ones.
    pub fn trees(&self) -> impl Iterator<Item = &RayTree> {
        self.tree.iter().chain(self.extra_trees.iter())
    }

    /// Makes extra tree `i` the current one (the list and detail show it); the current one
    /// joins the extra trees in its place.
    pub fn make_current(&mut self, i: usize) {
        if i < self.extra_trees.len() {
            match self.tree.take() {
                Some(current) => {
                    self.tree = Some(std::mem::replace(&mut self.extra_trees[i], current))
                }
                None => self.tree = Some(self.extra_trees.remove(i)),
            }
        }
    }

    /// Adds the tree of pixel (`x`, `y`) to the trees shown, unless it is there or the trees
    /// are full (then says so). Returns false when full.
    fn add_tree(&mut self, x: u32, y: u32) -> bool {
        if self.trees().any(|t| t.pixel == [x, y]) {
            return true;
        }
        if self.trees().count() >= MAX_TREES {
            self.messages.push((
                false,
                format!("at most {MAX_TREES} trees are shown: click a pixel (without shift) to start over"),
            ));
            return false;
        }
        let Some(tree) = pixel_tree(&self.tracer, x, y) else {
            return true;
        };
        match self.tree {
            None => {
                self.tree = Some(tree);
                self.tree_state.selected = Some(Vec::new());
            }
            Some(_) => self.extra_trees.push(tree),
        }
        true
    }

    /// Watches the open scene's files (see [`watch`]), or nothing for a built-in scene.
    fn watch_scene(&mut self) {
        self.watch = None;
        let Some(source) = self.edit.source.clone() else {
            return;
        };
        match watch::SceneWatch::new(&watch::scene_files(&self.edit, &source)) {
            Ok(w) => self.watch = Some(w),
            Err(e) => self.messages.push((false, e)),
        }
    }

    /// True while a saved change waits for its reload (the UI keeps polling).
    pub fn reload_pending(&self) -> bool {
        self.watch.as_ref().is_some_and(watch::SceneWatch::pending)
    }

    /// Reloads the open scene after a save, in the background like an open. Same geometry:
    /// the camera (as moved in the viewer) and the clicked trees stay, and the accelerator is
    /// kept. A broken save: its error, and the last good scene stays.
    fn reload(&mut self) {
        if let Some(path) = self.edit.source.clone() {
            self.start_open(path, true);
        }
    }

    /// Opens `path` (or reloads it after a save, `reload`) in the background: read, parse and
    /// build off the UI thread, the scene shown staying up until the new one is ready. Cancels
    /// an open already under way (its result is never installed).
    fn start_open(&mut self, path: PathBuf, reload: bool) {
        self.cancel_open();
        if !reload {
            // The old scene's saves must not reload it over the file being opened.
            self.watch = None;
        }
        let request = opening::Request {
            path,
            settings: self.settings.trace,
            pane: self.pane_px.filter(|_| self.prefs.pane_size),
            max_side: self.max_side,
            reload: reload.then(|| (self.tracer.clone(), self.edit.camera.clone())),
            hook: self.open_hook.clone(),
        };
        match opening::OpenJob::start(request) {
            Ok(job) => self.opening = Some(job),
            Err(e) => {
                self.error(e);
                self.watch_scene();
            }
        }
    }

    /// Cancels the open under way, if any.
    fn cancel_open(&mut self) {
        if let Some(job) = self.opening.take() {
            job.cancel();
        }
    }

    /// Sets (or with `None` removes) the hook every background open calls at each stage, on
    /// its thread; takes effect at the next open.
    pub fn set_open_hook(&mut self, hook: Option<Arc<opening::OpenHook>>) {
        self.open_hook = hook;
    }

    /// The file being opened in the background, if any.
    pub fn opening(&self) -> Option<&Path> {
        self.opening.as_ref().map(|j| j.path.as_path())
    }

    /// What the status bar says of the open under way, and its percentage (below 100 until
    /// the new scene is installed): "loading FILE… n %", then "building BVH… n %".
    pub fn open_status(&mut self) -> Option<(String, f32)> {
        let rates = self.rates;
        let job = self.opening.as_mut()?;
        let percent = job.percent(&rates);
        let name = job
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let label = match job.stage() {
            opening::OpenStage::Read | opening::OpenStage::Parse => {
                format!("loading {name}… {percent:.0} %")
            }
            opening::OpenStage::Build | opening::OpenStage::Ready => {
                format!("building BVH… {percent:.0} %")
            }
        };
        Some((label, percent))
    }

    /// Takes the result of the background open, when it is ready.
    fn poll_open(&mut self) {
        let Some(outcome) = self.opening.as_ref().and_then(opening::OpenJob::try_take) else {
            return;
        };
        let Some(job) = self.opening.take() else {
            return;
        };
        let path = job.path.clone();
        match outcome {
            opening::Outcome::Opened(opened) => self.install_opened(&path, job.reload, *opened),
            // The message names the file, place and field; the old scene stays.
            opening::Outcome::Failed(e) if job.reload => self.error(format!(
                "{e} (after a save; the last good scene stays until the file loads again)"
            )),
            opening::Outcome::Failed(e) => {
                self.error(e);
                // The scene shown is watched again.
                self.watch_scene();
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
        if same_geometry {
            for w in &edit.warnings {
                self.messages.push((false, w.clone()));
            }
            // The camera as it is now (it may have moved while the file was read), the
            // accelerator shown kept: rendered as any edit is.
            let camera = self.edit.camera.clone();
            self.edit = edit;
            self.edit.camera = camera;
            self.messages
                .push((false, format!("reloaded {} after a save", path.display())));
            self.rates.learn(&timings);
            self.last_open = Some(timings);
            self.watch_scene();
            self.restart(false);
            return;
        } else {
            self.replace_scene(edit, path.display().to_string());
        }
        if reload {
            self.messages
                .push((false, format!("reloaded {} after a save", path.display())));
        }
        if let Some(message) = fit.message {
            self.error(message);
        }
        self.scene_size = fit.scene;
        self.rates.learn(&timings);
        self.last_open = Some(timings);
        self.watch_scene();
        self.pending_build = None;
        let target = self.viewer_target();
        let focus = self.hover.map(|(x, y)| (x as f32, y as f32));
        self.generation = self.session.start(tracer.clone(), target, focus);
        self.progress = Progress {
            started: Some(Instant::now()),
            pass_label: "preview".into(),
            ..Progress::default()
        };
        self.install_tracer(tracer, true);
    }

    /// Takes the tiles that arrived, within a time budget so the UI stays responsive.
    pub fn poll_session(&mut self) {
        if self.watch.as_mut().is_some_and(watch::SceneWatch::poll) {
            self.reload();
        }
        self.poll_open();
        // A tracer built off the UI thread comes before its generation's first tile.
        if let Some(tracer) = self.session.take_built() {
            let scene_view = self.pending_build.take().unwrap_or(true);
            self.install_tracer(tracer, scene_view);
            self.progress.pass_label = "preview".into();
        } else if let Some(t) = self.session.building_for() {
            // obvhs reports no progress: the time so far against the estimate at this run's
            // measured rate, held below 100 % until the build is handed over.
            let estimate = self.rates.build_secs(self.edit.triangles.len() as u64);
            let percent = (100.0 * t.as_secs_f64() / estimate.max(1e-3)).min(99.0);
            let percent = self.progress.build_percent.max(percent);
            self.progress.build_percent = percent;
            self.progress.pass_label = format!("building BVH… {percent:.0} %");
        }
        self.scene_view.poll();
        let budget = Instant::now();
        let shared = self.display.clone();
        let mut display = crate::sync::lock(&shared);
        let mode = self.prefs.mode;
        while let Some(event) =
            self.session
                .next_within(self.generation, budget, Duration::from_millis(8))
        {
            match event {
                SessionEvent::Tile(tile) => {
                    // The build finished after `take_built` above was asked: its tracer (and
                    // the film at its size) comes before its first tile.
                    if self.pending_build.is_some() {
                        drop(display);
                        if let Some(tracer) = self.session.take_built() {
                            let scene_view = self.pending_build.take().unwrap_or(true);
                            self.install_tracer(tracer, scene_view);
                            self.progress.pass_label = "preview".into();
                        }
                        display = crate::sync::lock(&shared);
                    }
                    if self.film.holds(tile.rect) {
                        let max_depth = self.scene.render.max_depth;
                        self.film.write_tile(&tile, mode, max_depth, &mut display);
                    }
                }
                SessionEvent::PassDone { pass, .. } => match pass {
                    Pass::Preview => {
                        self.progress.preview_done = true;
                        self.progress.pass_label = "1 sample".into();
                    }
                    Pass::Samples(n) => {
                        self.progress.samples_done = n;
                        self.progress.pass_label = format!("{n} samples");
                    }
                },
                SessionEvent::Finished { secs, .. } => {
                    self.progress.finished_secs = Some(secs);
                }
                SessionEvent::Failed { message, .. } => {
                    drop(display);
                    self.progress.pass_label = "stopped".into();
                    self.error(format!("{message}; the render stopped"));
                    return;
                }
            }
        }
    }

    /// Rewrites the whole display buffer for the current image mode.
    fn refresh_display(&mut self) {
        let mut display = crate::sync::lock(&self.display);
        let mode = self.prefs.mode;
        self.film
            .paint(mode, self.scene.render.max_depth, &mut display);
        display.params.exposure = self.prefs.exposure;
        display.params.tonemap = self.prefs.tonemap;
        display.params.raw = mode != ImageMode::Render;
        display.mark_all();
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
                Command::Restart => restart = true,
                Command::MoveCamera => restart = true,
                Command::Rebuild => {
                    restart = true;
                    rebuild = true;
                }
                // Read, parsed and built in the background ([`opening`]).
                Command::OpenFile(path) => self.start_open(path, false),
                Command::OpenBuiltin(name) => match scene::builtin::load_builtin(&name) {
                    Ok(s) => {
                        // Built-in scenes are tiny: opened at once, superseding any open.
                        self.cancel_open();
                        self.replace_scene(s, name);
                        self.watch = None;
                        rebuild = true;
                        restart = true;
                    }
                    Err(e) => self.error(e.to_string()),
                },
                Command::SaveScene(path) => {
                    let text = scene::scene_to_toml(&self.edit);
                    match export::write_text(&path, &text) {
                        Ok(()) => self
                            .messages
                            .push((false, format!("saved {}", path.display()))),
                        Err(e) => self.error(e.to_string()),
                    }
                }
                Command::Export(path) => self.export(&path),
                Command::ExportOverlay(path) => self.export_drawn(&path, false),
                Command::ExportSceneView(path) => self.export_drawn(&path, true),
                Command::ExportTree(path) => {
                    let json = self
                        .tree
                        .as_ref()
                        .map(|t| serde_json::to_string_pretty(t).unwrap_or_default());
                    self.save_tree_text(&path, json);
                }
                Command::ExportDiagram(path) => {
                    let options = crate::diagram::Options {
                        max_generation: self.tree_state.reveal.unwrap_or(u32::MAX),
                    };
                    let svg = self.tree.as_ref().map(|t| crate::diagram::svg(t, &options));
                    self.save_tree_text(&path, svg);
                }
                Command::PickMore(x, y) => {
                    self.add_tree(x, y);
                }
                Command::PickRect([x0, y0], [x1, y1]) => {
                    // A sparse grid: at most 8 × 8 pixels spread over the rectangle.
                    let axis = |a: u32, b: u32| -> Vec<u32> {
                        let n = (b - a + 1).min(8);
                        let mut v: Vec<u32> = (0..n)
                            .map(|i| {
                                a + ((b - a) as u64 * (2 * i as u64 + 1) / (2 * n as u64)) as u32
                            })
                            .collect();
                        v.dedup();
                        v
                    };
                    'grid: for y in axis(y0.min(y1), y0.max(y1)) {
                        for x in axis(x0.min(x1), x0.max(x1)) {
                            if !self.add_tree(x, y) {
                                break 'grid;
                            }
                        }
                    }
                }
                Command::Pick(x, y) => {
                    self.extra_trees.clear();
                    self.tree = pixel_tree(&self.tracer, x, y);
                    self.tree_state.selected = Some(Vec::new());
                    if let Some(hit) = self.tree.as_ref().and_then(|t| t.root.hit.as_ref()) {
                        self.selected_material = self
                            .scene
                            .materials
                            .iter()
                            .position(|m| m.name == hit.material);
                    }
                }
                Command::FrameAll => {
                    if let Some((lo, hi)) = self.edit.bounds() {
                        self.edit.camera = self.edit.camera.framing_all(lo, hi);
                    }
                    restart = true;
                }
                Command::Stop => {
                    // Esc stops an open under way too; the scene shown stays (and is watched).
                    if let Some(job) = self.opening.take() {
                        job.cancel();
                        self.messages
                            .push((false, format!("stopped opening {}", job.path.display())));
                        self.watch_scene();
                    }
                    self.session.stop();
                    self.generation = self.session.generation();
                }
            }
        }
        // An accelerator change while a file opens: the open starts again with it (the
        // first one is cancelled and never installed).
        if rebuild
            && let Some(job) = &self.opening
            && job.accel != self.settings.trace.accel
        {
            let (path, reload) = (job.path.clone(), job.reload);
            self.start_open(path, reload);
        }
        if restart {
            self.restart_views(rebuild, !camera_only);
        }
    }

    fn replace_scene(&mut self, s: Scene, label: String) {
        for w in &s.warnings {
            self.messages.push((false, w.clone()));
        }
        self.edit = s;
        self.scene_label = label;
        self.selected_material = None;
        self.selected_light = None;
        self.tree = None;
        // Pins and extra trees belong to the old scene; the scene view frames the new one.
        self.extra_trees.clear();
        self.tree_state = tree_view::TreeState::default();
        self.scene_view.unframe();
        self.history = undo::History::default();
    }

    /// Writes the film at full resolution (never a window grab), stamped with its progress.
    /// Writes the ray tree in some form (`None`: there is no tree yet).
    fn save_tree_text(&mut self, path: &Path, text: Option<String>) {
        match text.map(|text| export::write_text(path, &text)) {
            Some(Ok(())) => self
                .messages
                .push((false, format!("saved {}", path.display()))),
            Some(Err(e)) => self.error(e.to_string()),
            None => self.error("no ray tree to export: click a pixel first"),
        }
    }

    fn export(&mut self, path: &Path) {
        if self.render_size() != self.scene_size {
            return self.export_at_scene_size(path);
        }
        let target = self.viewer_target();
        let text = export::stamp(
            &self.scene_label,
            self.progress.samples_done,
            target,
            &self.scene.render,
            &self.settings.trace,
            self.tracer.accel.kind(),
        );
        match export::write_image(path, &self.image(), &text) {
            Ok(()) => self.messages.push((
                false,
                format!(
                    "exported {} ({}/{} samples)",
                    path.display(),
                    self.progress.samples_done,
                    target
                ),
            )),
            Err(e) => self.error(e.to_string()),
        }
    }

    /// The render follows the pane: the export renders the scene at its own size and sample
    /// count in the background (the viewer stays live) and says when the file is written.
    fn export_at_scene_size(&mut self, path: &Path) {
        if self.export_job.is_some() {
            return self.error("an export is still rendering: wait for its message");
        }
        let mut scene = (*self.scene).clone();
        (scene.render.width, scene.render.height) = self.scene_size;
        let (w, h) = self.scene_size;
        let samples = scene.render.samples;
        let stamp = export::stamp(
            &self.scene_label,
            samples,
            samples,
            &scene.render,
            &self.settings.trace,
            self.tracer.accel.kind(),
        );
        let tracer = Tracer::with_accel(
            Arc::new(scene),
            self.settings.trace,
            self.tracer.accel.clone(),
        );
        let threads = self.settings.threads;
        let shown = path.display().to_string();
        let path = path.to_path_buf();
        let (tx, rx) = std::sync::mpsc::channel();
        let job = move || {
            let message = match crate::render::render(&tracer, samples, threads, &|_, _| {}) {
                Ok((image, _)) => match export::write_image(&path, &image, &stamp) {
                    Ok(()) => (
                        false,
                        format!(
                            "exported {} ({w}x{h}, the scene's size, {samples} samples)",
                            path.display()
                        ),
                    ),
                    Err(e) => (true, e.to_string()),
                },
                Err(e) => (true, format!("cannot export {}: {e}", path.display())),
            };
            // The viewer may have closed meanwhile: then nobody waits for the message.
            let _ = tx.send(message);
        };
        match std::thread::Builder::new()
            .name("raytree-export".into())
            .spawn(job)
        {
            Ok(_) => {
                self.export_job = Some(rx);
                self.messages.push((
                    false,
                    format!(
                        "exporting {shown} at the scene's size ({w}x{h}, {samples} samples)..."
                    ),
                ));
            }
            Err(e) => self.error(format!("cannot start the export: {e}")),
        }
    }

    /// Writes the render with the trees drawn over it (`scene_view`: false) or the scene view
    /// at the scene's size (true) as a stamped PNG, drawn by the headless scene view's rules.
    fn export_drawn(&mut self, path: &Path, scene_view: bool) {
        let Some(tree) = self.tree.clone() else {
            self.error("no ray tree to draw: click a pixel first");
            return;
        };
        let filter = crate::scene_view::Filter {
            max_generation: self.tree_state.reveal.unwrap_or(u32::MAX),
            ..self.scene_view.filter.clone()
        };
        let drawn = if scene_view {
            let (w, h) = self.scene_size;
            let camera = self.scene_view.camera.clone();
            crate::scene_view::headless::scene_view_image(
                &self.scene,
                self.settings.trace,
                &tree,
                &camera,
                w,
                h,
                &filter,
            )
        } else {
            let trees: Vec<&RayTree> = self.trees().collect();
            crate::scene_view::headless::overlay_image(&self.tracer, &self.image(), &trees, &filter)
        };
        let canvas = match drawn {
            Ok(c) => c,
            Err(e) => return self.error(e.to_string()),
        };
        let text = export::stamp(
            &self.scene_label,
            self.progress.samples_done,
            self.scene.render.samples,
            &self.scene.render,
            &self.settings.trace,
            self.tracer.accel.kind(),
        );
        let (w, h) = (canvas.width(), canvas.height());
        match export::write_png_rgba8(path, w, h, canvas.rgba(), &text) {
            Ok(()) => self
                .messages
                .push((false, format!("exported {}", path.display()))),
            Err(e) => self.error(e.to_string()),
        }
    }

    fn file_stem(&self) -> String {
        Path::new(&self.scene_label)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("render")
            .to_string()
    }

    fn start_dir(&self) -> PathBuf {
        self.prefs
            .last_dir
            .clone()
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("."))
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.poll_session();
        self.poll_export();
        self.shortcuts(&ctx);
        if ctx.input_mut(|i| {
            i.consume_shortcut(&egui::KeyboardShortcut::new(
                egui::Modifiers::COMMAND,
                egui::Key::B,
            ))
        }) {
            self.toggle_settings_panel();
        }
        panels::top_bar(self, ui);
        panels::status_bar(self, ui);
        // Hover is transient: the views set it again while the pointer stays on a node.
        self.tree_state.hovered = None;
        scene_pane::advance_playback(self, &ctx);
        if !self.settings_settled {
            self.settings_settled = true;
            if ctx.content_rect().width() < SETTINGS_MIN_WIDTH {
                self.toggle_settings_panel();
            }
        }
        if !self.prefs.settings_panel {
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
                        self.toggle_settings_panel();
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
                            self.toggle_settings_panel();
                        }
                    });
                    // Scrolled both ways: wide content (an opened material) scrolls instead of
                    // widening the panel, which would move and resize the render.
                    egui::ScrollArea::both().show(ui, |ui| panels::side_panel(self, ui));
                });
        }
        // The panes fill the central panel edge to edge.
        let frame = egui::Frame::central_panel(ui.style()).inner_margin(0);
        egui::CentralPanel::default()
            .frame(frame)
            .show(ui, |ui| workspace::show(self, ui, pane_ui));
        if let Some(browser) = &mut self.browser {
            match browser.show(&ctx) {
                dialog::Outcome::Open => {}
                dialog::Outcome::Cancel => self.browser = None,
                dialog::Outcome::Chose(purpose, path) => {
                    self.prefs.last_dir = path.parent().map(Path::to_path_buf);
                    self.pending.push(match purpose {
                        BrowseFor::Open => Command::OpenFile(path),
                        BrowseFor::SaveScene => Command::SaveScene(path),
                        BrowseFor::Export => Command::Export(path),
                        BrowseFor::ExportOverlay => Command::ExportOverlay(path),
                        BrowseFor::ExportSceneView => Command::ExportSceneView(path),
                        BrowseFor::ExportTree => Command::ExportTree(path),
                        BrowseFor::ExportDiagram => Command::ExportDiagram(path),
                    });
                    self.browser = None;
                }
            }
        }
        panels::help_window(&ctx, &mut self.show_help);
        panels::export_window(self, &ctx);
        if self.sweep.open
            && let Some(point) = self.sweep.show(&ctx, &self.edit, &self.settings.trace)
        {
            // A clicked point: its settings become the viewer's; say what changed.
            if let Some(text) = self.sweep.applied.clone() {
                self.messages.push((false, text));
            }
            self.edit.render.max_depth = point.max_depth;
            self.edit.render.samples = point.samples;
            self.settings.trace = point.trace;
            self.pending.push(Command::Rebuild);
        }
        self.show_toasts(&ctx);
        self.apply();
        self.track_edits(&ctx);
        self.refresh_if_mode_changed();
        if !self.is_finished() || !self.scene_view.is_finished() || self.export_job.is_some() {
            ctx.request_repaint();
        } else if self.watch.is_some() {
            // Idle: wake up now and then to see whether the scene was saved.
            ctx.request_repaint_after(watch::DEBOUNCE);
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, eframe::APP_KEY, &self.prefs);
    }
}

/// What each pane of the workspace shows.
fn pane_ui(app: &mut ViewerApp, ui: &mut egui::Ui, pane: workspace::Pane) {
    use workspace::Pane;
    match pane {
        Pane::Render => app.viewport(ui),
        Pane::SceneView => scene_pane::scene_view_ui(app, ui),
        Pane::Diagram => match app.tree.clone() {
            Some(tree) => {
                if tree_view::diagram(ui, &tree, &mut app.tree_state) {
                    let name = format!("tree-{}-{}.svg", tree.pixel[0], tree.pixel[1]);
                    let dir = app.start_dir();
                    app.browser = Some(FileBrowser::new(BrowseFor::ExportDiagram, dir, &name));
                }
            }
            None => {
                ui.weak("click a pixel in the render view for its ray tree");
            }
        },
        Pane::TreeList => {
            if app.tree.is_some() {
                panels::tree_panel(app, ui);
            } else {
                ui.weak(
                    "click a pixel in the render view for its ray tree; shift-click adds more pixels",
                );
            }
        }
    }
}

/// The toasts' stack: bottom right, above the status bar, over the panes.
fn new_toasts() -> egui_notify::Toasts {
    egui_notify::Toasts::default()
        .with_anchor(egui_notify::Anchor::BottomRight)
        .with_margin(egui::vec2(12.0, 56.0))
}

/// `text` broken into lines of at most about `width` characters at spaces (a toast does not
/// wrap its text itself).
pub fn wrap_words(text: &str, width: usize) -> String {
    let mut out = String::new();
    let mut line = 0;
    for word in text.split(' ') {
        let n = word.chars().count();
        if line > 0 && line + 1 + n > width {
            out.push('\n');
            line = 0;
        } else if line > 0 {
            out.push(' ');
            line += 1;
        }
        out.push_str(word);
        line += n;
    }
    out
}

impl ViewerApp {
    /// Shows the settings panel, or hides it (saying how it comes back).
    pub fn toggle_settings_panel(&mut self) {
        self.prefs.settings_panel = !self.prefs.settings_panel;
        if !self.prefs.settings_panel {
            self.messages.push((
                false,
                "settings hidden: Ctrl+B or View > Settings panel shows them".into(),
            ));
        }
    }

    /// Messages not yet shown become toasts: over the panes, bottom right, never moving the
    /// layout; notices go after a few seconds, errors stay longer (hover keeps either).
    fn show_toasts(&mut self, ctx: &egui::Context) {
        for (is_error, text) in self.messages.iter().skip(self.toasted) {
            let text = wrap_words(text, 72);
            // Plain-text marks: egui's default fonts have no emoji for the crate's icons.
            let level = if *is_error {
                ToastLevel::Custom("!".into(), egui::Color32::from_rgb(235, 100, 100))
            } else {
                ToastLevel::Custom("i".into(), egui::Color32::from_rgb(150, 200, 210))
            };
            self.toasts
                .add(egui_notify::Toast::custom(text, level))
                .closable(false)
                .duration(Some(Duration::from_secs(if *is_error { 20 } else { 6 })));
        }
        self.toasted = self.messages.len();
        self.toasts.show(ctx);
    }

    /// Takes every toast off the screen at once (the messages stay in the log).
    pub fn clear_toasts(&mut self) {
        self.toasts = new_toasts();
        self.toasted = self.messages.len();
    }

    /// The toasts on screen now.
    pub fn toasts_shown(&self) -> usize {
        self.toasts.len()
    }

    /// Notes the render pane's size `avail` (screen points). When the render follows the pane,
    /// a size that held for [`PANE_SIZE_DEBOUNCE`] (at once the first time) becomes the render
    /// size, within the loader's limits.
    pub(super) fn observe_pane(&mut self, ctx: &egui::Context, avail: egui::Rect) {
        if !self.prefs.pane_size {
            return;
        }
        let ppp = ctx.pixels_per_point();
        let max = scene::rules::MAX_IMAGE_SIZE as f32;
        let side = |v: f32| (v * ppp).floor().clamp(1.0, max) as u32;
        let px = (side(avail.width()), side(avail.height()));
        let now = Instant::now();
        let since = match self.pane_seen {
            Some((seen, since)) if seen == px => since,
            _ => {
                self.pane_seen = Some((px, now));
                now
            }
        };
        if self.pane_px == Some(px) {
            return;
        }
        let waited = now.duration_since(since);
        if self.pane_px.is_none() || waited >= PANE_SIZE_DEBOUNCE {
            self.pane_px = Some(px);
            self.pending.push(Command::MoveCamera);
        } else {
            ctx.request_repaint_after(PANE_SIZE_DEBOUNCE - waited);
        }
    }

    /// Where the render is drawn in `avail` (its aspect kept, on whole pixels), the display
    /// filtering set for that scale.
    pub(super) fn image_rect(&mut self, ctx: &egui::Context, avail: egui::Rect) -> egui::Rect {
        let (w, h) = self.render_size();
        let (rect, scale) = viewport::fit_image(avail, w, h, ctx.pixels_per_point());
        crate::sync::lock(&self.display).params.smooth = viewport::smooth_at(scale);
        rect
    }

    /// The viewer's own settings, in the render panel: the sample target and the pane size.
    pub fn view_settings_ui(&mut self, ui: &mut egui::Ui) {
        let mut target = self.prefs.viewer_samples;
        let mut pane = self.prefs.pane_size;
        let changed_target = ui
            .add(
                egui::Slider::new(&mut target, 1..=4096)
                    .logarithmic(true)
                    .text("viewer samples"),
            )
            .on_hover_text(
                "samples per pixel the viewer refines to, then it idles; the scene's `samples` \
                 is for export and `raytree render`",
            )
            .changed();
        let changed_pane = ui
            .checkbox(&mut pane, "render at pane size")
            .on_hover_text(
                "render as many pixels as the render pane has (sharp at any window size); the \
                 scene's width and height stay for export and saving",
            )
            .changed();
        if changed_target || changed_pane {
            self.set_view(target, pane);
        }
    }

    /// Takes the message of a finished background export.
    fn poll_export(&mut self) {
        if let Some(rx) = &self.export_job {
            match rx.try_recv() {
                Ok(message) => {
                    self.messages.push(message);
                    self.export_job = None;
                }
                Err(std::sync::mpsc::TryRecvError::Empty) => {}
                Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                    self.export_job = None;
                    self.error("the export stopped before it wrote its file");
                }
            }
        }
    }

    /// Whether an export is rendering in the background.
    pub fn exporting(&self) -> bool {
        self.export_job.is_some()
    }

    fn refresh_if_mode_changed(&mut self) {
        let (mode, exposure, tonemap) = {
            let d = crate::sync::lock(&self.display);
            (d.params.raw, d.params.exposure, d.params.tonemap)
        };
        let want_raw = self.prefs.mode != ImageMode::Render;
        if mode != want_raw
            || exposure != self.prefs.exposure
            || tonemap != self.prefs.tonemap
            || (want_raw && self.last_mode != self.prefs.mode)
        {
            self.refresh_display();
        }
        self.last_mode = self.prefs.mode;
    }

    /// Starts the trace with the settings of the working copy (for callers outside the UI).
    pub fn set_trace(&mut self, trace: TraceSettings) {
        self.settings.trace = trace;
        self.pending.push(Command::Rebuild);
    }

    /// The accelerator in use.
    pub fn accel(&self) -> &Accel {
        &self.tracer.accel
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
    }

    #[test]
    fn a_pixel_keeps_its_place_at_another_render_size() {
        assert_eq!(remap_pixel([0, 0], (640, 480), (1280, 960)), [1, 1]);
        assert_eq!(remap_pixel([639, 479], (640, 480), (320, 240)), [319, 239]);
        assert_eq!(remap_pixel([320, 240], (640, 480), (800, 300)), [400, 150]);
        // Never outside the new image.
        assert_eq!(remap_pixel([9, 9], (10, 10), (3, 3)), [2, 2]);
    }

    #[test]
    fn words_wrap_at_spaces_only() {
        assert_eq!(wrap_words("a bb ccc dddd", 6), "a bb\nccc\ndddd");
        let long = "x".repeat(30);
        assert_eq!(wrap_words(&long, 10), long);
        assert_eq!(wrap_words("", 10), "");
    }
}
