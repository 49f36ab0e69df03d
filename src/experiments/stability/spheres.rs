//! S1-S4: spheres (docs/stability.md, rows S1 to S4). A sphere far from the ray origin
//! (cancellation in the discriminant), its hit point off the surface, a huge sphere as the
//! ground against a plane, grazing rays and origins just inside.

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::{
    Row, StabilityOptions, Verdict, at, chart, fmt_g, log_sweep, p10, pct, trials, ulp, yes_if,
};
use crate::experiments::chart::Series;
use crate::geometry::sphere::sphere_roots_f64;
use crate::geometry::triangle::triangle_hit_f64;
use crate::geometry::{
    Ray, SphereMethod, TriangleMethod, intersect_sphere, intersect_triangle, sphere_hit_point,
};
use crate::rng::Pcg;

// =============================================================================================
// S1, S2: a sphere far from the ray origin

/// One cell of S1/S2: rays from distance `D = d_over_r · r`, half passing within `0.95 r` of
/// the centre (hits), half at `1.05…1.5 r` (misses), judged by the `f64` oracle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SphereCell {
    pub rays: usize,
    /// Rays the oracle says hit that the method misses.
    pub misses: usize,
    /// Rays the oracle says miss that the method reports as hits.
    pub false_hits: usize,
    /// Largest relative error of `t` against the oracle's near root, in units of
    /// `f32::EPSILON`.
    pub max_t_err_eps: f64,
    /// Largest `|‖P − C‖ − r|` of the method's hit point (`sphere_hit_point`), in `ulp(r)`.
    pub max_point_err_ulp: f64,
    /// Largest `|‖P − C‖ − r| / r` of the plain `P0 + t·u` (no re-projection).
    pub max_unprojected_rel: f64,
}

impl SphereCell {
    /// Misclassified rays, in percent.
    pub fn wrong_pct(&self) -> f64 {
        pct(self.misses + self.false_hits, self.rays)
    }
}

/// Measures one S1/S2 cell.
pub fn sphere_cell(method: SphereMethod, d_over_r: f32, n: usize, rng: &mut Pcg) -> SphereCell {
    let mut cell = SphereCell {
        rays: n,
        ..SphereCell::default()
    };
    for i in 0..n {
        let r = rng.range(1.0, 2.0);
        // Centre near the origin so the hit point's own f32 spacing is that of r (S2).
        let center = rng.unit() * rng.range(0.0, 0.5) * r;
        let dir = rng.unit();
        let rho = if i % 2 == 0 {
            0.95 * r * rng.f32().sqrt()
        } else {
            r * rng.range(1.05, 1.5)
        };
        // The ray's closest approach to the centre is at distance rho, D before it.
        let closest = center + rng.perpendicular(dir) * rho;
        let ray = Ray::new(closest - dir * (d_over_r * r), dir);
        let oracle = sphere_roots_f64(center, r, &ray).filter(|&(t0, _)| t0 > 0.0);
        let got = intersect_sphere(method, center, r, &ray, 0.0, f32::INFINITY);
        match (got, oracle) {
            (Some(t), Some((t0, _))) => {
                let t_err = ((t as f64 - t0) / t0).abs() / f32::EPSILON as f64;
                cell.max_t_err_eps = cell.max_t_err_eps.max(t_err);
                let dist = |p: Vec3| (DVec3::from(p) - DVec3::from(center)).length();
                let (p, _) = sphere_hit_point(method, center, r, &ray, t);
                let p_err = (dist(p) - r as f64).abs() / ulp(r) as f64;
                cell.max_point_err_ulp = cell.max_point_err_ulp.max(p_err);
                let raw = (dist(ray.at(t)) - r as f64).abs() / r as f64;
                cell.max_unprojected_rel = cell.max_unprojected_rel.max(raw);
            }
            (None, Some(_)) => cell.misses += 1,
            (Some(_), None) => cell.false_hits += 1,
            (None, None) => {}
        }
    }
    cell
}

