//! B2: BVH builds on pathological geometry (docs/stability.md, row B2): identical,
//! coplanar-centroid, collinear-centroid, nested and huge-and-tiny triangles.

use std::time::Instant;

use glam::Vec3;
use serde::Serialize;

use super::{Row, StabilityOptions, chart, fmt_g, p10, yes_if};
use crate::accel::{Accel, AccelKind, PrimSet};
use crate::experiments::chart::Series;
use crate::experiments::measure::value_name;
use crate::geometry::{Methods, Ray};
use crate::rng::Pcg;

/// The build keeps the 8-wide BVH shallow (`accel::bvh`: a balanced tree of 2²⁸ primitives
/// is about 10 levels deep, and the median-split fallback replaces any tree whose traversal
/// could overflow its stack), so a depth at or above this would be a bug.
pub const BVH_DEPTH_CAP: usize = 64;

/// Pathological inputs for the BVH build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pathology {
    /// `N` copies of one triangle.
    Identical,
    /// Random triangles whose centroids all lie on the plane `z = 0`.
    CoplanarCentroids,
    /// Random triangles whose centroids all lie on one line.
    CollinearCentroids,
    /// Triangles of sizes `1e-3…1e3` around one common centroid.
    NestedSameCentre,
    /// 1% triangles of size `1e4` over 99% of size `1e-3` in a unit box.
    HugeAndTiny,
}

impl Pathology {
    pub const ALL: [Pathology; 5] = [
        Pathology::Identical,
        Pathology::CoplanarCentroids,
        Pathology::CollinearCentroids,
        Pathology::NestedSameCentre,
        Pathology::HugeAndTiny,
    ];
}

/// B2 figures of one build.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BuildCell {
    pub case: Pathology,
    pub triangles: usize,
    pub build_secs: f64,
    /// BVH depth (root = 1).
    pub depth: usize,
    /// Probe rays whose closest hit differs from brute force.
    pub disagreements: usize,
}

/// Triangles of one pathological case.
pub fn pathological_triangles(case: Pathology, n: usize, rng: &mut Pcg) -> Vec<[Vec3; 3]> {
    // A triangle with centroid `c` and size `s` in a random orientation.
    let around = |rng: &mut Pcg, c: Vec3, s: f32| {
        let (a, b) = (rng.unit() * s, rng.unit() * s);
        [c + a, c + b, c - a - b]
    };
    (0..n)
        .map(|i| match case {
            Pathology::Identical => [
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            Pathology::CoplanarCentroids => {
                let c = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0);
                around(rng, c, 0.05)
            }
            Pathology::CollinearCentroids => {
                let c = Vec3::new(rng.range(-1.0, 1.0), 0.0, 0.0);
                around(rng, c, 0.05)
            }
            Pathology::NestedSameCentre => {
                let s = p10(-3) * 1e6f32.powf(rng.f32());
                around(rng, Vec3::splat(0.25), s)
            }
            Pathology::HugeAndTiny => {
                if i % 100 == 0 {
                    let c = rng.in_box(Vec3::splat(-1.0), Vec3::ONE);
                    around(rng, c, 1e4)
                } else {
                    let c = rng.in_box(Vec3::splat(-1.0), Vec3::ONE);
                    around(rng, c, 1e-3)
                }
            }
        })
        .collect()
}

/// Builds a BVH over `n` triangles of `case`, timing it, and checks `probes` rays against
/// brute force.
pub fn pathological_build(case: Pathology, n: usize, probes: usize, rng: &mut Pcg) -> BuildCell {
    let prims = PrimSet {
        spheres: vec![],
        triangles: pathological_triangles(case, n, rng),
    };
    let start = Instant::now();
    let bvh = Accel::build(AccelKind::Bvh, &prims);
    let build_secs = start.elapsed().as_secs_f64();
    let brute = Accel::build(AccelKind::None, &prims);
    let m = Methods::default();
    let mut disagreements = 0;
    for _ in 0..probes {
        let o = rng.unit() * 3.0;
        let ray = Ray::new(
            o,
            (rng.in_box(Vec3::splat(-1.0), Vec3::ONE) - o).normalize(),
        );
        let a = bvh.closest_hit(&m, &ray, 0.0, f32::INFINITY);
        let b = brute.closest_hit(&m, &ray, 0.0, f32::INFINITY);
        disagreements += usize::from(a != b);
    }
    BuildCell {
        case,
        triangles: n,
        build_secs,
        depth: bvh.bvh_depth().unwrap_or(0),
        disagreements,
    }
}

pub(super) fn row_b2(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let mut sizes = vec![100usize];
    while sizes.last().is_some_and(|&n| n * 10 <= o.max_build) {
        let n = sizes.last().copied().unwrap_or(100) * 10;
        sizes.push(n);
    }
    let mut cells = Vec::new();
    for case in Pathology::ALL {
        for &n in &sizes {
            cells.push(pathological_build(case, n, 100, rng));
        }
    }
    let max_depth = cells.iter().map(|c| c.depth).max().unwrap_or(0);
    let slowest = cells.iter().map(|c| c.build_secs).fold(0.0, f64::max);
    let disagreements: usize = cells.iter().map(|c| c.disagreements).sum();
    let series = Pathology::ALL
        .iter()
        .map(|&case| {
            Series::new(
                value_name(&case),
                cells
                    .iter()
                    .filter(|c| c.case == case)
                    .map(|c| (c.triangles as f64, c.depth as f64))
                    .collect(),
            )
        })
        .collect();
    Row {
        id: "B2",
        failure: "BVH build on pathological geometry (chains, deep trees, stack overflow)",
        naive_method: "plain PLOC / SAH build",
        robust_method: "jittered boxes, median-split fallback, depth guard",
        sweep: format!(
            "N = 1e2…{} identical, coplanar-centroid, collinear-centroid, nested and huge+tiny \
             triangles",
            fmt_g(*sizes.last().unwrap_or(&100) as f64)
        ),
        naive: "panics or overflows in other BVH libraries (svenstaro #44, tinybvh #164)".into(),
        robust: format!(
            "always terminates; max depth of the 8-wide BVH {max_depth} (cap {BVH_DEPTH_CAP}); slowest build \
             {slowest:.2} s; {disagreements} probe rays differ from brute force"
        ),
        target: "terminates; depth ≤ cap; no overflow",
        verdict: yes_if(max_depth < BVH_DEPTH_CAP && disagreements == 0),
        chart: Some(chart(
            "B2: BVH depth on pathological input",
            "triangles",
            "8-wide BVH depth",
            false,
            series,
        )),
    }
}
