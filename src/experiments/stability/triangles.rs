//! T1-T5: triangles (docs/stability.md, rows T1 to T5). Rays through the shared edges and
//! vertices of a closed mesh (leaks, double hits), tiny and needle triangles, bad triangles
//! in a valid mesh, small triangles far from the ray origin.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;

use glam::Vec3;
use serde::Serialize;

use super::{
    Row, StabilityOptions, Verdict, at, chart, fmt_g, log_sweep, p10, pct, trials, yes_if,
};
use crate::accel::{Accel, AccelKind, PrimSet};
use crate::experiments::chart::Series;
use crate::experiments::meshes::{octasphere, triangles};
use crate::experiments::scaling::scaling_scene;
use crate::geometry::triangle::triangle_hit_f64;
use crate::geometry::{Methods, Ray, TriangleMethod, intersect_triangle};
use crate::render::render;
use crate::rng::Pcg;
use crate::scene::{MaterialId, ObjectId};
use crate::trace::{TraceSettings, Tracer};

// =============================================================================================
// T1, T2: rays through the shared edges and vertices of a closed mesh

/// A ray aimed at a point of the surface at distance `t_target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AimedRay {
    pub ray: Ray,
    pub t_target: f32,
}

impl std::ops::Deref for AimedRay {
    type Target = Ray;
    fn deref(&self) -> &Ray {
        &self.ray
    }
}

/// Rays from outside aimed (radially, with a small random tilt) at every vertex and at three
/// points of every edge (the midpoint and two random ones) of a closed mesh around `center`,
/// `per_target` rays each: every one passes through the interior, so it must hit the mesh.
pub fn mesh_edge_rays(
    rng: &mut Pcg,
    verts: &[Vec3],
    tris: &[[usize; 3]],
    scale: f32,
    center: Vec3,
    per_target: usize,
) -> Vec<AimedRay> {
    let mut targets: Vec<Vec3> = verts.to_vec();
    let mut edges = std::collections::BTreeSet::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    for &(a, b) in &edges {
        for f in [0.5, rng.f32(), rng.f32()] {
            targets.push(verts[a] + (verts[b] - verts[a]) * f);
        }
    }
    let mut rays = Vec::new();
    for p in targets {
        for _ in 0..per_target {
            let radial = ((p - center) / scale).normalize();
            let out = (radial + 0.05 * rng.unit()).normalize();
            let origin = p + out * (scale * rng.range(0.5, 4.0));
            rays.push(AimedRay {
                ray: Ray::new(origin, (p - origin).normalize()),
                t_target: (p - origin).length(),
            });
        }
    }
    rays
}

/// A closed mesh (octahedron subdivided twice, 128 triangles) of radius `scale` whose centre
/// is `offset·scale` from the origin, and rays at its vertices and edges.
pub fn closed_mesh_case(
    scale: f32,
    offset: f32,
    per_target: usize,
    rng: &mut Pcg,
) -> (Vec<[Vec3; 3]>, Vec<AimedRay>) {
    let center = Vec3::new(0.3, -0.7, 0.2) * (offset * scale);
    let (verts, idx) = octasphere(2, scale, center);
    let rays = mesh_edge_rays(rng, &verts, &idx, scale, center, per_target);
    (triangles(&verts, &idx), rays)
}

/// T1/T2 figures of one method on one mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LeakCell {
    pub rays: usize,
    /// Rays that pass the near surface (first hit beyond the target by `0.1·scale`, or none).
    pub leaks: usize,
    /// Rays that hit two or more triangles of the near surface (T2).
    pub double_hits: usize,
    /// Rays whose closest hit through `accel` differs from the brute-force one (T2: must be
    /// 0, the tie-break by index makes it deterministic).
    pub differs_from_brute_force: usize,
}

