//! The speed-against-accuracy sweep (docs/speed-accuracy.md).
//!
//! [`run_sweep`] renders one scene once per setting of each knob that trades time for
//! accuracy — max depth, samples per pixel, the ray-weight cutoff, the sphere, triangle and
//! offset methods, and the accelerator — changing one knob at a time from the scene's own
//! settings (the *baseline*). Each point gets the median wall time of several runs (build +
//! render), the rays traced, and its error against a converged reference of the same scene and
//! size (many samples, deep recursion, the robust methods): mean FLIP, RMSE, PSNR and the share
//! of pixels that differ ([`super::metrics`]). Accelerators must not change the image at all;
//! every point also records how many pixels differ bit for bit from the baseline render. The
//! points no other beats in both time and error are marked ([`super::pareto`]).
//!
//! It takes a progress callback and a cancel flag and returns plain data, so the command line
//! and a viewer window (in a background thread) run the very same code; the files and lines
//! made of it are [`super::report`]'s.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::measure::{BenchError, BenchProgress, check_cancel, median, value_name};
use super::metrics::{ImageError, differing_pixels, image_error};
use super::pareto::{self, Tradeoff};
use crate::accel::AccelKind;
use crate::geometry::{Methods, OffsetMethod, SphereMethod, TriangleMethod};
use crate::render::{Image, RenderError, render};
use crate::scene::Scene;
use crate::trace::{TraceSettings, Tracer};

/// A setting that trades render time for accuracy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Knob {
    MaxDepth,
    Samples,
    Cutoff,
    Sphere,
    Triangle,
    Offset,
    Accel,
}

impl Knob {
    pub const ALL: [Knob; 7] = [
        Knob::MaxDepth,
        Knob::Samples,
        Knob::Cutoff,
        Knob::Sphere,
        Knob::Triangle,
        Knob::Offset,
        Knob::Accel,
    ];

    /// The name used in the CSV and the chart legend.
    pub fn name(self) -> &'static str {
        match self {
            Knob::MaxDepth => "max_depth",
            Knob::Samples => "samples",
            Knob::Cutoff => "cutoff",
            Knob::Sphere => "sphere",
            Knob::Triangle => "triangle",
            Knob::Offset => "offset",
            Knob::Accel => "accel",
        }
    }
}

/// Everything a point of the sweep was rendered with: apply it to reproduce the point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointSettings {
    pub max_depth: u32,
    pub samples: u32,
    pub trace: TraceSettings,
}

/// One measured point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchPoint {
    pub knob: Knob,
    /// The knob's value as text (`"5"`, `"lecture"`, `"bvh"`).
    pub value: String,
    pub settings: PointSettings,
    /// The accelerator actually built (`auto` resolved).
    pub accel_used: AccelKind,
    /// Median over the runs of build + render wall time, seconds.
    pub secs: f64,
    pub build_secs: f64,
    pub render_secs: f64,
    /// Rays traced (all kinds) in one run.
    pub rays: u64,
    pub error: ImageError,
    /// Pixels not bit-identical to the baseline render (0 for every accelerator).
    pub changed_pixels: usize,
    /// Mean FLIP against the baseline render: at most [`pareto::SAME_IMAGE_FLIP`], the point
    /// shows the baseline's image (bit differences that no one can see, e.g. depth 6 against 5).
    pub flip_vs_baseline: f64,
    /// On the Pareto front of (time, mean FLIP).
    pub pareto: bool,
}

/// The converged image every point is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ReferenceInfo {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub max_depth: u32,
    pub secs: f64,
}

/// What [`run_sweep`] measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchReport {
    pub reference: ReferenceInfo,
    /// The scene's own settings, from which one knob at a time is changed.
    pub baseline: PointSettings,
    pub points: Vec<BenchPoint>,
}

impl Tradeoff for BenchPoint {
    fn secs(&self) -> f64 {
        self.secs
    }

    fn error(&self) -> f64 {
        self.error.mean_flip
    }

    fn flip_vs_baseline(&self) -> f64 {
        self.flip_vs_baseline
    }
}

impl BenchReport {
    /// Indices of the Pareto front of time against mean FLIP, fastest first
    /// ([`pareto::pareto_front`]).
    pub fn pareto_front(&self) -> Vec<usize> {
        pareto::pareto_front(&self.points, |p| p.settings == self.baseline)
    }

