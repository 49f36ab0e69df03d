//! The render view's state: the session rendering the working copy progressively, the tracer
//! of the current generation, the film its tiles fill, the display the GPU draws, the size the
//! render follows, and an export rendering in the background.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use eframe::egui;

use super::film::Film;
use super::messages::{Message, Messages};
use super::modes::ImageMode;
use super::viewport::{self, DisplayState, Pixels, SharedDisplay};
use super::{Command, Prefs};
use crate::accel::Accel;
use crate::render::Image;
use crate::render::session::{Pass, Session};
use crate::scene::{self, Scene};
use crate::trace::{TraceSettings, Tracer};

/// How long the render pane's size must hold before the render follows it.
pub const PANE_SIZE_DEBOUNCE: Duration = Duration::from_millis(250);

/// Which views a new generation restarts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reach {
    /// The render only: the scene view's picture stays, unless it depends on the render
    /// camera (a headlight, walls cut away around it: see
    /// [`super::scene_pane::SceneView::follows_render_camera`]).
    Render,
    /// The render and the scene view.
    RenderAndSceneView,
}

impl Reach {
    /// The wider of the two.
    pub fn and(self, other: Reach) -> Reach {
        if self == Reach::Render && other == Reach::Render {
            Reach::Render
        } else {
            Reach::RenderAndSceneView
        }
    }
}

/// Progress of the current generation, as the UI saw it.
#[derive(Clone, Debug, Default)]
pub struct Progress {
    pub(super) started: Option<Instant>,
    /// Samples per pixel of the last complete pass (0: only the preview, or nothing yet).
    pub(super) samples_done: u32,
    pub(super) preview_done: bool,
    pub(super) finished_secs: Option<f64>,
    /// What the status bar says of the pass under way: "preview", "4 samples", "stopped".
    pub(super) pass_label: String,
    /// The largest build percentage shown, so it never goes back.
    pub(super) build_percent: f64,
}

impl Progress {
    fn starting(label: &str) -> Self {
        Progress {
            started: Some(Instant::now()),
            pass_label: label.into(),
            ..Progress::default()
        }
    }

    /// Notes a pass of the current generation done.
    pub fn pass_done(&mut self, pass: Pass) {
        match pass {
            Pass::Preview => {
                self.preview_done = true;
                self.pass_label = "1 sample".into();
            }
            Pass::Samples(n) => {
                self.samples_done = n;
                self.pass_label = crate::plural::count(n, "sample");
            }
        }
    }

    /// Seconds the generation has run (or took, when finished).
    pub fn elapsed(&self) -> f64 {
        match (self.finished_secs, self.started) {
            (Some(s), _) => s,
            (None, Some(t)) => t.elapsed().as_secs_f64(),
            _ => 0.0,
        }
    }
}

/// The render pane's size in pixels, and the size the render follows.
#[derive(Clone, Copy, Debug, Default)]
struct PaneSize {
    /// As last seen, since when it has held, and the egui pass it was first seen in.
    seen: Option<((u32, u32), Instant, u64)>,
    /// The size the render follows (`None`: the scene's), set once `seen` held.
    follows: Option<(u32, u32)>,
}

/// The render view's state.
pub struct RenderView {
    /// The tracer of the current generation; its scene is the one rendered.
    pub(super) tracer: Arc<Tracer>,
    pub(super) session: Session,
    generation: u64,
    /// A build asked of the session and not yet installed, and which views its generation
    /// restarts; while it is, the current tracer's accelerator does not fit the working copy,
    /// so every restart builds (a stop in the middle of a build drops it).
    pub(super) pending_build: Option<Reach>,
    pub(super) progress: Progress,
    /// The film as the latest tiles left it: linear colour and sample-0 facts per pixel.
    pub(super) film: Film,
    pub(super) display: SharedDisplay,
    pane: PaneSize,
    /// The scene's own width and height (the working copy's, kept when an edit is refused).
    pub(super) scene_size: (u32, u32),
    /// The largest texture side the GPU allows: the render is never larger on screen.
    pub(super) max_side: u32,
    /// The image mode the display was last painted in.
    painted_mode: ImageMode,
    /// An export rendering at the scene's size in the background.
    pub(super) export_job: Option<ExportJob>,
}

/// An export rendering at the scene's size in the background: its progress, its cancel flag
/// and its message when done.
#[derive(Debug)]
pub struct ExportJob {
    message: Receiver<Message>,
    /// The file it writes, for the status bar.
    pub file: String,
    /// Thousandths of the work done.
    pub progress: Arc<AtomicU64>,
    pub cancel: Arc<AtomicBool>,
}

impl ExportJob {
    pub fn new(message: Receiver<Message>, file: String) -> Self {
        Self {
            message,
            file,
            progress: Arc::default(),
            cancel: Arc::default(),
        }
    }

