//! What the viewer writes to files: the scene as TOML, the render (at the size shown, or at
//! the scene's own size in the background), the render with the trees drawn over it, the
//! scene view, and the ray tree as JSON or as its SVG figure.

use std::path::Path;
use std::sync::Arc;

use super::ViewerApp;
use super::messages::Message;
use super::render_view::ExportJob;
use crate::export;
use crate::scene;
use crate::scene_view::headless::Layer;
use crate::trace::Tracer;

/// A picture drawn with the trees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Drawn {
    /// The render with the trees drawn over it, as in the render view.
    Overlay,
    /// The scene view's camera at the scene's size.
    SceneView,
}

impl ViewerApp {
    /// Writes the working copy as a scene file.
    pub(super) fn save_scene(&mut self, path: &Path) {
        let text = scene::scene_to_toml(&self.working.scene);
        match export::write_text(path, &text) {
            Ok(()) => self.messages.notice(format!("saved {}", path.display())),
            Err(e) => self.messages.error(e.to_string()),
        }
    }

    /// Writes the current tree as JSON.
    pub(super) fn export_tree(&mut self, path: &Path) {
        let json = self
            .selection
            .tree
            .as_ref()
            .map(|t| serde_json::to_string_pretty(t).unwrap_or_default());
        self.save_tree_text(path, json);
    }

    /// Writes the current tree's figure as SVG, to the generations shown.
    pub(super) fn export_diagram(&mut self, path: &Path) {
        let options = crate::diagram::Options {
            max_generation: self.selection.max_generation(),
        };
        let svg = self
            .selection
            .tree
            .as_ref()
            .map(|t| crate::diagram::svg(t, &options));
        self.save_tree_text(path, svg);
    }

    /// Writes the ray tree in some form (`None`: there is no tree yet).
    fn save_tree_text(&mut self, path: &Path, text: Option<String>) {
        match text.map(|text| export::write_text(path, &text)) {
            Some(Ok(())) => self.messages.notice(format!("saved {}", path.display())),
            Some(Err(e)) => self.messages.error(e.to_string()),
            None => self
                .messages
                .error("no ray tree to export: click a pixel first"),
        }
    }

    /// "As shown": the picture in the render pane, at the size it is rendered, with the samples
    /// reached so far and the camera as it is. A PNG has the display's colours (exposure,
    /// tonemap, the image mode, exactly as the shader shows them); an EXR keeps linear radiance
    /// (the film; exposure and tonemap are for display). Stamped with both.
    pub(super) fn export(&mut self, path: &Path) {
        let (w, h) = self.render.size();
        let target = self.viewer_target();
        let done = self.render.progress.samples_done;
        let mut render = self.render.scene().render.clone();
        (render.width, render.height) = (w, h);
        let mut text = export::stamp(
            &self.files.label,
            done,
            target,
            &render,
            &self.working.settings.trace,
            self.render.accel().kind(),
        );
        let prefs = &self.workspace.prefs;
        text.push((
            "raytree.display".to_string(),
            serde_json::json!({
                "exposure": prefs.exposure,
                "tonemap": prefs.tonemap.label(),
                "mode": prefs.mode.label(),
            })
            .to_string(),
        ));
        let png = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        let written = if png {
            let shown = self.render.display_shown();
            export::write_png_rgb8(path, w, h, &shown, &text)
        } else {
            export::write_image(path, &self.render.image(), &text)
        };
        match written {
            Ok(()) => self.messages.notice(format!(
                "exported {} as shown ({w}x{h}, {done}/{target} samples)",
                path.display()
            )),
            Err(e) => self.messages.error(e.to_string()),
        }
    }

