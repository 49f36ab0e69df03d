//! Opening a scene file off the UI thread, so the window never freezes (docs/design.md, "The
//! viewer"). One background job reads the file (in chunks, with the bytes counted), parses it
//! (meshes, materials, attributes, the first look of a bare OBJ), makes the viewer's copy at
//! the render size and builds the accelerator (on rayon's global pool, beside the render's
//! workers); the UI keeps drawing the previous scene and takes the result when it is ready
//! ([`OpenJob::try_take`]). A newer open, an accelerator change or a reload cancels the job:
//! its flag is checked at every stage boundary (and between chunks of the read), and a
//! cancelled job never sends a result.
//!
//! Progress is stage-weighted (see [`OpenJob::percent`] and the README): the read is counted in
//! bytes; the parse and the build, which report nothing, are timed against estimates from the
//! file's size (and, once parsed, its triangle count) at the rates measured on this run.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use crate::render::panic_message;
use crate::scene::files::{LoadStep, load_scene_file_watched};
use crate::scene::{Camera, Scene, budget};
use crate::trace::{TraceSettings, Tracer};

/// The stages of an open, in order; the hook hears each as it begins.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum OpenStage {
    /// Reading the file's bytes.
    Read = 0,
    /// Parsing: meshes, materials, attributes, the first look.
    Parse = 1,
    /// Building the accelerator over the viewer's copy.
    Build = 2,
    /// Built: about to hand the result over.
    Ready = 3,
}

impl OpenStage {
    fn from_u8(v: u8) -> Self {
        match v {
            0 => Self::Read,
            1 => Self::Parse,
            2 => Self::Build,
            _ => Self::Ready,
        }
    }
}

/// Called on the open's thread as each stage begins (before its cancel check): the tests hold
/// an open in the background with it. The viewer sets none.
pub type OpenHook = dyn Fn(OpenStage) + Send + Sync;

/// What the open's thread reports, read by the UI without locks (but the stage's start time).
#[derive(Debug)]
pub struct OpenProgress {
    stage: AtomicU8,
    read_done: AtomicU64,
    read_total: AtomicU64,
    /// Triangles of the parsed scene (0 until parsed).
    triangles: AtomicU64,
    stage_since: Mutex<Instant>,
}

impl OpenProgress {
    fn new() -> Self {
        Self {
            stage: AtomicU8::new(OpenStage::Read as u8),
            read_done: AtomicU64::new(0),
            read_total: AtomicU64::new(0),
            triangles: AtomicU64::new(0),
            stage_since: Mutex::new(Instant::now()),
        }
    }

    fn enter(&self, stage: OpenStage) {
        *crate::sync::lock(&self.stage_since) = Instant::now();
        self.stage.store(stage as u8, Ordering::SeqCst);
    }

    pub fn stage(&self) -> OpenStage {
        OpenStage::from_u8(self.stage.load(Ordering::SeqCst))
    }

    fn stage_secs(&self) -> f64 {
        crate::sync::lock(&self.stage_since).elapsed().as_secs_f64()
    }
}

/// Rates of the stages, measured on this run (the last open) or, before any, on the
/// development machine (`cargo bench --bench open`: 2 cores shared with other work, a
/// 1M-triangle OBJ of 38 MB parsed in 0.75–1.5 s and copied and built in 1.1–2.7 s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rates {
    pub read_bytes_per_sec: f64,
    pub parse_bytes_per_sec: f64,
    pub build_triangles_per_sec: f64,
    /// OBJ bytes per triangle, to guess the build's size before the parse counts triangles.
    pub bytes_per_triangle: f64,
}

impl Default for Rates {
    fn default() -> Self {
        Self {
            read_bytes_per_sec: 1.0e9,
            parse_bytes_per_sec: 30.0e6,
            build_triangles_per_sec: 0.6e6,
            bytes_per_triangle: 38.0,
        }
    }
}

impl Rates {
    /// The rates of a finished open; a stage too short to time keeps its old rate.
    pub fn learn(&mut self, t: &Timings) {
        let rate = |amount: f64, secs: f64, old: f64| {
            if amount > 0.0 && secs > 1e-3 {
                amount / secs
            } else {
                old
            }
        };
        let (bytes, tris) = (t.bytes as f64, t.triangles as f64);
        self.read_bytes_per_sec = rate(bytes, t.read_secs, self.read_bytes_per_sec);
        self.parse_bytes_per_sec = rate(bytes, t.parse_secs, self.parse_bytes_per_sec);
        if t.built {
            self.build_triangles_per_sec = rate(tris, t.build_secs, self.build_triangles_per_sec);
        }
        if tris > 0.0 && bytes > 0.0 {
            self.bytes_per_triangle = bytes / tris;
        }
    }