/// Counts leaks through `accel` and double hits by brute force.
pub fn count_leaks(
    method: TriangleMethod,
    accel: AccelKind,
    tris: &[[Vec3; 3]],
    rays: &[AimedRay],
    scale: f32,
) -> LeakCell {
    let prims = PrimSet {
        spheres: vec![],
        triangles: tris.to_vec(),
    };
    let methods = Methods {
        triangle: method,
        ..Methods::default()
    };
    let brute = Accel::build(AccelKind::None, &prims);
    let other = (accel != AccelKind::None).then(|| Accel::build(accel, &prims));
    let mut cell = LeakCell {
        rays: rays.len(),
        ..LeakCell::default()
    };
    for ray in rays {
        let near = ray.t_target + 0.1 * scale;
        let reference = brute.closest_hit(&methods, ray, 0.0, f32::INFINITY);
        let hit = match &other {
            Some(a) => {
                let h = a.closest_hit(&methods, ray, 0.0, f32::INFINITY);
                cell.differs_from_brute_force += usize::from(h != reference);
                h
            }
            None => reference,
        };
        cell.leaks += usize::from(hit.is_none_or(|h| h.t > near));
        let near_hits = tris
            .iter()
            .filter_map(|v| intersect_triangle(method, v, ray, 0.0, f32::INFINITY))
            .filter(|h| h.t <= near)
            .count();
        cell.double_hits += usize::from(near_hits >= 2);
    }
    cell
}

/// Rays per target of [`closed_mesh_case`] so that a cell has about `rays` rays (642 targets).
fn per_target(rays: usize) -> usize {
    rays.div_ceil(642).max(1)
}

const T1_SCALES: [i32; 8] = [-4, -3, -2, -1, 0, 1, 2, 3];
const T1_OFFSETS: [f32; 4] = [0.0, 1e2, 1e4, 1e5];

fn t1_cells(o: &StabilityOptions, rng: &mut Pcg) -> Vec<(f32, f32, [LeakCell; 3])> {
    let mut out = Vec::new();
    for &k in &T1_SCALES {
        let scale = p10(k);
        for &offset in &T1_OFFSETS {
            let (tris, rays) = closed_mesh_case(scale, offset, per_target(o.rays), rng);
            let cells = [
                TriangleMethod::Lecture,
                TriangleMethod::MollerTrumbore,
                TriangleMethod::Watertight,
            ]
            .map(|m| count_leaks(m, AccelKind::Bvh, &tris, &rays, scale));
            out.push((scale, offset, cells));
        }
    }
    out
}