pub(super) fn row_s1(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let sweep = log_sweep(0, 7, 2);
    let sweep: Vec<f32> = std::iter::once(3.0)
        .chain(sweep.into_iter().skip(1))
        .collect();
    let mut lecture = Vec::new();
    let mut robust = Vec::new();
    for &d in &sweep {
        lecture.push((d, sphere_cell(SphereMethod::Lecture, d, o.rays, rng)));
        robust.push((d, sphere_cell(SphereMethod::Robust, d, o.rays, rng)));
    }
    let first_bad = |cells: &[(f32, SphereCell)]| {
        cells
            .iter()
            .find(|(_, c)| c.misses + c.false_hits > 0)
            .map(|(d, c)| (*d, c.wrong_pct()))
    };
    let naive = match first_bad(&lecture) {
        Some((d, p)) => format!(
            "first wrong at D/r = {}: {:.2}%; {:.1}% @1e3, {:.1}% @1e4, {:.1}% @1e5",
            fmt_g(d as f64),
            p,
            at(&lecture, 1e3).wrong_pct(),
            at(&lecture, 1e4).wrong_pct(),
            at(&lecture, 1e5).wrong_pct()
        ),
        None => "never wrong in the sweep".into(),
    };
    let exact_to = robust
        .iter()
        .take_while(|(_, c)| c.misses + c.false_hits == 0)
        .last()
        .map_or(0.0, |(d, _)| *d);
    let t_err = robust
        .iter()
        .filter(|(d, _)| *d <= 1e6)
        .map(|(_, c)| c.max_t_err_eps)
        .fold(0.0, f64::max);
    let robust_fail = first_bad(&robust);
    let wrong_at_1e6 = at(&robust, 1e6).wrong_pct();
    let robust_text = format!(
        "0 misses / 0 false hits up to D/r = {}; {:.2}% wrong at 1e6 (rays within ~ε·D of the \
         silhouette: f + b·u carries an absolute error of about ε·D); max rel t err {:.1} \
         EPSILON (≤1e6); {}",
        fmt_g(exact_to as f64),
        wrong_at_1e6,
        t_err,
        match robust_fail {
            Some((d, p)) => format!("first wrong at D/r = {} ({:.2}%)", fmt_g(d as f64), p),
            None => "never wrong in the sweep".into(),
        }
    );
    let naive_fails = first_bad(&lecture).is_some_and(|(d, _)| d <= 1e4);
    let series = |cells: &[(f32, SphereCell)]| {
        cells
            .iter()
            .map(|(d, c)| (*d as f64, c.wrong_pct()))
            .collect()
    };
    Row {
        id: "S1",
        failure: "sphere far from the ray origin: cancellation in the discriminant",
        naive_method: "lecture quadratic",
        robust_method: "Hearn–Baker discriminant + stable roots (RTG ch. 7)",
        sweep: format!("D/r = 3…1e7, {} rays per cell", o.rays),
        naive,
        robust: robust_text,
        target: "0/0 for D/r ≤ 1e6; rel t err ≤ 4 ulp",
        verdict: if !naive_fails || t_err > 4.0 || exact_to < 3e5 || wrong_at_1e6 > 0.1 {
            Verdict::No
        } else if exact_to >= 1e6 {
            Verdict::Yes
        } else {
            Verdict::Partly
        },
        chart: Some(chart(
            "S1: far sphere, misclassified rays",
            "D / r",
            "misses + false hits, %",
            false,
            vec![
                Series::new("lecture", series(&lecture)),
                Series::new("robust", series(&robust)),
            ],
        )),
    }
}

pub(super) fn row_s2(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let sweep: Vec<f32> = log_sweep(0, 6, 1);
    let cells: Vec<(f32, SphereCell)> = sweep
        .iter()
        .map(|&d| (d, sphere_cell(SphereMethod::Robust, d, o.rays, rng)))
        .collect();
    let unprojected = |x: f64| at(&cells, x).max_unprojected_rel;
    let worst_ulp = cells
        .iter()
        .map(|(_, c)| c.max_point_err_ulp)
        .fold(0.0, f64::max);
    Row {
        id: "S2",
        failure: "hit point off the surface (P0 + t·u rounds like D)",
        naive_method: "P0 + t·u",
        robust_method: "re-projection onto the sphere from its centre",
        sweep: format!("D/r = 1…1e6, {} rays per cell", o.rays),
        naive: format!(
            "|‖P−C‖−r|/r = {} @1e3, {} @1e6",
            fmt_g(unprojected(1e3)),
            fmt_g(unprojected(1e6))
        ),
        robust: format!("≤ {worst_ulp:.2} ulp(r) at every D/r"),
        target: "≤ 2 ulp after centre-relative re-projection",
        verdict: yes_if(worst_ulp <= 2.0 && unprojected(1e6) > 1e-3),
        chart: Some(chart(
            "S2: hit point distance from the sphere",
            "D / r",
            "max |‖P − C‖ − r| / r",
            true,
            vec![
                Series::new(
                    "P0 + t·u",
                    cells
                        .iter()
                        .map(|(d, c)| (*d as f64, c.max_unprojected_rel))
                        .collect(),
                ),
                Series::new(
                    "re-projected",
                    cells
                        .iter()
                        .map(|(d, c)| (*d as f64, c.max_point_err_ulp * ulp(1.5) as f64 / 1.5))
                        .collect(),
                ),
            ],
        )),
    }
}