    /// Estimated seconds to build an accelerator over `triangles` (its percentage while a
    /// build of the viewer's own runs).
    pub fn build_secs(&self, triangles: u64) -> f64 {
        triangles as f64 / self.build_triangles_per_sec.max(1.0)
    }
}

/// Seconds each stage took, and how much it handled.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    pub bytes: u64,
    pub triangles: u64,
    pub read_secs: f64,
    pub parse_secs: f64,
    pub build_secs: f64,
    /// False when the accelerator was reused (a reload with the same geometry).
    pub built: bool,
}

/// The size the viewer renders a scene of `scene_size` at, and what it does when that is
/// too large for the GPU's texture (`max_side`) or the memory budget.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The render's width and height.
    pub render: (u32, u32),
    /// The scene's own size (shrunk, with `message`, when the scene's size is too large).
    pub scene: (u32, u32),
    pub message: Option<String>,
}

/// A bare OBJ's first look, framed by the loader for the scene's own size (640×480), framed
/// again for the render `pane` it is shown in: in a pane narrower than 4:3 (the settings panel
/// beside it at 1600×1000) a long model lost both ends. A room's camera, or a scene that is no
/// bare OBJ, stays ([`crate::scene::first_look::refit_bare_obj`]).
pub fn frame_for_pane(scene: &mut Scene, pane: (u32, u32)) {
    let size = (scene.render.width, scene.render.height);
    (scene.render.width, scene.render.height) = pane;
    crate::scene::first_look::refit_bare_obj(scene);
    (scene.render.width, scene.render.height) = size;
}

/// The one rule for the render size: the pane's pixels (`pane`, when the render follows it)
/// or the scene's size, scaled down to fit the GPU and the memory budget (a shrunk scene
/// size says so; `raytree render` renders the full size).
pub fn fit_render(scene: (u32, u32), pane: Option<(u32, u32)>, max_side: u32) -> Fit {
    let (w, h) = pane.unwrap_or(scene);
    let limit = budget::memory_limit();
    let per_pixel = budget::viewer_memory_estimate(1, 1).max(1);
    let max_pixels = (limit.bytes / per_pixel).max(1) as f64;
    let k = (max_side as f64 / w.max(h) as f64)
        .min((max_pixels / (w as f64 * h as f64)).sqrt())
        .min(1.0);
    let scaled = (
        ((w as f64 * k) as u32).max(1),
        ((h as f64 * k) as u32).max(1),
    );
    if k >= 1.0 {
        Fit {
            render: (w, h),
            scene,
            message: None,
        }
    } else if pane.is_some() {
        // A pane larger than the GPU or the budget allows: fewer pixels, scaled up.
        Fit {
            render: scaled,
            scene,
            message: None,
        }
    } else {
        let (nw, nh) = scaled;
        Fit {
            render: scaled,
            scene: scaled,
            message: Some(format!(
                "the viewer shows at most {max_side} pixels across and {:.0} MiB of buffers ({}): showing {w}x{h} at {nw}x{nh}; `raytree render` renders the full size",
                limit.bytes as f64 / (1 << 20) as f64,
                limit.source
            )),
        }
    }
}

/// What an open needs from the viewer.
pub struct Request {
    pub path: PathBuf,
    pub settings: TraceSettings,
    /// The render pane's pixels, when the render follows the pane.
    pub pane: Option<(u32, u32)>,
    pub max_side: u32,
    /// A reload after a save: the tracer shown now (its accelerator is kept when the geometry
    /// did not change) and the viewer's camera (kept then too).
    pub reload: Option<(Arc<Tracer>, Camera)>,
    pub hook: Option<Arc<OpenHook>>,
}

/// A finished open.
pub struct Opened {
    /// The working copy, at the scene's size.
    pub edit: Scene,
    /// The tracer over the viewer's copy (at the render size), accelerator built.
    pub tracer: Arc<Tracer>,
    pub fit: Fit,
    /// A reload whose geometry is the one shown: camera, trees and accelerator kept.
    pub same_geometry: bool,
    pub timings: Timings,
}

pub enum Outcome {
    Opened(Box<Opened>),
    /// The one sentence of the loader (file, place, field).
    Failed(String),
}

/// Why a file is opened.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpenKind {
    /// Another scene, asked for by the user.
    Open,
    /// The scene shown, again, after a save.
    Reload,
}

