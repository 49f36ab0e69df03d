//! The progressive render session behind the viewer (docs/design.md, "The viewer"): rayon
//! workers trace 32×32 tiles in passes — a coarse preview (one sample per 8×8 block, the block
//! filled), every pixel at 1 sample, then samples accumulated in doubling batches up to the
//! target — nearest the focus point (image centre or cursor) first. Each start bumps a generation; workers drop stale work
//! at once; finished tiles go over a bounded channel tagged with their generation, so the UI
//! can never mix passes of two generations. The UI only ever calls `try_recv`.
//!
//! Each pixel's samples are added to its running sum in index order by
//! [`super::accumulate_tile`], the loop [`super::render`] runs too, so the converged image
//! equals the headless render bit for bit.

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use super::{Rect, TILE_SIZE, accumulate_tile, panic_message, tiles};
use crate::scene::{Camera, CameraFrame, Scene};
use crate::trace::{RayCounts, SampleInfo, TraceSettings, Tracer};

/// Side of the blocks of the coarse preview pass.
pub const PREVIEW_BLOCK: u32 = 8;

/// Capacity of the tile channel: enough for several passes of a large image between frames.
const CHANNEL_CAPACITY: usize = 4096;

/// Which pass a tile belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// One sample per block, blocks filled.
    Preview,
    /// Every pixel now holds the mean of `samples` samples.
    Samples(u32),
}

/// A finished tile.
#[derive(Clone, Debug)]
pub struct TileUpdate {
    pub generation: u64,
    pub pass: Pass,
    pub rect: Rect,
    /// Linear colours, row-major within `rect`.
    pub pixels: Vec<Vec3>,
    /// Image-mode facts, sent with the preview (block-filled) and the first full pass only.
    pub aux: Option<Vec<SampleInfo>>,
}

/// What the session reports to the UI.
#[derive(Clone, Debug)]
pub enum SessionEvent {
    Tile(TileUpdate),
    /// Every tile of a pass has been sent.
    PassDone {
        generation: u64,
        pass: Pass,
    },
    /// The target sample count is reached.
    Finished {
        generation: u64,
        secs: f64,
    },
    /// A worker panicked; the render of this generation stopped.
    Failed {
        generation: u64,
        message: String,
    },
}

impl SessionEvent {
    pub fn generation(&self) -> u64 {
        match self {
            SessionEvent::Tile(t) => t.generation,
            SessionEvent::PassDone { generation, .. }
            | SessionEvent::Finished { generation, .. }
            | SessionEvent::Failed { generation, .. } => *generation,
        }
    }
}

/// Live counters of the current generation, read by the UI without locks.
#[derive(Debug, Default)]
pub struct LiveStats {
    pub primary: AtomicU64,
    pub reflected: AtomicU64,
    pub refracted: AtomicU64,
    pub shadow: AtomicU64,
    /// Pixels finished in the current pass.
    pub pixels_done: AtomicU64,
}

impl LiveStats {
    fn add(&self, c: &RayCounts) {
        self.primary.fetch_add(c.primary, Ordering::Relaxed);
        self.reflected.fetch_add(c.reflected, Ordering::Relaxed);
        self.refracted.fetch_add(c.refracted, Ordering::Relaxed);
        self.shadow.fetch_add(c.shadow, Ordering::Relaxed);
    }

    pub fn counts(&self) -> RayCounts {
        RayCounts {
            primary: self.primary.load(Ordering::Relaxed),
            reflected: self.reflected.load(Ordering::Relaxed),
            refracted: self.refracted.load(Ordering::Relaxed),
            shadow: self.shadow.load(Ordering::Relaxed),
        }
    }
}

/// The sample ranges of the passes after the preview: [0,1), [1,2), [2,4), [4,8), … ending at
/// `target`.
pub fn sample_batches(target: u32) -> Vec<std::ops::Range<u32>> {
    let mut out = Vec::new();
    out.push(0..1.min(target));
    let mut done = 1;
    while done < target {
        let next = (done * 2).min(target);
        out.push(done..next);
        done = next;
    }
    out
}