// =============================================================================================
// S3: a huge sphere as the ground against a plane

/// One cell of S3: rays from height `h` above the top of a sphere of radius `r` (centre
/// `(0, −r, 0)`), going down at up to 55° from vertical; the same rays against the plane
/// `y = 0` made of two watertight triangles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct GroundCell {
    pub rays: usize,
    /// Largest relative error of the sphere's near root (a miss counts as 1).
    pub sphere_max_rel_t_err: f64,
    pub sphere_misses: usize,
    /// Largest relative error of the plane's `t` (a miss counts as 1).
    pub plane_max_rel_t_err: f64,
    pub plane_misses: usize,
}

/// Measures one S3 cell.
pub fn ground_cell(r: f32, h: f32, n: usize, rng: &mut Pcg) -> GroundCell {
    let center = Vec3::new(0.0, -r, 0.0);
    let l = 1e3 * h.max(1.0);
    let plane = [
        [
            Vec3::new(-l, 0.0, -l),
            Vec3::new(l, 0.0, -l),
            Vec3::new(l, 0.0, l),
        ],
        [
            Vec3::new(-l, 0.0, -l),
            Vec3::new(l, 0.0, l),
            Vec3::new(-l, 0.0, l),
        ],
    ];
    let mut cell = GroundCell {
        rays: n,
        ..GroundCell::default()
    };
    for _ in 0..n {
        let origin = Vec3::new(rng.range(-1.0, 1.0), h, rng.range(-1.0, 1.0));
        let dir = Vec3::new(rng.range(-1.0, 1.0), -1.0, rng.range(-1.0, 1.0)).normalize();
        let ray = Ray::new(origin, dir);
        if let Some((t0, _)) = sphere_roots_f64(center, r, &ray).filter(|&(t0, _)| t0 > 0.0) {
            let got = intersect_sphere(SphereMethod::Robust, center, r, &ray, 0.0, f32::INFINITY);
            let err = got.map_or(1.0, |t| ((t as f64 - t0) / t0).abs());
            cell.sphere_misses += usize::from(got.is_none());
            cell.sphere_max_rel_t_err = cell.sphere_max_rel_t_err.max(err);
        }
        let oracle = plane
            .iter()
            .filter_map(|v| triangle_hit_f64(v, &ray))
            .find(|&(t, b0, b1, b2)| t > 0.0 && b0 >= 0.0 && b1 >= 0.0 && b2 >= 0.0);
        if let Some((t0, ..)) = oracle {
            let got = plane
                .iter()
                .filter_map(|v| {
                    intersect_triangle(TriangleMethod::Watertight, v, &ray, 0.0, f32::INFINITY)
                })
                .map(|h| h.t)
                .reduce(f32::min);
            let err = got.map_or(1.0, |t| ((t as f64 - t0) / t0).abs());
            cell.plane_misses += usize::from(got.is_none());
            cell.plane_max_rel_t_err = cell.plane_max_rel_t_err.max(err);
        }
    }
    cell
}

