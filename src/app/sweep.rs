//! The "Speed vs accuracy" window: runs the sweep of `experiments::sweep` on the current scene
//! in a background thread (progress, cancel), plots error against time on log axes with
//! `egui_plot` (ticks in milliseconds and mean FLIP, not logarithms), one series per knob and the
//! Pareto front as a staircase, labels a hovered point with its setting, time and error, and
//! applies a point's settings when it is clicked, saying what changed (old -> new).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Mutex};

use eframe::egui::{self, Color32, Ui};
use egui_plot::{GridInput, GridMark, HoverPosition, Legend, Line, Plot, PlotPoints, Points};

use crate::choice::Choice;
use crate::experiments::measure::{BenchError, BenchProgress};
use crate::experiments::pareto::staircase;
use crate::experiments::sweep::{
    BenchOptions, BenchPoint, BenchReport, Knob, PointSettings, run_sweep,
};
use crate::scene::Scene;
use crate::trace::TraceSettings;

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
    /// What the last applied point changed ("max depth 5 -> 2"), shown until the next apply.
    pub applied: Option<String>,
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

/// The plot's floor: an error of zero is drawn at this mean FLIP.
const FLOOR: f64 = 1e-6;

/// Log10 of a positive value, with zero errors drawn at the plot's floor.
fn log(v: f64) -> f64 {
    v.max(FLOOR).log10()
}

/// A time in seconds as people read it: "0.42 ms", "12 ms", "1.5 s".
pub fn format_secs(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.2} ms", s * 1e3)
    } else if s < 1.0 {
        format!("{} ms", round3(s * 1e3))
    } else {
        format!("{} s", round3(s))
    }
}

/// A mean FLIP (0: the same image as the reference, 1: as different as can be).
pub fn format_flip(e: f64) -> String {
    if e <= FLOOR {
        "0 (same as reference)".to_string()
    } else if e < 1e-3 {
        format!("{e:.1e}")
    } else {
        round3(e)
    }
}

/// Three significant digits, without trailing zeros.
fn round3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.digits$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// Grid marks on a log10 axis at 1, 2 and 5 times each power of ten (decades thicker); only
/// the decades when the range spans more than four of them.
pub fn log_ticks(input: GridInput) -> Vec<GridMark> {
    let (lo, hi) = input.bounds;
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo || hi - lo > 40.0 {
        return Vec::new();
    }
    let fine = hi - lo <= 4.0;
    let mut marks = Vec::new();
    for k in (lo.floor() as i64)..=(hi.ceil() as i64) {
        let k = k as f64;
        marks.push(GridMark {
            value: k,
            step_size: 1.0,
        });
        if fine {
            for m in [2f64, 5.0] {
                marks.push(GridMark {
                    value: k + m.log10(),
                    step_size: 0.3,
                });
            }
        }
    }
    marks.retain(|m| m.value >= lo && m.value <= hi);
    marks
}

/// The knob's setting of a point, as the settings panel names it: "samples = 4".
pub fn setting_text(p: &BenchPoint) -> String {
    let name = match p.knob {
        Knob::MaxDepth => "max depth",
        Knob::Samples => "samples",
        Knob::Cutoff => "weight cutoff",
        Knob::Sphere => "sphere method",
        Knob::Triangle => "triangle method",
        Knob::Offset => "offset method",
        Knob::Accel => "accelerator",
    };
    format!("{name} = {}", p.value)
}

/// The hover label of a point: its setting, time and error.
pub fn point_label(p: &BenchPoint) -> String {
    format!(
        "{}\ntime {} per image\nmean FLIP {}{}",
        setting_text(p),
        format_secs(p.secs),
        format_flip(p.error.mean_flip),
        if p.pareto {
            "\non the Pareto front"
        } else {
            ""
        }
    )
}