/// Called by a worker at the start of each tile of every pass, inside the panic guard: the
/// fault tests make it panic to check that a failed worker is reported, as
/// [`super::render_with`] does for the batch render. The viewer sets none.
pub type TileHook = dyn Fn(Pass, Rect) + Send + Sync;

/// Called on the caller's thread just before [`Session::start`] spawns the render's
/// coordinator thread; an error stands for a failed spawn (the system out of threads or
/// memory): the fault tests use it to check that such a failure reaches the UI as
/// [`SessionEvent::Failed`]. The viewer sets none.
pub type SpawnHook = dyn Fn() -> std::io::Result<()> + Send + Sync;

/// A step of a generation's coordinator thread, reported to the [`StepHook`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Step {
    /// The tracer of a [`Session::start_build`] is about to be built; until the hook returns,
    /// the build waits.
    Building,
    /// The coordinator is done: the generation sends nothing more, whether it finished, failed,
    /// was superseded or was stopped.
    Done,
}

/// Called on a generation's coordinator thread with the generation and each [`Step`]: the
/// tests use it to hold a build until they have seen [`Session::start_build`] return, and to
/// know when a failed, superseded or stopped generation can send nothing more. The viewer sets
/// none.
pub type StepHook = dyn Fn(u64, Step) + Send + Sync;

/// Owns the worker pool and the channel; one per viewer.
pub struct Session {
    generation: Arc<AtomicU64>,
    sender: SyncSender<SessionEvent>,
    receiver: Receiver<SessionEvent>,
    pool: Arc<rayon::ThreadPool>,
    threads: usize,
    stats: Arc<LiveStats>,
    /// Events of older generations dropped on receipt.
    stale_dropped: Cell<u64>,
    tile_hook: Option<Arc<TileHook>>,
    spawn_hook: Option<Arc<SpawnHook>>,
    step_hook: Option<Arc<StepHook>>,
    /// A start that could not spawn its thread: handed out by [`Self::try_next`], since no
    /// worker exists to send it.
    start_failure: Cell<Option<SessionEvent>>,
    /// The tracer a [`Self::start_build`] made, with its generation, until taken.
    built: Arc<BuiltSlot>,
    /// The generation whose accelerator is being built and since when, until it is taken.
    building: Cell<Option<(u64, Instant)>>,
}

impl Session {
    /// A session with `threads` workers (0: every core).
    pub fn new(threads: usize) -> Result<Self, String> {
        let (sender, receiver) = sync_channel(CHANNEL_CAPACITY);
        Ok(Self {
            generation: Arc::new(AtomicU64::new(0)),
            sender,
            receiver,
            pool: Arc::new(build_pool(threads)?),
            threads,
            stats: Arc::new(LiveStats::default()),
            stale_dropped: Cell::new(0),
            tile_hook: None,
            spawn_hook: None,
            step_hook: None,
            start_failure: Cell::new(None),
            built: Arc::new(Mutex::new(None)),
            building: Cell::new(None),
        })
    }

    /// Sets (or with `None` removes) the [`TileHook`]; takes effect at the next start.
    pub fn set_tile_hook(&mut self, hook: Option<Arc<TileHook>>) {
        self.tile_hook = hook;
    }

    /// Sets (or with `None` removes) the [`SpawnHook`]; takes effect at the next start.
    pub fn set_spawn_hook(&mut self, hook: Option<Arc<SpawnHook>>) {
        self.spawn_hook = hook;
    }

    /// Sets (or with `None` removes) the [`StepHook`]; takes effect at the next start.
    pub fn set_step_hook(&mut self, hook: Option<Arc<StepHook>>) {
        self.step_hook = hook;
    }

