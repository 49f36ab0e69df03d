//! The speed-against-accuracy sweep (SPEC §7, STABILITY M1) and the accelerator scaling sweep.
//!
//! [`run_sweep`] renders one scene once per setting of each knob that trades time for
//! accuracy — max depth, samples per pixel, the ray-weight cutoff, the sphere, triangle and
//! offset methods, and the accelerator — changing one knob at a time from the scene's own
//! settings (the *baseline*). Each point gets the median wall time of several runs (build +
//! render), the rays traced, and its error against a converged reference of the same scene and
//! size (many samples, deep recursion, the robust methods): mean FLIP, RMSE, PSNR and the share
//! of pixels that differ ([`super::metrics`]). Accelerators must not change the image at all;
//! every point also records how many pixels differ bit for bit from the baseline render.
//!
//! [`run_scaling`] times building and rendering a tessellated sphere of 8 to 2M triangles with
//! each accelerator; [`crossovers`] finds where one becomes faster than another, which is what
//! `AccelKind::Auto` uses.
//!
//! Both take a progress callback and a cancel flag and return plain data, so the command line
//! and a viewer window (in a background thread) run the very same code.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::chart::{Chart, Series, SeriesStyle, write_chart};
use super::meshes::{octasphere, triangles};
use super::metrics::{ImageError, differing_pixels, image_error};
use crate::accel::AccelKind;
use crate::export::{ExportError, write_text};
use crate::geometry::{Methods, OffsetMethod, SphereMethod, TriangleMethod};
use crate::render::{Image, RenderError, render};
use crate::scene::{Camera, Light, Material, MaterialId, Object, ObjectId, ObjectSource, Scene};
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
    /// Mean FLIP against the baseline render: at most [`SAME_IMAGE_FLIP`], the point shows
    /// the baseline's image (bit differences that no one can see, e.g. depth 6 against 5).
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
    /// The full sweep of issue 5 at 320×240 (a few minutes on two cores): depth 0–12, 1–64
    /// samples, 5 runs, a 256-sample reference.
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

/// Where a sweep is: step `step` of `steps`, doing `what`.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchProgress {
    pub step: usize,
    pub steps: usize,
    pub what: String,
}

