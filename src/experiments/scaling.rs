//! The accelerator scaling sweep: [`run_scaling`] times building and rendering a tessellated
//! sphere of 1 to 2M triangles with each accelerator; [`crossovers`] finds where one becomes
//! faster than another, which is what `AccelKind::Auto` uses.
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

    /// A measured point of `secs` render time, for the tests of what is made of the points.
    #[cfg(test)]
    pub(super) fn timed(triangles: usize, accel: AccelKind, secs: f64) -> Self {
        Self {
            triangles,
            accel,
            build_secs: 0.0,
            render_secs: secs,
            memory_bytes: 0,
            rays: 0,
            skipped: None,
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossover_is_interpolated_between_sizes() {
        let p = ScalingPoint::timed;
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
    }
}