    /// The share of the work done, 0 to 1.
    pub fn done(&self) -> f32 {
        self.progress.load(Ordering::Relaxed) as f32 / 1000.0
    }

    /// Asks the job to stop; its message says it was cancelled.
    pub fn stop(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

impl RenderView {
    pub fn new(
        scene: Arc<Scene>,
        trace: TraceSettings,
        threads: usize,
        max_side: u32,
    ) -> Result<Self, String> {
        let session = Session::new(threads)?;
        let (w, h) = (scene.render.width, scene.render.height);
        Ok(Self {
            tracer: Arc::new(Tracer::new(scene, trace)),
            session,
            generation: 0,
            pending_build: None,
            progress: Progress::default(),
            film: Film::new(w, h),
            display: Arc::new(Mutex::new(DisplayState::new(w, h))),
            pane: PaneSize::default(),
            scene_size: (w, h),
            max_side: max_side.max(1),
            painted_mode: ImageMode::Render,
            export_job: None,
        })
    }

    /// The scene rendered.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.tracer.scene
    }

    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The accelerator in use.
    pub fn accel(&self) -> &Accel {
        &self.tracer.accel
    }

    /// The size rendered at: the render pane's pixels (when the render follows the pane and
    /// the pane has been seen) or the scene's width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.scene().render.width, self.scene().render.height)
    }

    /// The film as it stands: the mean of the samples done so far.
    pub fn image(&self) -> Image {
        self.film.image()
    }

    /// The pane size the render follows, when `prefs` have it follow the pane.
    pub fn pane(&self, prefs: &Prefs) -> Option<(u32, u32)> {
        self.pane.follows.filter(|_| prefs.pane_size)
    }

    /// The render pane's size in pixels as last drawn (`None`: not drawn yet, or the render
    /// does not follow it).
    pub fn pane_seen(&self, prefs: &Prefs) -> Option<(u32, u32)> {
        self.pane
            .seen
            .map(|(px, _, _)| px)
            .filter(|_| prefs.pane_size)
    }

    /// Sets the viewer's sample target and whether the render follows the pane's size in
    /// `prefs`, and asks for a render with them.
    pub fn set_view(
        &mut self,
        prefs: &mut Prefs,
        pending: &mut Vec<Command>,
        viewer_samples: u32,
        pane_size: bool,
    ) {
        prefs.viewer_samples = viewer_samples.clamp(1, scene::rules::MAX_SAMPLES);
        prefs.pane_size = pane_size;
        if !pane_size {
            self.pane.follows = None;
        }
        pending.push(Command::Restart);
    }

    /// Starts a generation of `tracer`, whose accelerator is built.
    pub fn start(&mut self, tracer: Arc<Tracer>, target: u32, focus: Option<(f32, f32)>) {
        self.generation = self.session.start(tracer, target, focus);
        self.progress = Progress::starting("preview");
    }

    /// Starts a generation whose accelerator the session builds first, off the UI thread:
    /// the previous image stays up, with "building BVH…", until the built tracer is taken.
    pub fn start_build(
        &mut self,
        scene: Arc<Scene>,
        trace: TraceSettings,
        target: u32,
        focus: Option<(f32, f32)>,
        reach: Reach,
    ) {
        self.generation = self.session.start_build(scene, trace, target, focus);
        self.progress = Progress::starting("building BVH…");
        self.pending_build = Some(self.pending_build.map_or(reach, |r| r.and(reach)));
    }

    /// Stops the render; the film keeps what it has.
    pub fn stop(&mut self) {
        self.session.stop();
        self.generation = self.session.generation();
    }

    /// The tracer built for the pending generation, once the session hands it out, and the
    /// views that generation restarts.
    pub fn take_built(&mut self) -> Option<(Arc<Tracer>, Reach)> {
        let tracer = self.session.take_built()?;
        let reach = self
            .pending_build
            .take()
            .unwrap_or(Reach::RenderAndSceneView);
        self.progress.pass_label = "preview".into();
        Some((tracer, reach))
    }

    /// Makes `tracer` the current one, film and display at its size; returns the size
    /// rendered before.
    pub fn install(&mut self, tracer: Arc<Tracer>) -> (u32, u32) {
        let old = self.size();
        self.tracer = tracer;
        let (w, h) = self.size();
        self.film.resize(w, h);
        crate::sync::lock(&self.display).resize(w, h);
        old
    }

    /// While the session builds: the time so far against the estimate of `estimate_secs`
    /// (obvhs reports no progress), held below 100 % until the build is handed over.
    pub fn show_build_progress(&mut self, estimate_secs: f64) {
        if let Some(t) = self.session.building_for() {
            let percent = (100.0 * t.as_secs_f64() / estimate_secs.max(1e-3)).min(99.0);
            let percent = self.progress.build_percent.max(percent);
            self.progress.build_percent = percent;
            self.progress.pass_label = format!("building BVH… {percent:.0} %");
        }
    }