/// Why a sweep stopped.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("the sweep was cancelled")]
    Cancelled,
    #[error(transparent)]
    Render(#[from] RenderError),
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

/// The kebab-case name serde gives a unit enum value (`moller-trumbore`).
pub fn value_name<T: Serialize>(v: &T) -> String {
    serde_json::to_value(v)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// One timed render: the image, the seconds (build + render), build and render seconds, rays,
/// and the accelerator built.
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

/// Median of a non-empty list.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
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

fn check(cancel: &AtomicBool) -> Result<(), BenchError> {
    if cancel.load(Ordering::Relaxed) {
        Err(BenchError::Cancelled)
    } else {
        Ok(())
    }
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

    check(cancel)?;
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

    check(cancel)?;
    say(1, "baseline".into());
    let base_scene = scene_with(scene, opts, baseline.max_depth);
    let base_image =
        render_once(&base_scene, baseline.trace, baseline.samples, opts.threads)?.image;

    let mut out = Vec::with_capacity(points.len());
    for (i, (knob, value, settings)) in points.into_iter().enumerate() {
        check(cancel)?;
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
    for i in pareto_front(&out, &baseline) {
        out[i].pareto = true;
    }
    Ok(BenchReport {
        reference: reference_info,
        baseline,
        points: out,
    })
}

/// Mean FLIP against the baseline below which a point shows the same image (FLIP's authors
/// put the threshold of a visible difference around 0.01 for a pair of images seen in
/// alternation; a tenth of that is far below it).
pub const SAME_IMAGE_FLIP: f64 = 1e-3;

fn same_image(p: &BenchPoint) -> bool {
    p.flip_vs_baseline <= SAME_IMAGE_FLIP
}

/// Indices of the points no other point beats in both time and mean FLIP (lower is better in
/// both), sorted by time.
///
/// Points that show the baseline's image ([`SAME_IMAGE_FLIP`]: the accelerators, deeper
/// recursion than the scene needs, methods that change nothing visible in this scene) are one
/// setting as far as the image goes, and their times differ by little more than noise. They
/// count once, as the baseline's own point (or the first of them), at the median of their
/// times ([`front_secs`]), so the front never recommends a method for having been lucky with
/// the clock.
pub fn pareto_front(points: &[BenchPoint], baseline: &PointSettings) -> Vec<usize> {
    let rep = representative(points, baseline);
    let key = |i: usize| (front_secs(points, baseline, i), points[i].error.mean_flip);
    let candidates: Vec<usize> = (0..points.len())
        .filter(|&i| !same_image(&points[i]) || Some(i) == rep)
        .collect();
    let mut front: Vec<usize> = candidates
        .iter()
        .copied()
        .filter(|&i| {
            let (t, e) = key(i);
            !candidates.iter().any(|&j| {
                let (qt, qe) = key(j);
                qt <= t && qe <= e && (qt < t || qe < e)
            })
        })
        .collect();
    front.sort_by(|&a, &b| key(a).0.total_cmp(&key(b).0));
    front
}

/// The point that stands for all those with the baseline's image.
fn representative(points: &[BenchPoint], baseline: &PointSettings) -> Option<usize> {
    let same: Vec<usize> = (0..points.len())
        .filter(|&i| same_image(&points[i]))
        .collect();
    same.iter()
        .copied()
        .find(|&i| points[i].settings == *baseline)
        .or(same.first().copied())
}

/// The time the Pareto front uses for point `i`: its own, or for the baseline's image the
/// median over every point with that image.
pub fn front_secs(points: &[BenchPoint], baseline: &PointSettings, i: usize) -> f64 {
    if !same_image(&points[i]) || representative(points, baseline) != Some(i) {
        return points[i].secs;
    }
    median(
        points
            .iter()
            .filter(|p| same_image(p))
            .map(|p| p.secs)
            .collect(),
    )
}

/// The sweep as CSV, one line per point.
pub fn bench_csv(report: &BenchReport) -> String {
    let mut s = String::from(
        "knob,value,max_depth,samples,cutoff,sphere,triangle,offset,accel,accel_used,secs,\
         build_secs,render_secs,rays,mrays_per_sec,mean_flip,rmse,psnr_db,differing_share,\
         changed_pixels,flip_vs_baseline,pareto\n",
    );
    for p in &report.points {
        let m = &p.settings.trace.methods;
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{:.6},{:.6},{:.6},{},{:.3},{:.6},{:.6},{:.3},{:.6},{},{:.6},{}\n",
            p.knob.name(),
            p.value,
            p.settings.max_depth,
            p.settings.samples,
            p.settings.trace.cutoff,
            value_name(&m.sphere),
            value_name(&m.triangle),
            value_name(&m.offset),
            value_name(&p.settings.trace.accel),
            value_name(&p.accel_used),
            p.secs,
            p.build_secs,
            p.render_secs,
            p.rays,
            p.rays as f64 / p.render_secs.max(1e-9) / 1e6,
            p.error.mean_flip,
            p.error.rmse,
            p.error.psnr_db,
            p.error.differing_share,
            p.changed_pixels,
            p.flip_vs_baseline,
            p.pareto,
        ));
    }
    s
}

/// Mean FLIP against time on log axes, one series per knob, the Pareto front on top.
pub fn bench_chart(report: &BenchReport, scene_name: &str) -> Chart {
    let mut series: Vec<Series> = Knob::ALL
        .iter()
        .map(|&k| {
            let of_knob: Vec<&BenchPoint> = report.points.iter().filter(|p| p.knob == k).collect();
            let pts = of_knob
                .iter()
                .map(|p| (p.secs, p.error.mean_flip))
                .collect();
            let s = Series::new(k.name(), pts);
            match k {
                // Ordered values: a line; methods and accelerators: labelled points.
                Knob::MaxDepth | Knob::Samples | Knob::Cutoff => s,
                _ => s.styled(
                    SeriesStyle::Points,
                    of_knob.iter().map(|p| p.value.clone()).collect(),
                ),
            }
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let front_idx = pareto_front(&report.points, &report.baseline);
    let front = front_idx
        .iter()
        .map(|&i| {
            let secs = front_secs(&report.points, &report.baseline, i);
            (secs, report.points[i].error.mean_flip)
        })
        .collect();
    let labels = front_idx
        .iter()
        .map(|&i| {
            let p = &report.points[i];
            format!("{} {}", p.knob.name(), p.value)
        })
        .collect();
    series.push(Series::new("Pareto front", front).styled(SeriesStyle::Front, labels));
    Chart {
        title: format!(
            "{scene_name}: error against time ({}x{}, reference {} spp, depth {})",
            report.reference.width,
            report.reference.height,
            report.reference.samples,
            report.reference.max_depth
        ),
        x_label: "time per image, s (build + render, median)".into(),
        y_label: "mean FLIP against the reference".into(),
        x_log: true,
        y_log: true,
        series,
    }
}

// ---------------------------------------------------------------------------------------------
// Scaling: build and render time against triangle count

/// The triangle counts of the full scaling sweep: single triangles, then whole octaspheres
/// (`8·4^L`), and 1M (half of the 2M sphere) to place the grid/BVH crossover.
pub const SCALING_SIZES: [usize; 14] = [
    1, 2, 4, 8, 32, 128, 512, 2048, 8192, 32768, 131_072, 524_288, 1_048_576, 2_097_152,
];

/// What the scaling sweep measures: build and render time of [`scaling_scene`] at each
/// triangle count of `sizes`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScalingOptions {
    pub sizes: Vec<usize>,
    pub width: u32,
    pub height: u32,
    /// Timed runs per point; the median is kept.
    pub runs: usize,
    pub threads: usize,
    /// `none` is skipped once its estimated time (the last measured time scaled by the
    /// triangle count) exceeds this many seconds.
    pub none_limit_secs: f64,
}

impl ScalingOptions {
    /// 1 to 2M triangles at 640×480, the built-in scenes' size (a couple of minutes).
    pub fn full() -> Self {
        Self {
            sizes: SCALING_SIZES.to_vec(),
            width: 640,
            height: 480,
            runs: 3,
            threads: 0,
            none_limit_secs: 20.0,
        }
    }

    /// 1 to 8k triangles at 64×48, one run.
    pub fn quick() -> Self {
        Self {
            sizes: SCALING_SIZES[..9].to_vec(),
            width: 64,
            height: 48,
            runs: 1,
            none_limit_secs: 2.0,
            ..Self::full()
        }
    }
}

/// One accelerator at one size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScalingPoint {
    pub triangles: usize,
    pub accel: AccelKind,
    pub build_secs: f64,
    pub render_secs: f64,
    /// The accelerator's own memory ([`crate::accel::Accel::memory_bytes`]).
    pub memory_bytes: usize,
    pub rays: u64,
    /// Why the point was not measured (then the figures are 0).
    pub skipped: Option<String>,
}

impl ScalingPoint {
    pub fn total_secs(&self) -> f64 {
        self.build_secs + self.render_secs
    }
}

/// The scaling scene: the first `triangles` triangles of the coarsest octasphere (a tessellated
/// unit sphere of `8·4^L` triangles) that has as many, lit by one light, the camera close
/// enough that the sphere fills most of the image; primary and shadow rays only.
pub fn scaling_scene(triangles_wanted: usize, width: u32, height: u32) -> Scene {
    let mut level = 0;
    while 8usize << (2 * level) < triangles_wanted {
        level += 1;
    }
    let (verts, mut tris) = octasphere(level, 1.0, Vec3::ZERO);
    tris.truncate(triangles_wanted);
    let mut scene = Scene {
        camera: Camera {
            position: Vec3::new(0.4, 0.5, 3.0),
            look_at: Vec3::ZERO,
            ..Camera::default()
        },
        lights: vec![Light {
            name: "key".into(),
            position: Vec3::new(3.0, 4.0, 5.0),
            color: Vec3::ONE,
            radius: 0.0,
        }],
        materials: vec![Material::default()],
        objects: vec![Object {
            name: "sphere mesh".into(),
            source: ObjectSource::Triangle,
        }],
        triangles: triangles(&verts, &tris)
            .into_iter()
            .map(|vertices| crate::scene::Triangle {
                vertices,
                material: MaterialId(0),
                object: ObjectId(0),
            })
            .collect(),
        ..Scene::default()
    };
    scene.render.width = width;
    scene.render.height = height;
    scene.render.max_depth = 0;
    scene.render.samples = 1;
    scene
}

/// Times every accelerator at every size of `opts` (see [`ScalingOptions`]).
pub fn run_scaling(
    opts: &ScalingOptions,
    progress: &dyn Fn(&BenchProgress),
    cancel: &AtomicBool,
) -> Result<Vec<ScalingPoint>, BenchError> {
    const KINDS: [AccelKind; 3] = [AccelKind::None, AccelKind::Grid, AccelKind::Bvh];
    let steps = opts.sizes.len() * KINDS.len();
    let mut out = Vec::new();
    // The last measured (triangles, seconds) of `none`, to predict the next.
    let mut none_last: Option<(usize, f64)> = None;
    for (li, &size) in opts.sizes.iter().enumerate() {
        let scene = Arc::new(scaling_scene(size, opts.width, opts.height));
        let n = scene.triangles.len();
        for (ki, &kind) in KINDS.iter().enumerate() {
            check(cancel)?;
            progress(&BenchProgress {
                step: li * KINDS.len() + ki,
                steps,
                what: format!("{} triangles, {}", n, value_name(&kind)),
            });
            if kind == AccelKind::None
                && let Some((n0, t0)) = none_last
            {
                let estimate = t0 * n as f64 / n0 as f64;
                if estimate > opts.none_limit_secs {
                    out.push(ScalingPoint {
                        triangles: n,
                        accel: kind,
                        build_secs: 0.0,
                        render_secs: 0.0,
                        memory_bytes: 0,
                        rays: 0,
                        skipped: Some(format!(
                            "skipped: estimated {estimate:.0} s > {} s",
                            opts.none_limit_secs
                        )),
                    });
                    continue;
                }
            }
            let mut builds = Vec::new();
            let mut renders = Vec::new();
            let mut rays = 0;
            let mut memory = 0;
            for _ in 0..opts.runs.max(1) {
                let tracer = Tracer::new(
                    scene.clone(),
                    TraceSettings {
                        accel: kind,
                        ..TraceSettings::default()
                    },
                );
                let (_, stats) = render(&tracer, 1, opts.threads, &|_, _| {})?;
                builds.push(stats.build_secs);
                renders.push(stats.render_secs);
                rays = stats.rays.total();
                memory = tracer.accel.memory_bytes();
            }
            let p = ScalingPoint {
                triangles: n,
                accel: kind,
                build_secs: median(builds),
                render_secs: median(renders),
                memory_bytes: memory,
                rays,
                skipped: None,
            };
            if kind == AccelKind::None {
                none_last = Some((n, p.total_secs()));
            }
            out.push(p);
        }
    }
    Ok(out)
}

/// A change of the faster accelerator between two sizes: from about `triangles` on, `faster`
/// takes less time (build + render) than `slower`. The count is interpolated log-linearly
/// between the two measured sizes around the change.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Crossover {
    pub faster: AccelKind,
    pub slower: AccelKind,
    pub triangles: f64,
}