    /// The time the front uses for point `i` ([`pareto::front_secs`]).
    pub fn front_secs(&self, i: usize) -> f64 {
        pareto::front_secs(&self.points, |p| p.settings == self.baseline, i)
    }

    /// The accelerator points as `(kind, pixels changed)`: every count must be 0.
    pub fn accel_changes(&self) -> Vec<(AccelKind, usize)> {
        self.points
            .iter()
            .filter(|p| p.knob == Knob::Accel)
            .map(|p| (p.settings.trace.accel, p.changed_pixels))
            .collect()
    }
}

/// What to sweep and how carefully. Ranges: `runs` 1..=15 (odd counts give a true median),
/// `reference_samples` 16..=4096, `max_depths` and `reference_max_depth` 0..=64, `samples`
/// 1..=65536, `cutoffs` in `[0, 1)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchOptions {
    /// Image size; `None` keeps the scene's.
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Timed runs per point; the median is kept.
    pub runs: usize,
    /// Worker threads; 0 uses every core.
    pub threads: usize,
    pub reference_samples: u32,
    pub reference_max_depth: u32,
    pub max_depths: Vec<u32>,
    pub samples: Vec<u32>,
    /// Cutoffs, swept at `reference_max_depth` so that the cutoff is what ends the rays.
    pub cutoffs: Vec<f32>,
}

impl BenchOptions {
    /// The full sweep that docs/speed-accuracy.md reports, at 320×240 (a few minutes on two
    /// cores): depth 0–12, 1–64 samples, 5 runs, a 256-sample reference.
    pub fn full() -> Self {
        Self {
            width: Some(320),
            height: Some(240),
            runs: 5,
            threads: 0,
            reference_samples: 256,
            reference_max_depth: 12,
            max_depths: (0..=12).collect(),
            samples: vec![1, 2, 4, 8, 16, 32, 64],
            cutoffs: vec![0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.0],
        }
    }

    /// A few seconds: a small image, one run, fewer samples.
    pub fn quick() -> Self {
        Self {
            width: Some(96),
            height: Some(72),
            runs: 1,
            reference_samples: 64,
            samples: vec![1, 2, 4, 8, 16],
            cutoffs: vec![0.5, 0.1, 0.02, 0.0],
            ..Self::full()
        }
    }
}

/// The settings of every point: one knob changed at a time from `base`.
fn sweep_points(base: &PointSettings, opts: &BenchOptions) -> Vec<(Knob, String, PointSettings)> {
    let mut out = Vec::new();
    let with = |f: &dyn Fn(&mut PointSettings)| {
        let mut s = *base;
        f(&mut s);
        s
    };
    for &d in &opts.max_depths {
        out.push((Knob::MaxDepth, d.to_string(), with(&|s| s.max_depth = d)));
    }
    for &n in &opts.samples {
        out.push((Knob::Samples, n.to_string(), with(&|s| s.samples = n)));
    }
    for &c in &opts.cutoffs {
        let s = with(&|s| {
            s.max_depth = opts.reference_max_depth;
            s.trace.cutoff = c;
        });
        out.push((Knob::Cutoff, c.to_string(), s));
    }
    for m in [SphereMethod::Lecture, SphereMethod::Robust] {
        let s = with(&|s| s.trace.methods.sphere = m);
        out.push((Knob::Sphere, value_name(&m), s));
    }
    for m in [
        TriangleMethod::Lecture,
        TriangleMethod::MollerTrumbore,
        TriangleMethod::Watertight,
    ] {
        let s = with(&|s| s.trace.methods.triangle = m);
        out.push((Knob::Triangle, value_name(&m), s));
    }
    for m in [
        OffsetMethod::Fixed,
        OffsetMethod::NormalScaled,
        OffsetMethod::ErrorBound,
    ] {
        let s = with(&|s| s.trace.methods.offset = m);
        out.push((Knob::Offset, value_name(&m), s));
    }
    for k in [AccelKind::None, AccelKind::Grid, AccelKind::Bvh] {
        out.push((Knob::Accel, value_name(&k), with(&|s| s.trace.accel = k)));
    }
    out
}

/// One timed render: the image, its build and render seconds, the rays traced and the
/// accelerator built.
struct Timed {
    image: Image,
    build_secs: f64,
    render_secs: f64,
    rays: u64,
    accel: AccelKind,
}