    /// Changes the worker count (takes effect at the next start).
    pub fn set_threads(&mut self, threads: usize) -> Result<(), String> {
        if threads != self.threads {
            self.pool = Arc::new(build_pool(threads)?);
            self.threads = threads;
        }
        Ok(())
    }

    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::SeqCst)
    }

    pub fn stats(&self) -> &LiveStats {
        &self.stats
    }

    /// Stops the current render: its workers drop their work at the next tile.
    pub fn stop(&mut self) -> u64 {
        self.generation.fetch_add(1, Ordering::SeqCst) + 1
    }

    /// Starts rendering the tracer's scene up to `target` samples, tiles nearest `focus`
    /// (pixels; `None`: the image centre) first. Returns the new generation; when its thread
    /// cannot be spawned, that generation's first event is [`SessionEvent::Failed`].
    pub fn start(&mut self, tracer: Arc<Tracer>, target: u32, focus: Option<(f32, f32)>) -> u64 {
        self.spawn(Source::Ready(tracer), None, target, focus)
    }

    /// Like [`Self::start`], but seen through `view` (its own camera and size) instead of the
    /// scene's camera and `[render]` size: the scene view renders the render's scene this way,
    /// sharing it (and its accelerator) instead of copying a million triangles per orbit.
    pub fn start_view(&mut self, tracer: Arc<Tracer>, view: View, target: u32) -> u64 {
        self.spawn(Source::Ready(tracer), Some(view), target, None)
    }

    /// Like [`Self::start`], but first builds the tracer (its accelerator) of `scene` on the
    /// coordinator thread, so the caller never waits for a build (the window never freezes).
    /// The tracer is handed out by [`Self::take_built`] once built, just before the
    /// generation's first tile. A later start or stop supersedes the build: its result is
    /// dropped, never handed out (the build itself runs to its end in the background, as
    /// obvhs's cannot be interrupted). A panic in the build is that generation's
    /// [`SessionEvent::Failed`].
    pub fn start_build(
        &mut self,
        scene: Arc<Scene>,
        settings: TraceSettings,
        target: u32,
        focus: Option<(f32, f32)>,
    ) -> u64 {
        let generation = self.spawn(Source::Build(scene, settings), None, target, focus);
        self.building.set(Some((generation, Instant::now())));
        generation
    }

    /// The tracer built for the current generation by [`Self::start_build`], once, when it is
    /// ready; `None` before, after it was taken, and for superseded builds.
    pub fn take_built(&self) -> Option<Arc<Tracer>> {
        let mut slot = crate::sync::lock(&self.built);
        match slot.take() {
            Some((generation, tracer)) if generation == self.generation() => {
                self.building.set(None);
                Some(tracer)
            }
            _ => None,
        }
    }

    /// How long the current generation's accelerator has been building, while it is (until
    /// [`Self::take_built`] hands it out).
    pub fn building_for(&self) -> Option<std::time::Duration> {
        match self.building.get() {
            Some((generation, since)) if generation == self.generation() => Some(since.elapsed()),
            _ => None,
        }
    }

    fn spawn(
        &mut self,
        source: Source,
        view: Option<View>,
        target: u32,
        focus: Option<(f32, f32)>,
    ) -> u64 {
        let generation = self.stop();
        self.start_failure.set(None);
        self.building.set(None);
        self.stats = Arc::new(LiveStats::default());
        let current = self.generation.clone();
        let sender = self.sender.clone();
        let stats = self.stats.clone();
        let tile_hook = self.tile_hook.clone();
        let step_hook = self.step_hook.clone();
        let built = self.built.clone();
        let pool = self.pool.clone();
        // The coordinator runs on its own thread so the UI never waits; it builds the
        // accelerator if asked, only hands passes to the pool and stops as soon as the
        // generation moves on.
        let coordinator = move || {
            let step = |step| {
                if let Some(hook) = &step_hook {
                    hook(generation, step);
                }
            };
            let generate = || {
                let tracer = match source {
                    Source::Ready(tracer) => tracer,
                    Source::Build(scene, settings) => {
                        step(Step::Building);
                        match catch_unwind(AssertUnwindSafe(|| Tracer::new(scene, settings))) {
                            Ok(tracer) => {
                                let tracer = Arc::new(tracer);
                                let mut slot = crate::sync::lock(&built);
                                // Superseded while building: the result is dropped here.
                                if current.load(Ordering::SeqCst) != generation {
                                    return;
                                }
                                *slot = Some((generation, tracer.clone()));
                                tracer
                            }
                            Err(panic) => {
                                let message = panic_message(panic.as_ref());
                                let _ = sender.send(SessionEvent::Failed {
                                    generation,
                                    message: format!("building the accelerator failed: {message}"),
                                });
                                return;
                            }
                        }
                    }
                };
                let view = view.unwrap_or_else(|| View {
                    camera: tracer.scene.camera.clone(),
                    width: tracer.scene.render.width,
                    height: tracer.scene.render.height,
                });
                let job = Job {
                    tracer,
                    view,
                    target: target.max(1),
                    focus,
                    generation,
                    current,
                    failed: AtomicBool::new(false),
                    sender,
                    stats,
                    tile_hook,
                };
                job.run();
            };
            generate();
            step(Step::Done);
        };
        let spawned = match &self.spawn_hook {
            Some(hook) => hook(),
            None => Ok(()),
        }
        .and_then(|()| {
            std::thread::Builder::new()
                .name(format!("raytree-render-{generation}"))
                .spawn(move || pool.install(coordinator))
        });
        // Without its thread the generation would wait for tiles forever: say so instead.
        if let Err(e) = spawned {
            self.start_failure.set(Some(SessionEvent::Failed {
                generation,
                message: format!("cannot start the render thread: {e}"),
            }));
        }
        generation
    }

    /// Events of older generations that arrived after a restart and were dropped.
    pub fn stale_dropped(&self) -> u64 {
        self.stale_dropped.get()
    }

    /// The next event of `generation`, if one is waiting and `since` is less than `budget` ago:
    /// the UI's per-frame loop, which must leave time to draw.
    pub fn next_within(
        &self,
        generation: u64,
        since: Instant,
        budget: std::time::Duration,
    ) -> Option<SessionEvent> {
        while since.elapsed() < budget {
            let event = self.try_next()?;
            if event.generation() == generation {
                return Some(event);
            }
        }
        None
    }

    /// The next event, if one is waiting; stale generations are dropped here too.
    pub fn try_next(&self) -> Option<SessionEvent> {
        if let Some(ev) = self.start_failure.take() {
            if ev.generation() == self.generation() {
                return Some(ev);
            }
            self.stale_dropped.set(self.stale_dropped.get() + 1);
        }
        loop {
            match self.receiver.try_recv() {
                Ok(ev) if ev.generation() == self.generation() => return Some(ev),
                Ok(_) => self.stale_dropped.set(self.stale_dropped.get() + 1),
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return None,
            }
        }
    }
}