/// For the pairs none/grid, none/BVH and grid/BVH: which is faster at the smallest size
/// measured, and every crossover after it, in order of size.
pub fn crossovers(points: &[ScalingPoint]) -> Vec<(AccelKind, AccelKind, Vec<Crossover>)> {
    let pairs = [
        (AccelKind::None, AccelKind::Grid),
        (AccelKind::None, AccelKind::Bvh),
        (AccelKind::Grid, AccelKind::Bvh),
    ];
    pairs
        .iter()
        .map(|&(a, b)| {
            // (ln n, ln(t_b / t_a)) per size where both were measured.
            let mut ratios: Vec<(f64, f64)> = Vec::new();
            for p in points
                .iter()
                .filter(|p| p.accel == a && p.skipped.is_none())
            {
                if let Some(q) = points
                    .iter()
                    .find(|q| q.accel == b && q.triangles == p.triangles && q.skipped.is_none())
                {
                    let r = (q.total_secs().max(1e-9) / p.total_secs().max(1e-9)).ln();
                    ratios.push(((p.triangles as f64).ln(), r));
                }
            }
            let first_faster = match ratios.first() {
                Some(&(_, r)) if r < 0.0 => b,
                _ => a,
            };
            let mut changes = Vec::new();
            for w in ratios.windows(2) {
                let ((x0, r0), (x1, r1)) = (w[0], w[1]);
                if (r0 < 0.0) != (r1 < 0.0) {
                    let f = r0 / (r0 - r1);
                    let (faster, slower) = if r1 < 0.0 { (b, a) } else { (a, b) };
                    changes.push(Crossover {
                        faster,
                        slower,
                        triangles: (x0 + f * (x1 - x0)).exp(),
                    });
                }
            }
            (first_faster, if first_faster == a { b } else { a }, changes)
        })
        .collect()
}

