//! Another scene comes in: a file opened or reloaded after a save in the background (read,
//! parsed and built off the UI thread by [`super::opening`]), or a built-in scene, and what
//! installing it does to the other parts.

use std::path::{Path, PathBuf};

use super::messages::Message;
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
            let label = path.display().to_string();
            self.messages
                .push(opened_message(&edit, &label, Some(reloaded)));
            // The camera as it is now (it may have moved while the file was read), the
            // accelerator shown kept: rendered as any edit is.
            let camera = self.working.scene.camera.clone();
            self.working.scene = edit;
            self.working.scene.camera = camera;
            self.files.learn(timings);
            self.files.watch(&self.working.scene, &mut self.messages);
            self.restart(false, Reach::RenderAndSceneView);
            return;
        }
        let said = (kind == OpenKind::Reload).then_some(reloaded);
        self.replace_scene(edit, path.display().to_string(), said);
        if let Some(message) = fit.message {
            self.messages.error(message);
        }
        self.render.scene_size = fit.scene;
        self.files.learn(timings);
        self.files.watch(&self.working.scene, &mut self.messages);
        self.render.pending_build = None;
        self.start_generation(tracer, Reach::RenderAndSceneView);
        // The open was fitted and framed for the pane as it was when it began: none yet for a
        // file named on the command line (opened before the window's first frame), or another
        // one if the window was resized while the file loaded. For the pane as it is now, or
        // once its size is known (the restart the pane's first size starts).
        let pane = self.render.pane(&self.workspace.prefs);
        let fitted = opening::fit_render(self.render.scene_size, pane, self.render.max_side);
        let for_another = fitted.render != self.render.size();
        self.frame_on_pane = pane.is_none() || for_another;
        if pane.is_some() && for_another {
            self.restart(false, Reach::RenderAndSceneView);
        }
    }

    /// Makes `s` the working copy, named `label`: nothing of the old scene stays picked, the
    /// scene view frames the new one, and the history starts over. One message says so
    /// ([`opened_message`]; `said` is its sentence instead of the scene's summary).
    pub(super) fn replace_scene(&mut self, s: Scene, label: String, said: Option<String>) {
        self.messages.push(opened_message(&s, &label, said));
        self.working.scene = s;
        self.working.history = undo::History::default();
        self.files.label = label;
        self.selection.clear();
        self.scene_view.unframe();
    }
}

/// The one message of an open: "kitchen.obj: 57k triangles, 30 materials, 1 light; 5 notes",
/// the loader's notes behind it as details. A scene without notes from a built-in name says
/// nothing more than the window's title does, but still one line, so every open is logged.
pub(super) fn opened_message(scene: &Scene, label: &str, said: Option<String>) -> Message {
    use crate::plural::{count, count_short};
    let name = std::path::Path::new(label)
        .file_name()
        .map_or(label.to_string(), |n| n.to_string_lossy().into_owned());
    let mut parts = Vec::new();
    if !scene.triangles.is_empty() {
        parts.push(count_short(scene.triangles.len() as u64, "triangle"));
    }
    if !scene.spheres.is_empty() {
        parts.push(count(scene.spheres.len() as u64, "sphere"));
    }
    parts.push(count(scene.materials.len() as u64, "material"));
    parts.push(count(scene.lights.len() as u64, "light"));
    let mut text = said.unwrap_or_else(|| format!("opened {name}: {}", parts.join(", ")));
    if !scene.warnings.is_empty() {
        text.push_str(&format!("; {}", count(scene.warnings.len() as u64, "note")));
    }
    Message::notice(text).with_details(scene.warnings.clone())
}
