//! The "Speed vs accuracy" window: runs the sweep of `experiments::sweep` on the current scene
//! in a background thread (progress, cancel), plots error against time on log axes with
//! `egui_plot`, one series per knob and the Pareto front, and applies a point's settings when it
//! is clicked.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Mutex};

use eframe::egui::{self, Color32, Ui};
use egui_plot::{Legend, Line, Plot, PlotPoints, Points};

use crate::experiments::measure::{BenchError, BenchProgress};
use crate::experiments::sweep::{BenchOptions, BenchReport, Knob, PointSettings, run_sweep};
use crate::scene::Scene;

enum Message {
    Progress(BenchProgress),
    Done(Result<BenchReport, String>),
}

/// The window's state; the sweep itself runs on its own thread.
#[derive(Default)]
pub struct SweepWindow {
    pub open: bool,
    running: Option<(Arc<AtomicBool>, Receiver<Message>)>,
    progress: Option<BenchProgress>,
    pub report: Option<BenchReport>,
    error: Option<String>,
    quick: bool,
}

fn knob_color(k: Knob) -> Color32 {
    match k {
        Knob::MaxDepth => Color32::from_rgb(230, 90, 70),
        Knob::Samples => Color32::from_rgb(80, 170, 255),
        Knob::Cutoff => Color32::from_rgb(240, 180, 60),
        Knob::Sphere => Color32::from_rgb(90, 220, 120),
        Knob::Triangle => Color32::from_rgb(200, 120, 240),
        Knob::Offset => Color32::from_rgb(120, 220, 220),
        Knob::Accel => Color32::from_rgb(200, 200, 200),
    }
}

/// Log10 of a positive value, with zero errors drawn at the plot's floor.
fn log(v: f64) -> f64 {
    v.max(1e-6).log10()
}