pub(super) fn row_t1(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let cells = t1_cells(o, rng);
    let per10k = |c: &LeakCell| 1e4 * c.leaks as f64 / c.rays.max(1) as f64;
    let worst = |m: usize| {
        cells
            .iter()
            .map(|(s, off, c)| (per10k(&c[m]), *s, *off))
            .fold((0.0, 0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
    };
    let sum = |m: usize| cells.iter().map(|(_, _, c)| c[m].leaks).sum::<usize>();
    let rays: usize = cells.iter().map(|(_, _, c)| c[2].rays).sum();
    let mut series = Vec::new();
    for (m, name) in [(0, "lecture"), (1, "Möller–Trumbore"), (2, "watertight")] {
        for off in [0.0f32, 1e4] {
            series.push(Series::new(
                format!("{name}, offset {}", fmt_g(off as f64)),
                cells
                    .iter()
                    .filter(|(_, o2, _)| *o2 == off)
                    .map(|(s, _, c)| (*s as f64, per10k(&c[m])))
                    .collect(),
            ));
        }
    }
    let (lw, ls, lo) = worst(0);
    let (mw, ms, mo) = worst(1);
    let mt_tiny = cells
        .iter()
        .filter(|(s, _, _)| *s < 2e-4)
        .map(|(_, _, c)| per10k(&c[1]))
        .fold(f64::INFINITY, f64::min);
    Row {
        id: "T1",
        failure: "cracks at shared edges and vertices of a closed mesh",
        naive_method: "lecture plane + barycentric; Möller–Trumbore",
        robust_method: "watertight (Woop–Benthin–Wald 2013) through the BVH",
        sweep: format!(
            "scale 1e-4…1e3, centre offset 0…1e5 × scale, ~{} rays per cell at vertices and edges",
            cells.first().map_or(0, |c| c.2[2].rays)
        ),
        naive: format!(
            "lecture: {} leaks in all, worst {:.0} per 10k (scale {}, offset {}); MT: {} in all, \
             worst {:.0} per 10k (scale {}, offset {}), ≥ {:.0} per 10k at scale 1e-4",
            sum(0),
            lw,
            fmt_g(ls as f64),
            fmt_g(lo as f64),
            sum(1),
            mw,
            fmt_g(ms as f64),
            fmt_g(mo as f64),
            mt_tiny
        ),
        robust: format!("{} leaks in {} rays through the BVH", sum(2), rays),
        target: "0 leaks, including through the BVH",
        verdict: yes_if(sum(2) == 0 && sum(0) + sum(1) > 0),
        chart: Some(chart(
            "T1: leaks through a closed mesh",
            "mesh scale",
            "leaks per 10k rays",
            false,
            series,
        )),
    }
}

pub(super) fn row_t2(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let mut rows = Vec::new();
    for k in [-3, 0, 3] {
        let scale = p10(k);
        let (tris, rays) = closed_mesh_case(scale, 0.0, per_target(o.rays), rng);
        // Vertex rays come first: 66 vertices × per_target.
        let n_vertex = 66 * per_target(o.rays);
        let vertex = count_leaks(
            TriangleMethod::Watertight,
            AccelKind::Bvh,
            &tris,
            &rays[..n_vertex],
            scale,
        );
        let edge = count_leaks(
            TriangleMethod::Watertight,
            AccelKind::Bvh,
            &tris,
            &rays[n_vertex..],
            scale,
        );
        rows.push((scale, vertex, edge));
    }
    let differs: usize = rows
        .iter()
        .map(|(_, v, e)| v.differs_from_brute_force + e.differs_from_brute_force)
        .sum();
    let v_share = |c: &LeakCell| pct(c.double_hits, c.rays);
    Row {
        id: "T2",
        failure: "double hits at shared edges (both neighbours report the ray)",
        naive_method: "–",
        robust_method: "watertight + tie-break by the lower primitive id",
        sweep: "closed mesh at scale 1e-3, 1, 1e3; vertex and edge rays".into(),
        naive: rows
            .iter()
            .map(|(s, v, e)| {
                format!(
                    "scale {}: {:.0}% of vertex rays, {:.0}% of edge rays hit ≥ 2 triangles",
                    fmt_g(*s as f64),
                    v_share(v),
                    v_share(e)
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
        robust: format!("closest hit through the BVH differs from brute force on {differs} rays"),
        target: "report the count; the closest hit is deterministic (tie-break by index)",
        verdict: yes_if(differs == 0),
        chart: None,
    }
}

// =============================================================================================
// T3: tiny and needle triangles

/// Rays through the centroid of random triangles with longest edge `edge` and width
/// `edge / aspect`, placed in `[−base_extent, base_extent]³`, from `10·edge` away at up to
/// about 17° off the normal. Only rays the `f64` oracle puts well inside (every barycentric
/// ≥ 0.05) count. Returns (tested, misses).
pub fn centroid_misses(
    method: TriangleMethod,
    edge: f32,
    aspect: f32,
    base_extent: f32,
    n: usize,
    rng: &mut Pcg,
) -> (usize, usize) {
    trials(n, rng, |rng| {
        let base = rng.in_box(Vec3::splat(-base_extent), Vec3::splat(base_extent));
        let a = rng.unit();
        let b = rng.perpendicular(a);
        let v = [
            base,
            base + a * edge,
            base + a * (0.5 * edge) + b * (edge / aspect),
        ];
        let normal = (v[1] - v[0]).cross(v[2] - v[0]);
        let thin = normal.length() < 0.5 * edge * edge / aspect;
        if thin || !normal.is_finite() {
            return None; // the rounded vertices are too thin to aim at reliably
        }
        let centroid = (v[0] + v[1] + v[2]) / 3.0;
        let dir_out = (normal.normalize() + 0.3 * rng.unit()).normalize();
        let origin = centroid + dir_out * (10.0 * edge);
        let ray = Ray::new(origin, (centroid - origin).normalize());
        let (_, b0, b1, b2) = triangle_hit_f64(&v, &ray)?;
        if b0.min(b1).min(b2) < 0.05 {
            return None;
        }
        Some(intersect_triangle(method, &v, &ray, 0.0, f32::INFINITY).is_none())
    })
}

pub(super) fn row_t3(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let edges = log_sweep(-6, 2, 1);
    let n = (o.rays / 4).max(100);
    let mut mt = Vec::new();
    let mut wt = Vec::new();
    for &e in &edges {
        let (t, m) = centroid_misses(TriangleMethod::MollerTrumbore, e, 1.0, 1.0, n, rng);
        mt.push((e as f64, pct(m, t)));
        let (t, m) = centroid_misses(TriangleMethod::Watertight, e, 1.0, 1.0, n, rng);
        wt.push((e as f64, pct(m, t)));
    }
    let aspects = log_sweep(0, 6, 1);
    let mut mt_needle = Vec::new();
    let mut wt_needle = Vec::new();
    for &a in &aspects {
        let (t, m) = centroid_misses(TriangleMethod::MollerTrumbore, 1e-2, a, 1e-2, n, rng);
        mt_needle.push((a as f64, pct(m, t)));
        let (t, m) = centroid_misses(TriangleMethod::Watertight, 1e-2, a, 1e-2, n, rng);
        wt_needle.push((a as f64, pct(m, t)));
    }
    let first = |v: &[(f64, f64)], rev: bool| {
        let it: Box<dyn Iterator<Item = &(f64, f64)>> = if rev {
            Box::new(v.iter().rev())
        } else {
            Box::new(v.iter())
        };
        it.filter(|(_, p)| *p > 50.0)
            .map(|(x, p)| format!("{} ({p:.0}%)", fmt_g(*x)))
            .next()
            .unwrap_or_else(|| "never".into())
    };
    let wt_miss: f64 = wt.iter().chain(&wt_needle).map(|p| p.1).fold(0.0, f64::max);
    // A needle whose width is a few ulp of its ray-relative coordinates loses it in the
    // translation; the watertight test then decides it in f64 (an edge function within its
    // rounding error of 0, or t within its error bound).
    let wt_needle_ok_to = wt_needle
        .iter()
        .take_while(|p| p.1 == 0.0)
        .last()
        .map_or(0.0, |p| p.0);
    let wt_edges_ok = wt.iter().all(|p| p.1 == 0.0);
    Row {
        id: "T3",
        failure: "tiny and needle triangles missed by an absolute |det| epsilon",
        naive_method: "Möller–Trumbore, |det| < 1e-8",
        robust_method: "watertight, only det = 0 rejected, close calls in f64",
        sweep: format!("edge 1e-6…1e2 (aspect 1); aspect 1…1e6 at edge 1e-2; {n} rays per cell"),
        naive: format!(
            "MT misses most rays from edge {} down and from aspect {} up (edge 1e-2)",
            first(&mt, true),
            first(&mt_needle, false)
        ),
        robust: if wt_miss == 0.0 {
            format!(
                "watertight: 0 misses at every edge size and every aspect up to {} (width 1e-8, \
                 1.3 ulp of the coordinates relative to the ray origin 10 lengths away: edge \
                 functions within their rounding error of 0 and t within its bound are decided \
                 in f64)",
                fmt_g(wt_needle_ok_to)
            )
        } else {
            format!(
                "watertight: needles 0 up to aspect {}, then up to {wt_miss:.1}%",
                fmt_g(wt_needle_ok_to)
            )
        },
        target: "0 misses; only det == 0 rejected",
        verdict: if !mt.first().is_some_and(|p| p.1 > 50.0) || !wt_edges_ok {
            Verdict::No
        } else if wt_miss == 0.0 {
            Verdict::Yes
        } else if wt_needle_ok_to >= 1e4 {
            Verdict::Partly
        } else {
            Verdict::No
        },
        chart: Some(chart(
            "T3: rays through the centroid of tiny and needle triangles",
            "edge length (aspect 1) or aspect ratio (edge 1e-2)",
            "missed, %",
            false,
            vec![
                Series::new("MT vs edge", mt),
                Series::new("watertight vs edge", wt),
                Series::new("MT vs aspect", mt_needle),
                Series::new("watertight vs aspect", wt_needle),
            ],
        )),
    }
}

// =============================================================================================
// T4: bad triangles in a valid mesh

/// T4 figures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BadTriangleCell {
    pub triangles: usize,
    pub injected: usize,
    /// Skipped at build time (for every accelerator kind alike, or `usize::MAX` if they
    /// disagree).
    pub skipped: usize,
    pub rays: usize,
    /// Rays that hit the clean mesh.
    pub clean_hits: usize,
    /// Rays whose closest hit (t, barycentrics, triangle) differs between the clean and the
    /// injected mesh, over all accelerator kinds.
    pub changed_hits: usize,
    /// Non-finite pixels in renders of the injected mesh, over all accelerator kinds.
    pub nan_pixels: usize,
    /// Builds, queries or renders that panicked.
    pub panics: usize,
}

/// Builds a closed mesh (octasphere level 4, 2048 triangles), inserts `fraction` bad
/// triangles at random places (NaN, ±∞ and huge vertices, zero-area ones), and compares every
/// accelerator's answers with the clean mesh's; renders the injected scene at 48×36.
pub fn bad_triangles(fraction: f32, n_rays: usize, rng: &mut Pcg) -> BadTriangleCell {
    let (verts, idx) = octasphere(4, 1.0, Vec3::ZERO);
    let clean = triangles(&verts, &idx);
    let injected = ((clean.len() as f32 * fraction).round() as usize).max(1);
    let bad_kinds = [
        [Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X, Vec3::Y],
        [Vec3::splat(f32::INFINITY), Vec3::X, Vec3::Y],
        [Vec3::ZERO, Vec3::new(f32::NEG_INFINITY, 1.0, 0.0), Vec3::Y],
        [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
        [Vec3::ONE; 3],
        [Vec3::splat(f32::MAX), -Vec3::splat(f32::MAX), Vec3::ZERO],
    ];
    // dirty[i] = Some(clean index) or None for a bad one.
    let mut order: Vec<Option<usize>> = (0..clean.len()).map(Some).collect();
    for _ in 0..injected {
        let at = rng.below(order.len() + 1);
        order.insert(at, None);
    }
    let mut bad_i = 0;
    let dirty: Vec<[Vec3; 3]> = order
        .iter()
        .map(|o| match o {
            Some(i) => clean[*i],
            None => {
                bad_i += 1;
                bad_kinds[bad_i % bad_kinds.len()]
            }
        })
        .collect();
    let clean_of = |prim: u32| order[prim as usize];
    let mut cell = BadTriangleCell {
        triangles: clean.len(),
        injected,
        rays: n_rays,
        ..BadTriangleCell::default()
    };
    let rays: Vec<Ray> = (0..n_rays)
        .map(|_| {
            let o = rng.unit() * 3.0;
            Ray::new(o, (rng.unit() * 0.9 - o).normalize())
        })
        .collect();
    let m = Methods::default();
    let clean_set = PrimSet {
        spheres: vec![],
        triangles: clean.clone(),
    };
    let dirty_set = PrimSet {
        spheres: vec![],
        triangles: dirty.clone(),
    };
    let mut skipped = None;
    for kind in [AccelKind::None, AccelKind::Grid, AccelKind::Bvh] {
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let a = Accel::build(kind, &clean_set);
            let b = Accel::build(kind, &dirty_set);
            let mut changed = 0;
            let mut hits = 0;
            for ray in &rays {
                let h0 = a.closest_hit(&m, ray, 0.0, f32::INFINITY);
                let h1 = b.closest_hit(&m, ray, 0.0, f32::INFINITY);
                hits += usize::from(h0.is_some());
                let same = match (h0, h1) {
                    (None, None) => true,
                    (Some(x), Some(y)) => {
                        (x.t, x.b1, x.b2) == (y.t, y.b1, y.b2)
                            && clean_of(y.prim) == Some(x.prim as usize)
                    }
                    _ => false,
                };
                changed += usize::from(!same);
            }
            (b.skipped_prims(), hits, changed)
        }));
        match outcome {
            Ok((s, hits, changed)) => {
                skipped = match skipped {
                    None => Some(s),
                    Some(prev) if prev == s => Some(s),
                    Some(_) => Some(usize::MAX),
                };
                cell.clean_hits = hits;
                cell.changed_hits += changed;
            }
            Err(_) => cell.panics += 1,
        }
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let mut scene = scaling_scene(8, 48, 36);
            scene.triangles = dirty
                .iter()
                .map(|&vertices| crate::scene::Triangle {
                    vertices,
                    material: MaterialId(0),
                    object: ObjectId(0),
                })
                .collect::<Vec<_>>()
                .into();
            let tracer = Tracer::new(
                Arc::new(scene),
                TraceSettings {
                    accel: kind,
                    ..TraceSettings::default()
                },
            );
            render(&tracer, 1, 1, &|_, _| {})
                .map(|(img, _)| img.pixels.iter().filter(|p| !p.is_finite()).count())
        }));
        match outcome {
            Ok(Ok(nan)) => cell.nan_pixels += nan,
            _ => cell.panics += 1,
        }
    }
    cell.skipped = skipped.unwrap_or(0);
    cell
}

