//! The open scene's files: its label, the watch on its files for saves, the open (or reload)
//! under way in the background, and the rates the last open measured for the next one's
//! progress.

use std::path::Path;
use std::sync::Arc;

use super::messages::Messages;
use super::opening::{OpenHook, OpenJob, OpenStage, Outcome, Rates, Request, Timings};
use super::watch::{self, SceneWatch};
use crate::scene::Scene;

pub struct SceneFiles {
    /// What the scene is called: its path, or a built-in scene's name.
    pub label: String,
    /// The open scene's files, watched for saves (`None` for built-in scenes).
    watch: Option<SceneWatch>,
    /// A file being opened (or reloaded) in the background; the scene shown stays until it
    /// is ready.
    job: Option<OpenJob>,
    /// Called by background opens at each stage (the tests hold an open with it).
    hook: Option<Arc<OpenHook>>,
    /// Wakes the UI when a watched file changes.
    waker: Option<watch::Waker>,
    /// Rates of the stages of the last open, for the next one's progress estimate.
    rates: Rates,
    /// Times of the last open, for the record (benchmarks print them).
    pub last_open: Option<Timings>,
}

impl SceneFiles {
    pub fn new(label: String) -> Self {
        Self {
            label,
            watch: None,
            job: None,
            hook: None,
            waker: None,
            rates: Rates::default(),
            last_open: None,
        }
    }

    /// Watches the files of `scene` (see [`watch`]), or nothing for a built-in scene.
    pub fn watch(&mut self, scene: &Scene, messages: &mut Messages) {
        self.watch = None;
        let Some(source) = scene.source.clone() else {
            return;
        };
        match SceneWatch::new(&watch::scene_files(scene, &source), self.waker.clone()) {
            Ok(w) => self.watch = Some(w),
            Err(e) => messages.notice(e),
        }
    }

    /// Stops watching (a built-in scene, or another file being opened).
    pub fn unwatch(&mut self) {
        self.watch = None;
    }

    pub fn is_watched(&self) -> bool {
        self.watch.is_some()
    }

    /// Sets what wakes the UI when a watched file changes (taking effect at the next watch;
    /// the scene watched now is watched again with it).
    pub fn wake_with(&mut self, waker: watch::Waker, scene: &Scene, messages: &mut Messages) {
        self.waker = Some(waker);
        if self.watch.is_some() {
            self.watch(scene, messages);
        }
    }

    /// What wakes the UI (a no-op before the window's first frame, and without a window).
    pub fn waker(&self) -> watch::Waker {
        self.waker.clone().unwrap_or_else(|| Arc::new(|| {}))
    }

    pub fn has_waker(&self) -> bool {
        self.waker.is_some()
    }

    /// True while a saved change waits for its reload.
    pub fn reload_pending(&self) -> bool {
        self.reload_in().is_some()
    }

    /// When the saved change waiting for its reload settles (`None`: none waits).
    pub fn reload_in(&self) -> Option<std::time::Duration> {
        self.watch.as_ref().and_then(SceneWatch::settles_in)
    }

    /// Whether the watched files were saved and have settled: time to reload.
    pub fn saved(&mut self) -> bool {
        self.watch.as_mut().is_some_and(SceneWatch::poll)
    }

    /// Starts the open of `request` in the background, cancelling one already under way (its
    /// result is never installed). On failure the error is said and `shown` is watched again.
    pub fn start(&mut self, mut request: Request, shown: &Scene, messages: &mut Messages) {
        self.cancel();
        if request.reload.is_none() {
            // The old scene's saves must not reload it over the file being opened.
            self.watch = None;
        }
        request.hook = self.hook.clone();
        match OpenJob::start(request) {
            Ok(job) => self.job = Some(job),
            Err(e) => {
                messages.error(e);
                self.watch(shown, messages);
            }
        }
    }

    /// Cancels the open under way, if any.
    pub fn cancel(&mut self) {
        if let Some(job) = self.job.take() {
            job.cancel();
        }
    }

    /// Esc: cancels the open under way, saying so; `shown` stays (and is watched again).
    pub fn stop(&mut self, shown: &Scene, messages: &mut Messages) {
        if let Some(job) = self.job.take() {
            job.cancel();
            messages.notice(format!("stopped opening {}", job.path.display()));
            self.watch(shown, messages);
        }
    }

    /// Sets (or with `None` removes) the hook every background open calls at each stage, on
    /// its thread; takes effect at the next open.
    pub fn set_hook(&mut self, hook: Option<Arc<OpenHook>>) {
        self.hook = hook;
    }

    /// The open under way, if any.
    pub fn job(&self) -> Option<&OpenJob> {
        self.job.as_ref()
    }

    /// The file being opened in the background, if any.
    pub fn opening(&self) -> Option<&Path> {
        self.job.as_ref().map(|j| j.path.as_path())
    }

    /// What the status bar says of the open under way, and its percentage (below 100 until
    /// the new scene is installed): "loading FILE… n %", then "building BVH… n %".
    pub fn status(&mut self) -> Option<(String, f32)> {
        let rates = self.rates;
        let job = self.job.as_mut()?;
        let percent = job.percent(&rates);
        let name = job
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let label = match job.stage() {
            OpenStage::Read | OpenStage::Parse => format!("loading {name}… {percent:.0} %"),
            OpenStage::Build | OpenStage::Ready => format!("building BVH… {percent:.0} %"),
        };
        Some((label, percent))
    }

    /// The finished open and its outcome, when it is ready.
    pub fn take_finished(&mut self) -> Option<(OpenJob, Outcome)> {
        let outcome = self.job.as_ref().and_then(OpenJob::try_take)?;
        Some((self.job.take()?, outcome))
    }

    /// Notes the times of a finished open, for the next one's estimate.
    pub fn learn(&mut self, timings: Timings) {
        self.rates.learn(&timings);
        self.last_open = Some(timings);
    }

    /// Estimated seconds to build an accelerator over `triangles`, at this run's rate.
    pub fn build_secs(&self, triangles: u64) -> f64 {
        self.rates.build_secs(triangles)
    }

    /// The scene's name as a file stem, for the names the file dialogs offer.
    pub fn file_stem(&self) -> String {
        Path::new(&self.label)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("render")
            .to_string()
    }
}