/// An open under way.
pub struct OpenJob {
    pub path: PathBuf,
    /// Whether it reloads the open scene after a save.
    pub kind: OpenKind,
    /// The accelerator it builds.
    pub accel: crate::accel::AccelKind,
    cancel: Arc<AtomicBool>,
    progress: Arc<OpenProgress>,
    receiver: Receiver<Outcome>,
    /// The largest percentage shown so far: the number never goes back.
    shown: f32,
}

impl OpenJob {
    /// Starts the open on a thread of its own. Its parallel parts (the parse, the build) run
    /// on rayon's global pool, not on the render's: the render's workers take their own tiles
    /// before any job handed to their pool, so an open queued there waited for the whole
    /// previous render to converge (seen at 64 samples: 30 s at "57 %").
    pub fn start(request: Request) -> Result<Self, String> {
        let cancel = Arc::new(AtomicBool::new(false));
        let progress = Arc::new(OpenProgress::new());
        let (sender, receiver) = channel();
        let job = Self {
            path: request.path.clone(),
            kind: if request.reload.is_some() {
                OpenKind::Reload
            } else {
                OpenKind::Open
            },
            accel: request.settings.accel,
            cancel: cancel.clone(),
            progress: progress.clone(),
            receiver,
            shown: 0.0,
        };
        let work = move || {
            let outcome = catch_unwind(AssertUnwindSafe(|| run(&request, &cancel, &progress)))
                .unwrap_or_else(|panic| {
                    Some(Outcome::Failed(format!(
                        "{}: cannot open the file: {}",
                        request.path.display(),
                        panic_message(panic.as_ref())
                    )))
                });
            // A cancelled open never hands anything over.
            if let Some(outcome) = outcome
                && !cancel.load(Ordering::SeqCst)
            {
                // The viewer may have closed meanwhile: then nobody waits.
                let _ = sender.send(outcome);
            }
        };
        std::thread::Builder::new()
            .name("raytree-open".into())
            .spawn(work)
            .map_err(|e| format!("cannot start opening {}: {e}", job.path.display()))?;
        Ok(job)
    }

    /// Stops the job at its next stage boundary; its result is never handed over.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::SeqCst);
    }

    /// The result, once, when it is ready.
    pub fn try_take(&self) -> Option<Outcome> {
        match self.receiver.try_recv() {
            Ok(outcome) => Some(outcome),
            Err(TryRecvError::Empty) => None,
            // The thread ended without a word: only a cancelled job does that.
            Err(TryRecvError::Disconnected) => Some(Outcome::Failed(format!(
                "{}: the open stopped before it finished",
                self.path.display()
            ))),
        }
    }

    pub fn stage(&self) -> OpenStage {
        self.progress.stage()
    }

    /// The open's progress in percent, never back, below 100 until the result is taken.
    /// Stage-weighted: each stage's weight is its estimated seconds at `rates` (read and parse
    /// from the file's bytes; the build from the triangles, guessed from the bytes until the
    /// parse has counted them). Within the read, bytes read; within the parse and the build,
    /// their elapsed time against their estimate, held at 95 % of the stage when it overruns.
    pub fn percent(&mut self, rates: &Rates) -> f32 {
        let p = &self.progress;
        let total = p.read_total.load(Ordering::SeqCst) as f64;
        let done = p.read_done.load(Ordering::SeqCst) as f64;
        let triangles = match p.triangles.load(Ordering::SeqCst) {
            0 => total / rates.bytes_per_triangle.max(1.0),
            n => n as f64,
        };
        let weights = [
            total / rates.read_bytes_per_sec.max(1.0),
            total / rates.parse_bytes_per_sec.max(1.0),
            triangles / rates.build_triangles_per_sec.max(1.0),
        ];
        let stage = p.stage();
        let within = match stage {
            OpenStage::Read => {
                if total > 0.0 {
                    (done / total).min(1.0)
                } else {
                    0.0
                }
            }
            OpenStage::Parse | OpenStage::Build => {
                let estimate = weights[stage as usize].max(1e-3);
                (p.stage_secs() / estimate).min(0.95)
            }
            OpenStage::Ready => 1.0,
        };
        let before: f64 = weights.iter().take(stage as usize).sum();
        let current = weights.get(stage as usize).copied().unwrap_or(0.0);
        let all: f64 = weights.iter().sum::<f64>().max(1e-9);
        let percent = (100.0 * (before + within * current) / all).clamp(0.0, 99.0) as f32;
        self.shown = self.shown.max(percent);
        self.shown
    }
}