    /// The scene at its own size and sample count, rendered in the background (the viewer
    /// stays live, the status bar shows the progress and can cancel it); a message says when
    /// the file is written.
    pub(super) fn export_at_scene_size(&mut self, path: &Path) {
        if self.render.export_job.is_some() {
            return self
                .messages
                .error("an export is still rendering: wait for it or cancel it in the status bar");
        }
        let mut scene = (**self.render.scene()).clone();
        (scene.render.width, scene.render.height) = self.render.scene_size;
        let (w, h) = self.render.scene_size;
        let samples = scene.render.samples;
        let trace = self.working.settings.trace;
        let stamp = export::stamp(
            &self.files.label,
            samples,
            samples,
            &scene.render,
            &trace,
            self.render.accel().kind(),
        );
        let tracer = Tracer::with_accel(Arc::new(scene), trace, self.render.tracer.accel.clone());
        let threads = self.working.settings.threads;
        let shown = path.display().to_string();
        let path = path.to_path_buf();
        let (tx, rx) = std::sync::mpsc::channel();
        let job = ExportJob::new(rx, shown.clone());
        let (progress, cancel, wake) =
            (job.progress.clone(), job.cancel.clone(), self.files.waker());
        let work = move || {
            use std::sync::atomic::Ordering;
            let report = |done: u64, total: u64| {
                let permille = (done * 1000).checked_div(total).unwrap_or(0);
                let before = progress.swap(permille, Ordering::Relaxed);
                // A frame for each whole percent, not for each tile.
                if permille / 10 != before / 10 {
                    wake();
                }
            };
            let tile = |t: &Tracer,
                        f: &crate::scene::CameraFrame,
                        r: crate::render::Rect,
                        s: std::ops::Range<u32>,
                        px: &mut [glam::Vec3]| {
                if cancel.load(Ordering::Relaxed) {
                    crate::trace::RayCounts::default()
                } else {
                    crate::render::trace_tile(t, f, r, s, px)
                }
            };
            let rendered = crate::render::render_with(&tracer, samples, threads, &report, &tile);
            let message = if cancel.load(Ordering::Relaxed) {
                Message::notice(format!("cancelled the export of {}", path.display()))
            } else {
                match rendered {
                    Ok((image, _)) => match export::write_image(&path, &image, &stamp) {
                        Ok(()) => Message::notice(format!(
                            "exported {} ({w}x{h}, the scene's size, {})",
                            path.display(),
                            crate::plural::count(samples, "sample")
                        )),
                        Err(e) => Message::error(e.to_string()),
                    },
                    Err(e) => Message::error(format!("cannot export {}: {e}", path.display())),
                }
            };
            // The viewer may have closed meanwhile: then nobody waits for the message.
            let _ = tx.send(message);
            wake();
        };
        match std::thread::Builder::new()
            .name("raytree-export".into())
            .spawn(work)
        {
            Ok(_) => self.render.export_job = Some(job),
            Err(e) => self.messages.error(format!("cannot start the export: {e}")),
        }
    }

    /// Writes `picture` as a stamped PNG, drawn by the headless scene view's rules.
    pub(super) fn export_drawn(&mut self, path: &Path, picture: Drawn) {
        if self.selection.tree.is_none() {
            self.messages
                .error("no ray tree to draw: click a pixel first");
            return;
        };
        let filter = crate::scene_view::Filter {
            max_generation: self.selection.max_generation(),
            ..self.scene_view.filter.clone()
        };
        let scene = self.render.scene().clone();
        let layers: Vec<Layer> = self
            .selection
            .layers()
            .into_iter()
            .map(|(tree, _, look, depth)| Layer {
                tree,
                look: Some(look),
                depth,
            })
            .collect();
        let drawn = if picture == Drawn::SceneView {
            let (w, h) = self.render.scene_size;
            crate::scene_view::headless::scene_view_image(
                &scene,
                self.working.settings.trace,
                &layers,
                &self.scene_view.camera,
                w,
                h,
                &filter,
                self.scene_view.cutaway,
            )
        } else {
            crate::scene_view::headless::overlay_image(
                &self.render.tracer,
                &self.render.image(),
                &layers,
                &filter,
            )
        };
        let canvas = match drawn {
            Ok(c) => c,
            Err(e) => return self.messages.error(e.to_string()),
        };
        let text = export::stamp(
            &self.files.label,
            self.render.progress.samples_done,
            scene.render.samples,
            &scene.render,
            &self.working.settings.trace,
            self.render.accel().kind(),
        );
        let (w, h) = (canvas.width(), canvas.height());
        match export::write_png_rgba8(path, w, h, canvas.rgba(), &text) {
            Ok(()) => self.messages.notice(format!("exported {}", path.display())),
            Err(e) => self.messages.error(e.to_string()),
        }
    }
}
