//! Another scene comes in: a file opened or reloaded after a save in the background (read,
//! parsed and built off the UI thread by [`super::opening`]), or a built-in scene, and what
//! installing it does to the other parts.

use std::path::{Path, PathBuf};

use super::opening::{self, OpenKind};
use super::render_view::Reach;
use super::{ViewerApp, undo};
use crate::scene::Scene;

impl ViewerApp {
    /// True while a saved change waits for its reload (the UI keeps polling).
    pub fn reload_pending(&self) -> bool {
        self.files.reload_pending()
    }

    /// Opens `path` (or reloads it after a save) in the background: read, parse and
    /// build off the UI thread, the scene shown staying up until the new one is ready. Cancels
    /// an open already under way (its result is never installed). A reload of the same
    /// geometry keeps the camera (as moved in the viewer), the trees and the accelerator.
    pub(super) fn start_open(&mut self, path: PathBuf, kind: OpenKind) {
        let request = opening::Request {
            path,
            settings: self.working.settings.trace,
            pane: self.render.pane(&self.workspace.prefs),
            max_side: self.render.max_side,
            reload: (kind == OpenKind::Reload).then(|| {
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
    pub(super) fn poll_open(&mut self) {
        let Some((job, outcome)) = self.files.take_finished() else {
            return;
        };
        match outcome {
            opening::Outcome::Opened(opened) => self.install_opened(&job.path, job.kind, *opened),
            // The message names the file, place and field; the old scene stays.
            opening::Outcome::Failed(e) if job.kind == OpenKind::Reload => self.messages.error(
                format!("{e} (after a save; the last good scene stays until the file loads again)"),
            ),
            opening::Outcome::Failed(e) => {
                self.messages.error(e);
                // The scene shown is watched again.
                self.files.watch(&self.working.scene, &mut self.messages);
            }
        }
    }

    /// Makes an opened (or reloaded) scene the one shown and rendered.
    fn install_opened(&mut self, path: &Path, kind: OpenKind, opened: opening::Opened) {
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
        if kind == OpenKind::Reload {
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

    /// Makes `s` the working copy, named `label`: nothing of the old scene stays picked, the
    /// scene view frames the new one, and the history starts over.
    pub(super) fn replace_scene(&mut self, s: Scene, label: String) {
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