pub(super) fn row_t4(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let fractions = [0.001f32, 0.01, 0.1];
    let cells: Vec<BadTriangleCell> = fractions
        .iter()
        .map(|&f| bad_triangles(f, (o.rays / 4).max(200), rng))
        .collect();
    let ok = cells.iter().all(|c| {
        c.panics == 0 && c.nan_pixels == 0 && c.changed_hits == 0 && c.skipped == c.injected
    });
    Row {
        id: "T4",
        failure: "zero-area and NaN/∞ triangles in a valid mesh",
        naive_method: "–",
        robust_method: "drop and count at build time (every accelerator)",
        sweep: "0.1%, 1%, 10% bad triangles injected into a 2048-triangle closed mesh".into(),
        naive: "glam's min/max and `f32 as usize` would spread NaN into boxes and cells".into(),
        robust: cells
            .iter()
            .map(|c| {
                format!(
                    "{} injected: {} skipped, {} panics, {} NaN pixels, {} of {} hits changed",
                    c.injected, c.skipped, c.panics, c.nan_pixels, c.changed_hits, c.clean_hits
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
        target: "no panic; bad tris skipped and counted; valid hit rate unchanged",
        verdict: yes_if(ok),
        chart: None,
    }
}

// =============================================================================================
// T5: small triangles far from the ray origin

/// Rays from `distance` (in triangle sizes) at random triangles of size 1 near the origin, seen
/// at up to `max_tilt_deg` from face-on, through a point the `f64` oracle puts well inside
/// (every barycentric ≥ 0.1). Returns (tested, misses). The watertight test's conservative
/// `t > δt` bound (pbrt-v4) grows with the ray-relative coordinates: far enough away it
/// passes `t` itself, and the test decides the hit in `f64`.
pub fn far_triangle_misses(
    method: TriangleMethod,
    distance: f32,
    max_tilt_deg: f32,
    n: usize,
    rng: &mut Pcg,
) -> (usize, usize) {
    let max_tilt = max_tilt_deg.to_radians();
    trials(n, rng, |rng| {
        let a = rng.unit();
        let b = rng.perpendicular(a);
        let c = rng.in_box(Vec3::splat(-1.0), Vec3::ONE);
        let v = [c + a * 0.6, c - a * 0.3 + b * 0.5, c - a * 0.3 - b * 0.5];
        let normal = a.cross(b);
        // A direction at `tilt` from the normal.
        let tilt = rng.range(0.0, max_tilt);
        let side = rng.perpendicular(normal);
        let towards = (normal * tilt.cos() + side * tilt.sin()).normalize();
        let (w1, w2) = (rng.range(0.15, 0.45), rng.range(0.15, 0.45));
        let target = v[0] + w1 * (v[1] - v[0]) + w2 * (v[2] - v[0]);
        let origin = target + towards * distance;
        let ray = Ray::new(origin, (target - origin).normalize());
        let (t, b0, b1, b2) = triangle_hit_f64(&v, &ray)?;
        if t <= 0.0 || b0.min(b1).min(b2) < 0.1 {
            return None;
        }
        Some(intersect_triangle(method, &v, &ray, 0.0, f32::INFINITY).is_none())
    })
}

pub(super) fn row_t5(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let distances = log_sweep(3, 7, 2);
    let n = (o.rays / 4).max(100);
    let cases = [
        (
            "watertight, face-on ±30°",
            TriangleMethod::Watertight,
            30.0f32,
        ),
        ("watertight, up to 85°", TriangleMethod::Watertight, 85.0),
        ("MT, up to 85°", TriangleMethod::MollerTrumbore, 85.0),
        ("lecture, up to 85°", TriangleMethod::Lecture, 85.0),
    ];
    let series: Vec<Series> = cases
        .iter()
        .map(|&(name, m, tilt)| {
            Series::new(
                name,
                distances
                    .iter()
                    .map(|&d| {
                        let (t, miss) = far_triangle_misses(m, d, tilt, n, rng);
                        (d as f64, pct(miss, t))
                    })
                    .collect(),
            )
        })
        .collect();
    let onset = |i: usize| {
        series[i]
            .points
            .iter()
            .find(|p| p.1 > 0.0)
            .map(|p| format!("{} ({:.2}%)", fmt_g(p.0), p.1))
            .unwrap_or_else(|| "never".into())
    };
    let missed = |i: usize, d: f64| at(&series[i].points, d);
    // Where f32 can place the triangle: one ulp of the distance at most 1/16 of its size
    // (ulp(1e6) = 1/16). Farther, the vertices relative to the ray origin round by a quarter
    // of the triangle (3.2e6) or all of it (1e7).
    let placeable = |i: usize| {
        series[i]
            .points
            .iter()
            .filter(|p| p.0 <= 1.001e6)
            .map(|p| p.1)
            .fold(0.0, f64::max)
    };
    Row {
        id: "T5",
        failure: "small triangles far from the ray origin (found here)",
        naive_method: "Möller–Trumbore; lecture",
        robust_method: "watertight, t > δt (pbrt-v4) decided in f64 where t ≤ δt",
        sweep: format!("distance 1e3…1e7 triangle sizes, rays through the inside, {n} per cell"),
        naive: format!(
            "MT misses from distance {}; lecture from {}",
            onset(2),
            onset(3)
        ),
        robust: format!(
            "watertight misses {:.2}% face-on and {:.2}% up to 85° up to 1e6 sizes (ulp of the \
             distance ≤ 1/16 of the size); first miss: {} face-on, {} up to 85° ({:.1}% at \
             1e7, where one ulp is the whole triangle; MT {:.1}%). The f32 bound δt \
             grows like ε·t²/size and passes t from ~1e5 sizes: hits with t ≤ δt are decided \
             in f64",
            placeable(0),
            placeable(1),
            onset(0),
            onset(1),
            missed(1, 1e7),
            missed(2, 1e7)
        ),
        target: "no misses where f32 can still place the triangle (ulp of the distance ≤ size/16)",
        verdict: if placeable(0) == 0.0 && placeable(1) == 0.0 {
            Verdict::Yes
        } else if missed(0, 1e4) == 0.0 && missed(1, 1e4) == 0.0 {
            Verdict::Partly
        } else {
            Verdict::No
        },
        chart: Some(chart(
            "T5: rays through small triangles from far away",
            "distance from the ray origin, in triangle sizes",
            "missed, %",
            false,
            series,
        )),
    }
}
