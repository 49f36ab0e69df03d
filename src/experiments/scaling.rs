//! The accelerator scaling sweep: [`run_scaling`] times building and rendering a tessellated
//! sphere of 1 to 2M triangles with each accelerator; [`crossovers`] says which is faster
//! where, which is what `AccelKind::Auto` was set from.
//!
//! Like [`super::sweep`] it takes a progress callback and a cancel flag and returns plain data;
//! the files and lines made of it are [`super::report`]'s.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::measure::{BenchError, BenchProgress, check_cancel, median, value_name};
use super::meshes::{octasphere, triangles};
use crate::accel::AccelKind;
use crate::render::render;
use crate::scene::{Camera, Light, Material, MaterialId, Object, ObjectId, ObjectSource, Scene};
use crate::trace::{TraceSettings, Tracer};

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
    /// Medians of the runs.
    pub build_secs: f64,
    pub render_secs: f64,
    /// The fastest and slowest run's build + render: the spread [`crossovers`] weighs a
    /// difference against.
    pub total_min_secs: f64,
    pub total_max_secs: f64,
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

    /// A measured point of `secs` render time, for the tests of what is made of the points.
    #[cfg(test)]
    pub(super) fn timed(triangles: usize, accel: AccelKind, secs: f64) -> Self {
        Self {
            triangles,
            accel,
            build_secs: 0.0,
            render_secs: secs,
            total_min_secs: secs,
            total_max_secs: secs,
            memory_bytes: 0,
            rays: 0,
            skipped: None,
        }
    }

    /// [`Self::timed`] with its runs spread from `min` to `max` seconds.
    #[cfg(test)]
    pub(super) fn spread(mut self, min: f64, max: f64) -> Self {
        (self.total_min_secs, self.total_max_secs) = (min, max);
        self
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
            follow_camera: false,
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
            .collect::<Vec<_>>()
            .into(),
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
            check_cancel(cancel)?;
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
                        total_min_secs: 0.0,
                        total_max_secs: 0.0,
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
            let mut totals = Vec::new();
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
                totals.push(stats.build_secs + stats.render_secs);
                rays = stats.rays.total();
                memory = tracer.accel.memory_bytes();
            }
            let p = ScalingPoint {
                triangles: n,
                accel: kind,
                build_secs: median(builds),
                render_secs: median(renders),
                total_min_secs: totals.iter().copied().fold(f64::INFINITY, f64::min),
                total_max_secs: totals.iter().copied().fold(0.0, f64::max),
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

/// Two accelerators count as level at a size when their medians are closer than this (as a
/// share of the faster) or when the ranges of their runs overlap: a frame of a few
/// milliseconds varies by tens of per cent between runs, so such a difference says nothing
/// about which is faster.
pub const LEVEL_WITHIN: f64 = 0.10;

/// What one stretch of sizes says of a pair of accelerators.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Verdict {
    /// This one took less time (build + render) by more than [`LEVEL_WITHIN`].
    Faster(AccelKind),
    /// The two were within [`LEVEL_WITHIN`] of each other, or their runs overlapped.
    Level,
}

/// Consecutive measured sizes, `from` to `to` triangles, with one [`Verdict`]. `crosses_at` is
/// set where the faster one changes straight from the other accelerator to this one: the count
/// where the time ratio passes 1, interpolated log-linearly between the two sizes around it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Stretch {
    pub verdict: Verdict,
    pub from: usize,
    pub to: usize,
    pub crosses_at: Option<f64>,
}

/// Two accelerators compared over the sizes where both were measured, smallest first.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PairComparison {
    pub a: AccelKind,
    pub b: AccelKind,
    pub stretches: Vec<Stretch>,
}