/// The settings of the point nearest to `at` (plot coordinates: log10 seconds, log10 FLIP),
/// if it lies within 5% of the plot's `span` of it.
pub fn nearest_point(report: &BenchReport, at: [f64; 2], span: [f64; 2]) -> Option<PointSettings> {
    let (sx, sy) = (span[0].max(1e-9), span[1].max(1e-9));
    report
        .points
        .iter()
        .map(|p| {
            let dx = (log(p.secs) - at[0]) / sx;
            let dy = (log(p.error.mean_flip) - at[1]) / sy;
            (dx * dx + dy * dy, p)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .filter(|(d, _)| *d < 0.0025)
        .map(|(_, p)| p.settings)
}

impl SweepWindow {
    pub fn is_running(&self) -> bool {
        self.running.is_some()
    }

    /// Starts a sweep of `scene` in the background (a copy: edits meanwhile do not affect it).
    pub fn start(&mut self, scene: &Scene, ctx: &egui::Context) {
        if self.running.is_some() {
            return;
        }
        let cancel = Arc::new(AtomicBool::new(false));
        let (tx, rx) = channel();
        let scene = scene.clone();
        let mut opts = if self.quick {
            BenchOptions::quick()
        } else {
            BenchOptions::full()
        };
        // The window is for looking: keep the image small enough to answer in seconds.
        if !self.quick {
            opts.width = Some(scene.render.width.min(320));
            opts.height = Some(scene.render.height.min(240));
            opts.runs = 1;
        }
        let flag = cancel.clone();
        let ctx = ctx.clone();
        let spawned = std::thread::Builder::new()
            .name("raytree-sweep".into())
            .spawn(move || {
                let tx_progress = Mutex::new(tx.clone());
                let result = run_sweep(
                    &scene,
                    &opts,
                    &|p| {
                        if let Ok(tx) = tx_progress.lock() {
                            let _ = tx.send(Message::Progress(p.clone()));
                        }
                        ctx.request_repaint();
                    },
                    &flag,
                );
                let result = result.map_err(|e| match e {
                    BenchError::Cancelled => "cancelled".to_string(),
                    other => other.to_string(),
                });
                let _ = tx.send(Message::Done(result));
                ctx.request_repaint();
            });
        match spawned {
            Ok(_) => {
                self.running = Some((cancel, rx));
                self.error = None;
                self.progress = None;
            }
            Err(e) => self.error = Some(format!("cannot start the sweep: {e}")),
        }
    }

    fn poll(&mut self) {
        let Some((_, rx)) = &self.running else {
            return;
        };
        let mut done = None;
        while let Ok(m) = rx.try_recv() {
            match m {
                Message::Progress(p) => self.progress = Some(p),
                Message::Done(r) => done = Some(r),
            }
        }
        if let Some(r) = done {
            self.running = None;
            match r {
                Ok(report) => self.report = Some(report),
                Err(e) => self.error = Some(e),
            }
        }
    }

    /// Draws the window; returns the settings of a clicked point, to apply.
    pub fn show(&mut self, ctx: &egui::Context, scene: &Scene) -> Option<PointSettings> {
        self.poll();
        let mut open = self.open;
        let mut chosen = None;
        egui::Window::new("Speed vs accuracy")
            .open(&mut open)
            .default_size([640.0, 480.0])
            .show(ctx, |ui| chosen = self.contents(ui, ctx, scene));
        self.open = open;
        chosen
    }

    fn contents(
        &mut self,
        ui: &mut Ui,
        ctx: &egui::Context,
        scene: &Scene,
    ) -> Option<PointSettings> {
        ui.horizontal(|ui| {
            if let Some((cancel, _)) = &self.running {
                if ui.button("Cancel").clicked() {
                    cancel.store(true, Ordering::Relaxed);
                }
                if let Some(p) = &self.progress {
                    ui.add(
                        egui::ProgressBar::new(p.step as f32 / p.steps.max(1) as f32)
                            .desired_width(200.0)
                            .text(format!("{}/{}", p.step, p.steps)),
                    );
                    ui.label(&p.what);
                }
            } else {
                if ui.button("Run the sweep").clicked() {
                    self.start(scene, ctx);
                }
                ui.checkbox(&mut self.quick, "quick (96×72)");
            }
        });
        if let Some(e) = &self.error {
            ui.colored_label(Color32::LIGHT_RED, e);
        }
        let Some(report) = &self.report else {
            ui.label("Renders the scene once per setting of each knob and plots error (mean FLIP against a converged reference) against time. Click a point to use its settings.");
            return None;
        };
        ui.label("log10 mean FLIP against log10 seconds; the Pareto front is the white line. Click a point to apply it.");
        let mut chosen = None;
        let response = Plot::new("sweep")
            .legend(Legend::default())
            .x_axis_label("log10 seconds")
            .y_axis_label("log10 mean FLIP")
            .show(ui, |plot| {
                for knob in Knob::ALL {
                    let pts: Vec<[f64; 2]> = report
                        .points
                        .iter()
                        .filter(|p| p.knob == knob)
                        .map(|p| [log(p.secs), log(p.error.mean_flip)])
                        .collect();
                    if !pts.is_empty() {
                        plot.points(
                            Points::new(knob.name(), PlotPoints::from(pts))
                                .radius(4.0)
                                .color(knob_color(knob)),
                        );
                    }
                }
                let mut front: Vec<[f64; 2]> = report
                    .points
                    .iter()
                    .filter(|p| p.pareto)
                    .map(|p| [log(p.secs), log(p.error.mean_flip)])
                    .collect();
                front.sort_by(|a, b| a[0].total_cmp(&b[0]));
                plot.line(Line::new("Pareto front", PlotPoints::from(front)).color(Color32::WHITE));
                if plot.response().clicked()
                    && let Some(at) = plot.pointer_coordinate()
                {
                    let b = plot.plot_bounds();
                    chosen = nearest_point(report, [at.x, at.y], [b.width(), b.height()]);
                }
            });
        let _ = response;
        chosen
    }
}