pub(super) fn row_s3(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let radii = log_sweep(2, 6, 1);
    let heights = [1e-3f32, 1e-2, 1e-1, 1.0, 1e1, 1e2];
    let n = (o.rays / 4).max(100);
    // Per radius, the cells of every height.
    let mut cells: Vec<(f32, Vec<(f32, GroundCell)>)> = Vec::new();
    for &r in &radii {
        let row = heights.iter().map(|&h| (h, ground_cell(r, h, n, rng)));
        cells.push((r, row.collect()));
    }
    let get = |r: f32, h: f32| at(&at(&cells, f64::from(r)), f64::from(h));
    let plane_worst = cells
        .iter()
        .flat_map(|(_, row)| row)
        .map(|(_, c)| c.plane_max_rel_t_err)
        .fold(0.0, f64::max);
    let mut series = Vec::new();
    for h in [1e-3f32, 1.0] {
        series.push(Series::new(
            format!("sphere, h = {}", fmt_g(h as f64)),
            radii
                .iter()
                .map(|&r| (r as f64, get(r, h).sphere_max_rel_t_err))
                .collect(),
        ));
    }
    for h in [1e-3f32, 1.0] {
        series.push(Series::new(
            format!("plane, h = {}", fmt_g(h as f64)),
            radii
                .iter()
                .map(|&r| (r as f64, get(r, h).plane_max_rel_t_err.max(1e-9)))
                .collect(),
        ));
    }
    let s13 = get(1e3, 1e-3).sphere_max_rel_t_err;
    Row {
        id: "S3",
        failure: "huge sphere as the ground: c = |f|² − r² quantised",
        naive_method: "sphere of radius r (robust test)",
        robust_method: "plane of two watertight triangles",
        sweep: format!("r = 1e2…1e6, height h = 1e-3…1e2, {n} rays per cell"),
        naive: format!(
            "near-root rel t err {} @ r=1e3, h=1e-3; {} @ r=1e6, h=1e-3; {} @ r=1e6, h=1",
            fmt_g(s13),
            fmt_g(get(1e6, 1e-3).sphere_max_rel_t_err),
            fmt_g(get(1e6, 1.0).sphere_max_rel_t_err)
        ),
        robust: format!(
            "plane: max rel t err {} ({:.1} EPSILON) at every r and h",
            fmt_g(plane_worst),
            plane_worst / f32::EPSILON as f64
        ),
        target: "plane: ≤ few ulp independent of r",
        verdict: yes_if(plane_worst <= 8.0 * f32::EPSILON as f64 && s13 > 1e-3),
        chart: Some(chart(
            "S3: ground as a huge sphere or a plane",
            "sphere radius r",
            "max relative error of t",
            true,
            series,
        )),
    }
}

// =============================================================================================
// S4: grazing rays and origins inside the sphere

/// S4, grazing: rays whose closest approach to the centre is `r(1 − 10⁻ᵏ)` (half) or
/// `r(1 + 10⁻ᵏ)` (half), from `D/r` between 2 and 20. Returns the rays whose hit/miss verdict
/// disagrees with the `f64` oracle of the same `f32` ray.
pub fn grazing_wrong(method: SphereMethod, k: i32, n: usize, rng: &mut Pcg) -> usize {
    let mut wrong = 0;
    for i in 0..n {
        let center = rng.unit() * rng.range(0.0, 2.0);
        let r = rng.range(0.5, 2.0);
        let dir = rng.unit();
        let sign = if i % 2 == 0 { -1.0 } else { 1.0 };
        let rho = r * (1.0 + sign * p10(-k));
        let closest = center + rng.perpendicular(dir) * rho;
        let ray = Ray::new(closest - dir * (r * rng.range(2.0, 20.0)), dir);
        let truth = sphere_roots_f64(center, r, &ray).is_some_and(|(t0, _)| t0 > 0.0);
        let got = intersect_sphere(method, center, r, &ray, 0.0, f32::INFINITY).is_some();
        wrong += usize::from(truth != got);
    }
    wrong
}

/// S4, monotone in ρ: `families` sets of parallel-ish rays from `D/r` between 50 and 200
/// whose closest approach steps through `r(1 + j·step)`, `j = −m..=m`. Each ray's exact
/// (`f64`) distance ρ from the centre is computed from its rounded `f32` origin and direction;
/// sorted by it, the verdicts must read hit…hit, miss…miss, except within `4·ε·D` of the
/// surface, where no `f32` computation from an origin `D` away can decide (the Hearn–Baker
/// vector `f + b·u` alone carries about `ε·D`; the lecture's discriminant carries `ε·D²`, a
/// band `D/r` times wider). Returns the families where they do not.
pub fn grazing_non_monotone(
    method: SphereMethod,
    step: f32,
    m: i32,
    families: usize,
    rng: &mut Pcg,
) -> usize {
    let mut bad = 0;
    for _ in 0..families {
        let center = rng.unit() * rng.range(0.0, 2.0);
        let r = rng.range(0.5, 2.0);
        let dir = rng.unit();
        let side = rng.perpendicular(dir);
        let d = r * rng.range(50.0, 200.0);
        let mut verdicts: Vec<(f64, bool)> = (-m..=m)
            .map(|j| {
                let rho = r * (1.0 + j as f32 * step);
                let ray = Ray::new(center + side * rho - dir * d, dir);
                let u = DVec3::from(ray.dir);
                let f = DVec3::from(ray.origin) - DVec3::from(center);
                let exact = (f - u * (f.dot(u) / u.dot(u))).length();
                let hit = intersect_sphere(method, center, r, &ray, 0.0, f32::INFINITY).is_some();
                (exact, hit)
            })
            .collect();
        let band = 4.0 * f64::from(f32::EPSILON) * f64::from(d);
        verdicts.retain(|v| (v.0 - f64::from(r)).abs() >= band);
        verdicts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let first_miss = verdicts.iter().position(|v| !v.1).unwrap_or(verdicts.len());
        bad += usize::from(verdicts[first_miss..].iter().any(|v| v.1));
    }
    bad
}