/// Where the coordinator leaves a built tracer, with its generation.
type BuiltSlot = Mutex<Option<(u64, Arc<Tracer>)>>;

/// A camera and an image size to render a scene through, other than its own.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
}

/// What a generation renders: a tracer, or a scene whose tracer is built first.
enum Source {
    Ready(Arc<Tracer>),
    Build(Arc<Scene>, TraceSettings),
}

fn build_pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("raytree-worker-{i}"))
        .build()
        .map_err(|e| format!("cannot start {threads} render threads: {e}"))
}

struct Job {
    tracer: Arc<Tracer>,
    /// The camera and size rendered (the scene's own, or the scene view's).
    view: View,
    target: u32,
    focus: Option<(f32, f32)>,
    generation: u64,
    current: Arc<AtomicU64>,
    failed: AtomicBool,
    sender: SyncSender<SessionEvent>,
    stats: Arc<LiveStats>,
    tile_hook: Option<Arc<TileHook>>,
}

impl Job {
    fn stale(&self) -> bool {
        self.current.load(Ordering::Relaxed) != self.generation
            || self.failed.load(Ordering::Relaxed)
    }

    fn send(&self, ev: SessionEvent) {
        // The receiver lives as long as the session; a send error means the viewer is gone.
        if self.sender.send(ev).is_err() {
            self.failed.store(true, Ordering::Relaxed);
        }
    }