    /// Notes the render pane's size `avail` (screen points). When the render follows the pane,
    /// a size that held for [`PANE_SIZE_DEBOUNCE`] becomes the render size, within the loader's
    /// limits; returns true then. The first size is taken as soon as a second egui pass sees
    /// it: a window's first pass lays out before every panel knows its height, so the size it
    /// gives is not the window's (rendering it would mean a second render 250 ms later).
    pub fn observe_pane(&mut self, ctx: &egui::Context, avail: egui::Rect, prefs: &Prefs) -> bool {
        if !prefs.pane_size {
            return false;
        }
        let ppp = ctx.pixels_per_point();
        let max = scene::rules::MAX_IMAGE_SIZE as f32;
        let side = |v: f32| (v * ppp).floor().clamp(1.0, max) as u32;
        let px = (side(avail.width()), side(avail.height()));
        let now = Instant::now();
        let pass = ctx.cumulative_pass_nr();
        let (since, first_pass) = match self.pane.seen {
            Some((seen, since, first)) if seen == px => (since, first),
            _ => {
                self.pane.seen = Some((px, now, pass));
                (now, pass)
            }
        };
        if self.pane.follows == Some(px) {
            return false;
        }
        if self.pane.follows.is_none() && pass == first_pass {
            // Lay the window out once more (in the same frame when egui allows it, or else in
            // the next), and take the size that pass sees.
            ctx.request_discard("the render pane's first size is not settled");
            ctx.request_repaint();
            return false;
        }
        let waited = now.duration_since(since);
        if self.pane.follows.is_none() || waited >= PANE_SIZE_DEBOUNCE {
            self.pane.follows = Some(px);
            true
        } else {
            ctx.request_repaint_after(PANE_SIZE_DEBOUNCE - waited);
            false
        }
    }

    /// Where the render is drawn in `avail` (its aspect kept, on whole pixels), the display
    /// filtering set for that scale.
    pub fn image_rect(&mut self, ctx: &egui::Context, avail: egui::Rect) -> egui::Rect {
        let (w, h) = self.size();
        let (rect, scale) = viewport::fit_image(avail, w, h, ctx.pixels_per_point());
        crate::sync::lock(&self.display).params.smooth = viewport::smooth_at(scale);
        rect
    }

    /// Rewrites the whole display buffer for the image mode, exposure and tonemap of `prefs`.
    fn refresh_display(&mut self, prefs: &Prefs) {
        let mut display = crate::sync::lock(&self.display);
        let mode = prefs.mode;
        self.film
            .paint(mode, self.tracer.scene.render.max_depth, &mut display);
        display.params.exposure = prefs.exposure;
        display.params.tonemap = prefs.tonemap;
        display.params.pixels = pixels_of(mode);
        display.mark_all();
    }

    /// Repaints the display when `prefs` show it otherwise than it was painted.
    pub fn follow_display_prefs(&mut self, prefs: &Prefs) {
        let params = crate::sync::lock(&self.display).params;
        let pixels = pixels_of(prefs.mode);
        if params.pixels != pixels
            || params.exposure != prefs.exposure
            || params.tonemap != prefs.tonemap
            || (pixels == Pixels::Display && self.painted_mode != prefs.mode)
        {
            self.refresh_display(prefs);
        }
        self.painted_mode = prefs.mode;
    }

    /// Whether an export is rendering in the background.
    pub fn exporting(&self) -> bool {
        self.export_job.is_some()
    }

    /// The picture the display shows, as 8-bit sRGB RGB bytes ("as shown").
    pub fn display_shown(&self) -> Vec<u8> {
        crate::sync::lock(&self.display).shown_rgb8()
    }

    /// The export rendering in the background, if any.
    pub fn export_job(&self) -> Option<&ExportJob> {
        self.export_job.as_ref()
    }

    /// Takes the message of a finished background export.
    pub fn poll_export(&mut self, messages: &mut Messages) {
        if let Some(job) = &self.export_job {
            match job.message.try_recv() {
                Ok(message) => {
                    messages.push(message);
                    self.export_job = None;
                }
                Err(TryRecvError::Empty) => {}
                Err(TryRecvError::Disconnected) => {
                    self.export_job = None;
                    messages.error("the export stopped before it wrote its file");
                }
            }
        }
    }
}

/// What the display's pixels are in image mode `mode`.
fn pixels_of(mode: ImageMode) -> Pixels {
    if mode == ImageMode::Render {
        Pixels::Radiance
    } else {
        Pixels::Display
    }
}