/// S4, inside origins: rays starting `r·10⁻ᵏ` inside the surface (a refracted ray's origin),
/// going inwards at a random angle. Returns (rays the oracle confirms start inside, rays whose
/// `t` is not the far root within `1e-4` relative).
pub fn inside_origin_wrong(
    method: SphereMethod,
    k: i32,
    n: usize,
    rng: &mut Pcg,
) -> (usize, usize) {
    trials(n, rng, |rng| {
        let center = rng.unit() * rng.range(0.0, 2.0);
        let r = rng.range(0.5, 2.0);
        let nrm = rng.unit();
        let origin = center + nrm * (r * (1.0 - p10(-k)));
        let tilt = rng.range(0.0, 3.0) * rng.perpendicular(nrm);
        let ray = Ray::new(origin, (-nrm + tilt).normalize());
        let (n0, far) = sphere_roots_f64(center, r, &ray)?;
        if n0 >= 0.0 {
            return None; // rounded to the outside
        }
        let t = intersect_sphere(method, center, r, &ray, 0.0, f32::INFINITY);
        Some(!t.is_some_and(|t| (t as f64 - far).abs() <= 1e-4 * far.max(r as f64)))
    })
}

pub(super) fn row_s4(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let ks: Vec<i32> = (1..=7).collect();
    let mut graze = [Vec::new(), Vec::new()];
    let mut inside = [Vec::new(), Vec::new()];
    let methods = [SphereMethod::Lecture, SphereMethod::Robust];
    for &k in &ks {
        for (i, m) in methods.into_iter().enumerate() {
            graze[i].push(pct(grazing_wrong(m, k, o.rays, rng), o.rays));
            let (tested, wrong) = inside_origin_wrong(m, k, o.rays, rng);
            inside[i].push(pct(wrong, tested));
        }
    }
    let families = (o.rays / 100).max(20);
    let non_monotone = methods.map(|m| grazing_non_monotone(m, 1e-5, 100, families, rng));
    let first = |v: &[f64]| {
        v.iter()
            .position(|&p| p > 0.0)
            .map(|i| format!("k = {} ({:.2}%)", ks[i], v[i]))
            .unwrap_or_else(|| "never".into())
    };
    let zero_to = |v: &[f64], k: usize| v[..k].iter().all(|&p| p == 0.0);
    let robust_ok = non_monotone[1] == 0 && zero_to(&graze[1], 5) && zero_to(&inside[1], 6);
    let x = |v: &[f64]| -> Vec<(f64, f64)> {
        ks.iter()
            .zip(v)
            .map(|(&k, &p)| (10f64.powi(-k), p))
            .collect()
    };
    Row {
        id: "S4",
        failure: "grazing rays (ρ ≈ r) and origins just inside the sphere",
        naive_method: "lecture quadratic",
        robust_method: "robust quadratic",
        sweep: format!(
            "ρ/r = 1 ± 10⁻ᵏ from D/r = 2…20 and inside depth r·10⁻ᵏ, k = 1…7, {} rays; \
             {families} families of 201 rays from D/r = 50…200 stepping ρ by 1e-5·r",
            o.rays
        ),
        naive: format!(
            "grazing verdict wrong from {}; inside origin wrong root from {}; {} of {families} \
             families not monotone in ρ (outside 4·ε·D of the surface)",
            first(&graze[0]),
            first(&inside[0]),
            non_monotone[0]
        ),
        robust: format!(
            "grazing wrong from {} (|ρ − r| within a few ε·D); inside origin wrong from {} \
             (10⁻⁷ r is below one ulp of r); {} of {families} families not monotone in ρ \
             (outside 4·ε·D of the surface)",
            first(&graze[1]),
            first(&inside[1]),
            non_monotone[1]
        ),
        target: "monotone in ρ; inside origin hits the far root, never t ≤ 0",
        verdict: yes_if(robust_ok && !zero_to(&graze[0], 5)),
        chart: Some(chart(
            "S4: grazing rays and inside origins",
            "10⁻ᵏ (distance from the surface / r)",
            "wrong verdicts, %",
            false,
            vec![
                Series::new("grazing, lecture", x(&graze[0])),
                Series::new("grazing, robust", x(&graze[1])),
                Series::new("inside, lecture", x(&inside[0])),
                Series::new("inside, robust", x(&inside[1])),
            ],
        )),
    }
}