/// What applying `to` changes from the viewer's `max_depth`, `samples` and `trace`, as
/// "max depth 5 -> 2, samples 16 -> 4" (or says nothing changed).
pub fn change_text(
    max_depth: u32,
    samples: u32,
    trace: &TraceSettings,
    to: &PointSettings,
) -> String {
    let mut parts = Vec::new();
    let mut diff = |name: &str, a: String, b: String| {
        if a != b {
            parts.push(format!("{name} {a} -> {b}"));
        }
    };
    diff("max depth", max_depth.to_string(), to.max_depth.to_string());
    diff("samples", samples.to_string(), to.samples.to_string());
    diff(
        "weight cutoff",
        trace.cutoff.to_string(),
        to.trace.cutoff.to_string(),
    );
    diff(
        "sphere",
        trace.methods.sphere.name().into(),
        to.trace.methods.sphere.name().into(),
    );
    diff(
        "triangle",
        trace.methods.triangle.name().into(),
        to.trace.methods.triangle.name().into(),
    );
    diff(
        "offset",
        trace.methods.offset.name().into(),
        to.trace.methods.offset.name().into(),
    );
    diff(
        "accelerator",
        trace.accel.name().into(),
        to.trace.accel.name().into(),
    );
    if parts.is_empty() {
        "applied: nothing changed (the viewer already uses these settings)".to_string()
    } else {
        format!("applied: {}", parts.join(", "))
    }
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

    /// Draws the window; returns the settings of a clicked point, to apply (`max_depth`,
    /// `samples` and `trace`: the viewer's settings now, for the confirmation of what changed).
    pub fn show(
        &mut self,
        ctx: &egui::Context,
        scene: &Scene,
        trace: &TraceSettings,
    ) -> Option<PointSettings> {
        self.poll();
        let mut open = self.open;
        let mut chosen = None;
        // Opened at the right, away from the settings panel on the left that a point changes.
        let screen = ctx.content_rect();
        egui::Window::new("Speed vs accuracy")
            .open(&mut open)
            .pivot(egui::Align2::RIGHT_TOP)
            .default_pos(screen.right_top() + egui::vec2(-12.0, 48.0))
            .default_size([600.0, 460.0])
            .show(ctx, |ui| chosen = self.contents(ui, ctx, scene));
        self.open = open;
        if let Some(p) = &chosen {
            self.applied = Some(change_text(
                scene.render.max_depth,
                scene.render.samples,
                trace,
                p,
            ));
        }
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
                if ui
                    .button("Run the sweep")
                    .on_hover_text("render the scene once per setting of each knob, measuring time and error against a converged reference")
                    .clicked()
                {
                    self.start(scene, ctx);
                }
                ui.checkbox(&mut self.quick, "quick (96×72)")
                    .on_hover_text("a tiny image: answers in seconds, noisier numbers");
            }
        });
        if let Some(e) = &self.error {
            ui.colored_label(Color32::LIGHT_RED, e);
        }
        if let Some(text) = &self.applied {
            ui.colored_label(Color32::from_rgb(120, 230, 140), text);
        }
        let Some(report) = &self.report else {
            ui.label("Renders the scene once per setting of each knob and plots error (mean FLIP against a converged reference) against time. Click a point to use its settings.");
            return None;
        };
        ui.label("Error against time per image, both on log scales; the white staircase is the Pareto front (no other setting is both faster and more accurate). Settings that show the scene's own image count once, at the median of their times (the diamond). Hover a point for its setting, click it to apply it.");
        let mut chosen = None;
        let label = |pos: &HoverPosition<'_>| -> Option<String> {
            match pos {
                HoverPosition::NearDataPoint {
                    plot_name,
                    position,
                    ..
                } => {
                    if *plot_name == BASELINE_MARK {
                        return Some(format!(
                            "{} settings show the scene's own image;\nthey count once, at the median of their times:\ntime {}\nmean FLIP {}",
                            report
                                .points
                                .iter()
                                .filter(|p| crate::experiments::pareto::same_image(*p))
                                .count(),
                            format_secs(10f64.powf(position.x)),
                            format_flip(10f64.powf(position.y))
                        ));
                    }
                    let hit = report.points.iter().find(|p| {
                        (plot_name == &p.knob.name() || *plot_name == "Pareto front")
                            && (log(p.secs) - position.x).abs() < 1e-9
                            && (log(p.error.mean_flip) - position.y).abs() < 1e-9
                    });
                    Some(match hit {
                        Some(p) => point_label(p),
                        None => format!(
                            "{plot_name}\ntime {}\nmean FLIP {}",
                            format_secs(10f64.powf(position.x)),
                            format_flip(10f64.powf(position.y))
                        ),
                    })
                }
                HoverPosition::Elsewhere { position } => Some(format!(
                    "time {}\nmean FLIP {}",
                    format_secs(10f64.powf(position.x)),
                    format_flip(10f64.powf(position.y))
                )),
            }
        };
        Plot::new("sweep")
            .legend(Legend::default().position(legend_corner(report)))
            .x_axis_label("time per image (log scale)")
            .y_axis_label("mean FLIP error (log scale)")
            .x_grid_spacer(log_ticks)
            .y_grid_spacer(log_ticks)
            .x_axis_formatter(|m, _| format_secs(10f64.powf(m.value)))
            .y_axis_formatter(|m, _| format_flip(10f64.powf(m.value)))
            .label_formatter(label)
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
                let front: Vec<[f64; 2]> = front_points(report);
                // No bands: egui_plot merges points of equal x (the staircase's risers) into a
                // filled band, which drew the front as a wedge.
                plot.line(
                    Line::new("Pareto front", PlotPoints::from(staircase(&front)))
                        .color(Color32::WHITE)
                        .allow_band(false),
                );
                // The settings that show the baseline's image stand on the front as one point at
                // the median of their times: mark where.
                if let Some(at) = baseline_mark(report) {
                    plot.points(
                        Points::new(BASELINE_MARK, PlotPoints::from(vec![at]))
                            .shape(egui_plot::MarkerShape::Diamond)
                            .filled(false)
                            .radius(7.0)
                            .color(Color32::WHITE),
                    );
                }
                if plot.response().clicked()
                    && let Some(at) = plot.pointer_coordinate()
                {
                    let b = plot.plot_bounds();
                    chosen = nearest_point(report, [at.x, at.y], [b.width(), b.height()]);
                }
            });
        chosen
    }
}