fn render_once(
    scene: &Arc<Scene>,
    trace: TraceSettings,
    samples: u32,
    threads: usize,
) -> Result<Timed, RenderError> {
    let tracer = Tracer::new(scene.clone(), trace);
    let (image, stats) = render(&tracer, samples, threads, &|_, _| {})?;
    Ok(Timed {
        image,
        build_secs: stats.build_secs,
        render_secs: stats.render_secs,
        rays: stats.rays.total(),
        accel: tracer.accel.kind(),
    })
}

/// The scene at the sweep's size with `max_depth`.
fn scene_with(scene: &Scene, opts: &BenchOptions, max_depth: u32) -> Arc<Scene> {
    let mut s = scene.clone();
    if let Some(w) = opts.width {
        s.render.width = w;
    }
    if let Some(h) = opts.height {
        s.render.height = h;
    }
    s.render.max_depth = max_depth;
    Arc::new(s)
}

/// Runs the speed/accuracy sweep on `scene` (see the module documentation). `progress` is
/// called before each render step; setting `cancel` stops the sweep between renders with
/// [`BenchError::Cancelled`].
pub fn run_sweep(
    scene: &Scene,
    opts: &BenchOptions,
    progress: &dyn Fn(&BenchProgress),
    cancel: &AtomicBool,
) -> Result<BenchReport, BenchError> {
    let baseline = PointSettings {
        max_depth: scene.render.max_depth,
        samples: scene.render.samples.max(1),
        trace: TraceSettings::default(),
    };
    let points = sweep_points(&baseline, opts);
    let steps = points.len() + 2;
    let runs = opts.runs.max(1);
    let say = |step: usize, what: String| progress(&BenchProgress { step, steps, what });

    check_cancel(cancel)?;
    say(0, format!("reference ({} samples)", opts.reference_samples));
    let reference_trace = TraceSettings {
        accel: AccelKind::Bvh,
        methods: Methods::default(),
        cutoff: 0.0,
    };
    let ref_scene = scene_with(scene, opts, opts.reference_max_depth);
    let start = Instant::now();
    let reference = render_once(
        &ref_scene,
        reference_trace,
        opts.reference_samples,
        opts.threads,
    )?;
    let reference_info = ReferenceInfo {
        width: ref_scene.render.width,
        height: ref_scene.render.height,
        samples: opts.reference_samples,
        max_depth: opts.reference_max_depth,
        secs: start.elapsed().as_secs_f64(),
    };

    check_cancel(cancel)?;
    say(1, "baseline".into());
    let base_scene = scene_with(scene, opts, baseline.max_depth);
    let base_image =
        render_once(&base_scene, baseline.trace, baseline.samples, opts.threads)?.image;

    let mut out = Vec::with_capacity(points.len());
    for (i, (knob, value, settings)) in points.into_iter().enumerate() {
        check_cancel(cancel)?;
        say(i + 2, format!("{} = {value}", knob.name()));
        let s = scene_with(scene, opts, settings.max_depth);
        let mut totals = Vec::with_capacity(runs);
        let mut builds = Vec::with_capacity(runs);
        let mut renders = Vec::with_capacity(runs);
        let mut last = None;
        for _ in 0..runs {
            let t = render_once(&s, settings.trace, settings.samples, opts.threads)?;
            totals.push(t.build_secs + t.render_secs);
            builds.push(t.build_secs);
            renders.push(t.render_secs);
            last = Some(t);
        }
        let Some(t) = last else { continue };
        out.push(BenchPoint {
            knob,
            value,
            settings,
            accel_used: t.accel,
            secs: median(totals),
            build_secs: median(builds),
            render_secs: median(renders),
            rays: t.rays,
            error: image_error(&reference.image, &t.image),
            changed_pixels: differing_pixels(&base_image, &t.image),
            flip_vs_baseline: image_error(&base_image, &t.image).mean_flip,
            pareto: false,
        });
    }
    let mut report = BenchReport {
        reference: reference_info,
        baseline,
        points: out,
    };
    for i in report.pareto_front() {
        report.points[i].pareto = true;
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_knob_has_points_and_only_its_own_change() {
        let base = PointSettings {
            max_depth: 5,
            samples: 1,
            trace: TraceSettings::default(),
        };
        let pts = sweep_points(&base, &BenchOptions::quick());
        for k in Knob::ALL {
            assert!(pts.iter().any(|p| p.0 == k), "{k:?}");
        }
        for (k, _, s) in &pts {
            if *k != Knob::Accel {
                assert_eq!(s.trace.accel, AccelKind::Auto, "{k:?}");
            }
        }
    }
}