/// The scaling sweep as CSV.
pub fn scaling_csv(points: &[ScalingPoint]) -> String {
    let mut s = String::from(
        "triangles,accel,build_secs,render_secs,total_secs,memory_bytes,bytes_per_triangle,rays,note\n",
    );
    for p in points {
        s.push_str(&format!(
            "{},{},{:.6},{:.6},{:.6},{},{:.1},{},{}\n",
            p.triangles,
            value_name(&p.accel),
            p.build_secs,
            p.render_secs,
            p.total_secs(),
            p.memory_bytes,
            p.memory_bytes as f64 / p.triangles.max(1) as f64,
            p.rays,
            p.skipped.as_deref().unwrap_or(""),
        ));
    }
    s
}

/// Build + render time and build time alone against triangle count, log-log.
pub fn scaling_chart(points: &[ScalingPoint], width: u32, height: u32) -> Chart {
    let mut series = Vec::new();
    for kind in [AccelKind::None, AccelKind::Grid, AccelKind::Bvh] {
        let measured: Vec<&ScalingPoint> = points
            .iter()
            .filter(|p| p.accel == kind && p.skipped.is_none())
            .collect();
        let name = value_name(&kind);
        series.push(Series::new(
            format!("{name}: build + render"),
            measured
                .iter()
                .map(|p| (p.triangles as f64, p.total_secs()))
                .collect(),
        ));
        if kind != AccelKind::None {
            series.push(Series::new(
                format!("{name}: build"),
                measured
                    .iter()
                    .map(|p| (p.triangles as f64, p.build_secs))
                    .collect(),
            ));
        }
    }
    Chart {
        title: format!("Tessellated sphere, {width}x{height}, 1 spp: time against triangle count"),
        x_label: "triangles".into(),
        y_label: "seconds".into(),
        x_log: true,
        y_log: true,
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base() -> PointSettings {
        PointSettings {
            max_depth: 5,
            samples: 1,
            trace: TraceSettings::default(),
        }
    }

    fn point(secs: f64, flip: f64, changed_pixels: usize) -> BenchPoint {
        let flip_vs_baseline = if changed_pixels == 0 { 0.0 } else { 0.1 };
        BenchPoint {
            knob: Knob::Samples,
            value: String::new(),
            settings: PointSettings {
                samples: 2,
                ..base()
            },
            accel_used: AccelKind::Bvh,
            secs,
            build_secs: 0.0,
            render_secs: secs,
            rays: 0,
            error: ImageError {
                mean_flip: flip,
                ..ImageError::default()
            },
            changed_pixels,
            flip_vs_baseline,
            pareto: false,
        }
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points_by_time() {
        let pts = vec![
            point(1.0, 0.5, 9),
            point(2.0, 0.2, 9),
            point(2.5, 0.3, 9), // dominated by (2.0, 0.2)
            point(4.0, 0.1, 9),
            point(0.5, 0.9, 9),
            point(4.0, 0.1, 9), // a tie is kept
        ];
        assert_eq!(pareto_front(&pts, &base()), vec![4, 0, 1, 3, 5]);
    }

    #[test]
    fn the_baseline_image_counts_once_at_its_median_time() {
        let mut pts = vec![
            point(1.0, 0.5, 9),
            point(0.7, 0.4, 0), // lucky clock, same image as the baseline
            point(1.1, 0.4, 0),
            point(0.9, 0.4, 0),
            point(3.0, 0.1, 9),
        ];
        pts[2].settings = base();
        // The baseline (index 2) stands for the three at their median, 0.9 s.
        assert_eq!(pareto_front(&pts, &base()), vec![2, 4]);
        assert_eq!(front_secs(&pts, &base(), 2), 0.9);
        assert_eq!(front_secs(&pts, &base(), 1), 0.7);
    }

    #[test]
    fn crossover_is_interpolated_between_sizes() {
        let p = |n: usize, accel, secs: f64| ScalingPoint {
            triangles: n,
            accel,
            build_secs: 0.0,
            render_secs: secs,
            memory_bytes: 0,
            rays: 0,
            skipped: None,
        };
        let pts = vec![
            p(10, AccelKind::None, 1.0),
            p(10, AccelKind::Grid, 1.0),
            p(10, AccelKind::Bvh, 2.0),
            p(1000, AccelKind::None, 4.0),
            p(1000, AccelKind::Grid, 1.0),
            p(1000, AccelKind::Bvh, 2.0),
            p(100_000, AccelKind::Grid, 1.0),
            p(100_000, AccelKind::Bvh, 0.5),
        ];
        let c = crossovers(&pts);
        let (first, other, changes) = &c[1];
        assert_eq!((*first, *other), (AccelKind::None, AccelKind::Bvh));
        // ln ratio goes from ln 2 to −ln 2: halfway in log space, at 100.
        assert_eq!(changes.len(), 1);
        assert_eq!(changes[0].faster, AccelKind::Bvh);
        assert!((changes[0].triangles - 100.0).abs() < 1e-6, "{changes:?}");
        // Grid against BVH: grid first, BVH from 10 000 on (ln 2 to −ln 2 over 1e3…1e5).
        let (first, _, changes) = &c[2];
        assert_eq!(*first, AccelKind::Grid);
        assert!(
            (changes[0].triangles - 10_000.0).abs() < 1e-6,
            "{changes:?}"
        );
        assert_eq!(crossover_lines(&pts).len(), 3);
    }

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
        assert_eq!(
            value_name(&TriangleMethod::MollerTrumbore),
            "moller-trumbore"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Output: files and the lines the command prints

/// Writes `bench.csv`, `bench.svg` and `bench.png` into `dir`.
pub fn write_bench(dir: &Path, report: &BenchReport, scene_name: &str) -> Result<(), ExportError> {
    write_text(&dir.join("bench.csv"), &bench_csv(report))?;
    write_chart(&bench_chart(report, scene_name), &dir.join("bench"))
}

/// Writes `scaling.csv`, `scaling.svg` and `scaling.png` into `dir`.
pub fn write_scaling(
    dir: &Path,
    points: &[ScalingPoint],
    opts: &ScalingOptions,
) -> Result<(), ExportError> {
    write_text(&dir.join("scaling.csv"), &scaling_csv(points))?;
    write_chart(
        &scaling_chart(points, opts.width, opts.height),
        &dir.join("scaling"),
    )
}

/// The Pareto-optimal settings, one line each, fastest first.
pub fn pareto_lines(report: &BenchReport) -> Vec<String> {
    let same = report.points.iter().filter(|p| same_image(p)).count();
    pareto_front(&report.points, &report.baseline)
        .into_iter()
        .map(|i| {
            let p = &report.points[i];
            let name = format!("{} = {}", p.knob.name(), p.value);
            let note = if same_image(p) {
                format!("  (the scene's own image; {same} settings give it)")
            } else {
                String::new()
            };
            format!(
                "{name:<22} {:>9.4} s  mean FLIP {:.4}  PSNR {:>6.2} dB  {:>10} rays{note}",
                front_secs(&report.points, &report.baseline, i),
                p.error.mean_flip,
                p.error.psnr_db,
                p.rays
            )
        })
        .collect()
}

/// Accelerator points that changed the image (must be none), as `(kind, pixels)`.
pub fn accel_changes(report: &BenchReport) -> Vec<(AccelKind, usize)> {
    report
        .points
        .iter()
        .filter(|p| p.knob == Knob::Accel)
        .map(|p| (p.settings.trace.accel, p.changed_pixels))
        .collect()
}

/// The crossovers as sentences.
pub fn crossover_lines(points: &[ScalingPoint]) -> Vec<String> {
    let smallest = points.iter().map(|p| p.triangles).min().unwrap_or(0);
    crossovers(points)
        .iter()
        .map(|(first, other, changes)| {
            let mut line = format!(
                "{} is faster than {} at {smallest} triangles",
                value_name(first),
                value_name(other)
            );
            for c in changes {
                line.push_str(&format!(
                    "; {} is faster from about {:.0}",
                    value_name(&c.faster),
                    c.triangles
                ));
            }
            line
        })
        .collect()
}