/// The corner of the plot where its legend (about 0.4 of the plot's width and 0.55 of its
/// height, with the nine series' names) covers the fewest points.
fn legend_corner(report: &BenchReport) -> egui_plot::Corner {
    use crate::experiments::chart::{Corner, emptiest_corner};
    let pts: Vec<[f64; 2]> = report
        .points
        .iter()
        .map(|p| [log(p.secs), log(p.error.mean_flip)])
        .filter(|p| p[0].is_finite() && p[1].is_finite())
        .collect();
    let span = |k: usize| {
        let lo = pts.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
        // The plot's own margin about its data, as egui_plot bounds it.
        let pad = 0.05 * (hi - lo).max(1e-9);
        (lo - pad, hi + pad)
    };
    let ((x0, x1), (y0, y1)) = (span(0), span(1));
    let shares: Vec<(f64, f64)> = pts
        .iter()
        .map(|p| ((p[0] - x0) / (x1 - x0), (p[1] - y0) / (y1 - y0)))
        .collect();
    match emptiest_corner(&shares, (0.4, 0.55)) {
        Corner::UpperRight => egui_plot::Corner::RightTop,
        Corner::UpperLeft => egui_plot::Corner::LeftTop,
        Corner::LowerRight => egui_plot::Corner::RightBottom,
        Corner::LowerLeft => egui_plot::Corner::LeftBottom,
    }
}

/// The series of the baseline image's place on the front.
const BASELINE_MARK: &str = "baseline image (median time)";

/// Where the front places the settings that show the baseline's image, if they are on it.
fn baseline_mark(report: &BenchReport) -> Option<[f64; 2]> {
    report
        .pareto_front()
        .into_iter()
        .find(|&i| crate::experiments::pareto::same_image(&report.points[i]))
        .map(|i| {
            [
                log(report.front_secs(i)),
                log(report.points[i].error.mean_flip),
            ]
        })
}

/// The front's points in plot coordinates, fastest first, each at the time the front ranks it by
/// ([`BenchReport::front_secs`]): time rises and error falls along it.
pub fn front_points(report: &BenchReport) -> Vec<[f64; 2]> {
    report
        .pareto_front()
        .into_iter()
        .map(|i| {
            [
                log(report.front_secs(i)),
                log(report.points[i].error.mean_flip),
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_and_errors_read_as_units() {
        assert_eq!(format_secs(0.0123), "12.3 ms");
        assert_eq!(format_secs(0.5), "500 ms");
        assert_eq!(format_secs(2.0), "2 s");
        assert_eq!(format_secs(0.0002), "0.20 ms");
        assert_eq!(format_flip(0.05), "0.05");
        assert_eq!(format_flip(0.0), "0 (same as reference)");
    }

    #[test]
    fn log_ticks_fall_on_one_two_five() {
        let marks = log_ticks(GridInput {
            bounds: (-2.5, 0.1),
            base_step_size: 0.01,
        });
        let values: Vec<String> = marks
            .iter()
            .map(|m| format_secs(10f64.powf(m.value)))
            .collect();
        assert_eq!(
            values,
            vec![
                "5 ms", "10 ms", "20 ms", "50 ms", "100 ms", "200 ms", "500 ms", "1 s"
            ]
        );
    }

    #[test]
    fn the_change_names_old_and_new() {
        let trace = TraceSettings::default();
        let to = PointSettings {
            max_depth: 2,
            samples: 4,
            trace,
        };
        assert_eq!(change_text(5, 4, &trace, &to), "applied: max depth 5 -> 2");
        assert!(change_text(2, 4, &trace, &to).contains("nothing changed"));
    }
}