    fn run(&self) {
        let start = Instant::now();
        let (w, h) = (self.view.width, self.view.height);
        let frame = CameraFrame::new(&self.view.camera, w, h);
        let mut order = tiles(w, h, TILE_SIZE);
        if let Some((fx, fy)) = self.focus {
            let dist = |r: &Rect| {
                let dx = r.x as f32 + r.width as f32 * 0.5 - fx;
                let dy = r.y as f32 + r.height as f32 * 0.5 - fy;
                dx * dx + dy * dy
            };
            order.sort_by(|a, b| dist(a).total_cmp(&dist(b)));
        }
        let sums: Vec<Mutex<Vec<Vec3>>> = order
            .iter()
            .map(|r| Mutex::new(vec![Vec3::ZERO; (r.width * r.height) as usize]))
            .collect();

        self.pass(&order, Pass::Preview, |rect, _| {
            self.preview_tile(&frame, rect)
        });
        for batch in sample_batches(self.target) {
            if self.stale() {
                return;
            }
            let pass = Pass::Samples(batch.end);
            self.stats.pixels_done.store(0, Ordering::Relaxed);
            self.pass(&order, pass, |rect, i| {
                let mut tile_sums = crate::sync::lock(&sums[i]);
                let mut counts = RayCounts::default();
                let mut aux = (batch.start == 0).then(Vec::new);
                accumulate_tile(
                    &self.tracer,
                    &frame,
                    rect,
                    batch.clone(),
                    &mut tile_sums,
                    &mut counts,
                    aux.as_mut(),
                );
                self.stats.add(&counts);
                let n = batch.end as f32;
                (tile_sums.iter().map(|s| *s / n).collect(), aux)
            });
        }
        if !self.stale() {
            self.send(SessionEvent::Finished {
                generation: self.generation,
                secs: start.elapsed().as_secs_f64(),
            });
        }
    }

    /// Runs one pass over all tiles in parallel, sending each finished tile.
    fn pass(
        &self,
        order: &[Rect],
        pass: Pass,
        work: impl Fn(Rect, usize) -> (Vec<Vec3>, Option<Vec<SampleInfo>>) + Sync,
    ) {
        // One task per tile: left to rayon's adaptive splitting, a worker that has not been
        // stolen from runs a quarter of the tiles as one sequential piece, and the other
        // worker, out of pieces to steal, waited for it (70 of the 1-spp pass's 195 ms idle
        // at 1280×720 on 2 threads).
        order
            .par_iter()
            .enumerate()
            .with_max_len(1)
            .for_each(|(i, &rect)| {
                if self.stale() {
                    return;
                }
                match catch_unwind(AssertUnwindSafe(|| {
                    if let Some(hook) = &self.tile_hook {
                        hook(pass, rect);
                    }
                    work(rect, i)
                })) {
                    Ok((pixels, aux)) => {
                        if self.stale() {
                            return;
                        }
                        self.stats
                            .pixels_done
                            .fetch_add(pixels.len() as u64, Ordering::Relaxed);
                        self.send(SessionEvent::Tile(TileUpdate {
                            generation: self.generation,
                            pass,
                            rect,
                            pixels,
                            aux,
                        }));
                    }
                    Err(panic) => {
                        let message = panic_message(panic.as_ref());
                        if !self.failed.swap(true, Ordering::Relaxed) {
                            self.send(SessionEvent::Failed {
                                generation: self.generation,
                                message: format!(
                                    "a render worker failed on the tile at ({}, {}): {message}",
                                    rect.x, rect.y
                                ),
                            });
                        }
                    }
                }
            });
        if !self.stale() {
            self.send(SessionEvent::PassDone {
                generation: self.generation,
                pass,
            });
        }
    }

    /// One centre sample per 8×8 block, copied to the whole block (packets of neighbouring
    /// blocks: [`super::preview_tile`]).
    fn preview_tile(
        &self,
        frame: &CameraFrame,
        rect: Rect,
    ) -> (Vec<Vec3>, Option<Vec<SampleInfo>>) {
        let mut counts = RayCounts::default();
        let (pixels, aux) =
            super::preview_tile(&self.tracer, frame, rect, PREVIEW_BLOCK, &mut counts);
        self.stats.add(&counts);
        // The image modes get the preview too, so a mode view never shows render colours.
        (pixels, Some(aux))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_double_up_to_target() {
        assert_eq!(sample_batches(1), vec![0..1]);
        assert_eq!(sample_batches(5), vec![0..1, 1..2, 2..4, 4..5]);
        assert_eq!(sample_batches(8).last(), Some(&(4..8)));
    }
}