/// The job's work; `None` when cancelled (or the file could not be read at all: then a
/// `Failed`).
fn run(request: &Request, cancel: &AtomicBool, progress: &OpenProgress) -> Option<Outcome> {
    let go_on = |stage: OpenStage| {
        if let Some(hook) = &request.hook {
            hook(stage);
        }
        !cancel.load(Ordering::SeqCst)
    };
    let started = Instant::now();
    let mut timings = Timings::default();
    let mut parse_started = started;
    progress.enter(OpenStage::Read);
    if !go_on(OpenStage::Read) {
        return None;
    }
    let loaded = load_scene_file_watched(&request.path, &mut |step| match step {
        LoadStep::Read { done, total } => {
            progress.read_total.store(total, Ordering::SeqCst);
            progress.read_done.store(done, Ordering::SeqCst);
            !cancel.load(Ordering::SeqCst)
        }
        LoadStep::Parse => {
            timings.read_secs = started.elapsed().as_secs_f64();
            parse_started = Instant::now();
            progress.enter(OpenStage::Parse);
            go_on(OpenStage::Parse)
        }
    });
    let mut edit = match loaded {
        Ok(Some(scene)) => scene,
        Ok(None) => return None,
        Err(e) => return Some(Outcome::Failed(e.to_string())),
    };
    timings.parse_secs = parse_started.elapsed().as_secs_f64();
    timings.bytes = progress.read_total.load(Ordering::SeqCst);
    timings.triangles = edit.triangles.len() as u64;
    progress
        .triangles
        .store(timings.triangles.max(1), Ordering::SeqCst);
    progress.enter(OpenStage::Build);
    if !go_on(OpenStage::Build) {
        return None;
    }
    let build_started = Instant::now();
    let kept = request.reload.as_ref().filter(|(shown, _)| {
        edit.triangles == shown.scene.triangles && edit.spheres == shown.scene.spheres
    });
    match (kept, request.pane) {
        (Some((_, camera)), _) => edit.camera = camera.clone(),
        (None, Some(pane)) => frame_for_pane(&mut edit, pane),
        (None, None) => {}
    }
    edit.place_lights();
    let fit = fit_render(
        (edit.render.width, edit.render.height),
        request.pane,
        request.max_side,
    );
    (edit.render.width, edit.render.height) = fit.scene;
    let mut shown = edit.clone();
    (shown.render.width, shown.render.height) = fit.render;
    let shown = Arc::new(shown);
    let tracer = match kept {
        Some((old, _)) if old.settings.accel == request.settings.accel => {
            Tracer::with_accel(shown, request.settings, old.accel.clone())
        }
        _ => {
            timings.built = true;
            Tracer::new(shown, request.settings)
        }
    };
    timings.build_secs = build_started.elapsed().as_secs_f64();
    progress.enter(OpenStage::Ready);
    if !go_on(OpenStage::Ready) {
        return None;
    }
    Some(Outcome::Opened(Box::new(Opened {
        edit,
        tracer: Arc::new(tracer),
        fit,
        same_geometry: kept.is_some(),
        timings,
    })))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_that_fits_renders_at_its_size_and_a_huge_one_is_shrunk_with_a_message() {
        let fit = fit_render((640, 480), None, 8192);
        assert_eq!(fit.render, (640, 480));
        assert_eq!(fit.message, None);
        let fit = fit_render((16000, 100), None, 8000);
        assert_eq!(fit.render, (8000, 50));
        assert_eq!(fit.scene, (8000, 50));
        assert!(fit.message.is_some_and(|m| m.contains("16000x100")));
        // A pane too large: fewer pixels, the scene's size untouched.
        let fit = fit_render((640, 480), Some((16000, 100)), 8000);
        assert_eq!(
            (fit.render, fit.scene, fit.message),
            ((8000, 50), (640, 480), None)
        );
    }

    #[test]
    fn rates_learn_from_a_finished_open_but_not_from_an_untimed_stage() {
        let mut r = Rates::default();
        r.learn(&Timings {
            bytes: 100_000_000,
            triangles: 2_000_000,
            read_secs: 0.1,
            parse_secs: 2.0,
            build_secs: 0.0,
            built: true,
        });
        assert_eq!(r.read_bytes_per_sec, 1e9);
        assert_eq!(r.parse_bytes_per_sec, 5e7);
        assert_eq!(
            r.build_triangles_per_sec,
            Rates::default().build_triangles_per_sec
        );
        assert_eq!(r.bytes_per_triangle, 50.0);
        r.build_triangles_per_sec = 1.5e6;
        assert!((r.build_secs(3_000_000) - 2.0).abs() < 1e-9);
    }
}