/// For the pairs none/grid, none/BVH and grid/BVH: which is faster where, size by size, with
/// differences within [`LEVEL_WITHIN`] or within the runs' spread counted as level.
pub fn crossovers(points: &[ScalingPoint]) -> Vec<PairComparison> {
    let pairs = [
        (AccelKind::None, AccelKind::Grid),
        (AccelKind::None, AccelKind::Bvh),
        (AccelKind::Grid, AccelKind::Bvh),
    ];
    pairs
        .iter()
        .map(|&(a, b)| {
            // (n, ln(t_b / t_a), runs overlap) per size where both were measured.
            let mut ratios: Vec<(usize, f64, bool)> = Vec::new();
            for p in points
                .iter()
                .filter(|p| p.accel == a && p.skipped.is_none())
            {
                if let Some(q) = points
                    .iter()
                    .find(|q| q.accel == b && q.triangles == p.triangles && q.skipped.is_none())
                {
                    let r = (q.total_secs().max(1e-9) / p.total_secs().max(1e-9)).ln();
                    let overlap = p.total_min_secs <= q.total_max_secs
                        && q.total_min_secs <= p.total_max_secs;
                    ratios.push((p.triangles, r, overlap));
                }
            }
            ratios.sort_by_key(|&(n, _, _)| n);
            let level = (1.0 + LEVEL_WITHIN).ln();
            let verdict = |r: f64, overlap: bool| {
                if overlap || r.abs() < level {
                    Verdict::Level
                } else if r < 0.0 {
                    Verdict::Faster(b)
                } else {
                    Verdict::Faster(a)
                }
            };
            let mut stretches: Vec<Stretch> = Vec::new();
            let mut before: Option<(usize, f64)> = None;
            for &(n, r, overlap) in &ratios {
                let v = verdict(r, overlap);
                match stretches.last_mut() {
                    Some(last) if last.verdict == v => last.to = n,
                    last => {
                        let crosses_at = match (last.map(|l| l.verdict), before) {
                            (Some(Verdict::Faster(_)), Some((n0, r0)))
                                if v != Verdict::Level && (r0 < 0.0) != (r < 0.0) =>
                            {
                                let (x0, x1) = ((n0 as f64).ln(), (n as f64).ln());
                                let f = r0 / (r0 - r);
                                Some((x0 + f * (x1 - x0)).exp())
                            }
                            _ => None,
                        };
                        stretches.push(Stretch {
                            verdict: v,
                            from: n,
                            to: n,
                            crosses_at,
                        });
                    }
                }
                before = Some((n, r));
            }
            PairComparison { a, b, stretches }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossover_is_interpolated_between_sizes_and_small_differences_are_level() {
        let p = ScalingPoint::timed;
        let pts = vec![
            p(10, AccelKind::None, 1.0),
            p(10, AccelKind::Grid, 1.05),
            p(10, AccelKind::Bvh, 2.0),
            p(1000, AccelKind::None, 4.0),
            p(1000, AccelKind::Grid, 1.0),
            p(1000, AccelKind::Bvh, 2.0),
            p(100_000, AccelKind::Grid, 1.0),
            p(100_000, AccelKind::Bvh, 0.5),
            // 30 % apart but the runs overlap: level.
            p(200_000, AccelKind::Grid, 1.0).spread(0.9, 1.4),
            p(200_000, AccelKind::Bvh, 1.3).spread(1.2, 1.5),
        ];
        let c = crossovers(&pts);
        let none_bvh = &c[1];
        assert_eq!((none_bvh.a, none_bvh.b), (AccelKind::None, AccelKind::Bvh));
        assert_eq!(none_bvh.stretches.len(), 2, "{none_bvh:?}");
        let (first, then) = (none_bvh.stretches[0], none_bvh.stretches[1]);
        assert_eq!(first.verdict, Verdict::Faster(AccelKind::None));
        assert_eq!((first.from, first.to, first.crosses_at), (10, 10, None));
        assert_eq!(then.verdict, Verdict::Faster(AccelKind::Bvh));
        // ln ratio goes from ln 2 to −ln 2: halfway in log space, at 100.
        let at = then.crosses_at.expect("a crossing");
        assert!((at - 100.0).abs() < 1e-6, "{then:?}");
        // None against grid: 5 % apart at 10 is level, not a win; grid from 1000, no crossing.
        let none_grid = &c[0].stretches;
        assert_eq!(none_grid[0].verdict, Verdict::Level);
        assert_eq!(none_grid[1].verdict, Verdict::Faster(AccelKind::Grid));
        assert_eq!(none_grid[1].crosses_at, None);
        // Grid against BVH: grid first (10 and 1000), BVH from about 10 000 on.
        let grid_bvh = &c[2].stretches;
        assert_eq!((grid_bvh[0].from, grid_bvh[0].to), (10, 1000));
        let at = grid_bvh[1].crosses_at.expect("a crossing");
        assert!((at - 10_000.0).abs() < 1e-6, "{grid_bvh:?}");
        assert_eq!(grid_bvh[2].verdict, Verdict::Level, "{grid_bvh:?}");
        assert_eq!(grid_bvh[2].from, 200_000);
    }
}
