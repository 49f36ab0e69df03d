//! A1-A3: ray-origin offsets (docs/stability.md, rows A1 to A3). Shadow acne and contact
//! leaks against scene scale, acne under a grazing light, secondary rays that re-hit the
//! surface they leave.

use glam::Vec3;
use serde::Serialize;

use super::{Row, StabilityOptions, at, chart, p10, ulp, yes_if};
use crate::experiments::chart::Series;
use crate::geometry::{
    OffsetMethod, Ray, SphereMethod, TriangleMethod, intersect_sphere, intersect_triangle,
    offset_ray_origin, sphere_hit_point, triangle_hit_point,
};
use crate::rng::Pcg;

// =============================================================================================
// A1, A3: ray-origin offsets against scale, secondary rays

/// Shares of secondary rays that meet the surface they leave.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SelfHits {
    /// Surface points tested (camera rays that hit).
    pub points: usize,
    /// Shadow rays (towards a light on the outside, down to grazing) that hit their own
    /// surface: acne, as a fraction.
    pub acne: f64,
    /// Reflected rays that hit their own surface.
    pub reflected: f64,
    /// Transmitted rays that hit the surface again (for spheres: before 1% of the chord).
    pub transmitted: f64,
}

/// A point where a camera ray from a few radii away meets the sphere (robust method): the ray,
/// the re-projected point, its error bound and the outward unit normal.
fn sphere_sample(center: Vec3, r: f32, rng: &mut Pcg) -> Option<(Ray, Vec3, Vec3, Vec3)> {
    let sm = SphereMethod::Robust;
    let origin = center + rng.unit() * (3.0 * r);
    let aim = center + rng.unit() * (0.9 * r);
    let ray = Ray::new(origin, (aim - origin).normalize());
    let t = intersect_sphere(sm, center, r, &ray, 0.0, f32::INFINITY)?;
    let (p, err) = sphere_hit_point(sm, center, r, &ray, t);
    Some((ray, p, err, (p - center).normalize()))
}

/// A point where a ray from `2·s` away, from either side, meets triangle `v` (unit normal
/// `geo_n`) with method `tm`: the ray, the point, its error bound, and the normal turned
/// towards the ray.
fn triangle_sample(
    v: &[Vec3; 3],
    geo_n: Vec3,
    tm: TriangleMethod,
    s: f32,
    rng: &mut Pcg,
) -> Option<(Ray, Vec3, Vec3, Vec3)> {
    let side = if rng.f32() < 0.5 { geo_n } else { -geo_n };
    let (b1, b2) = (rng.f32(), rng.f32());
    let (b1, b2) = if b1 + b2 > 1.0 {
        (1.0 - b1, 1.0 - b2)
    } else {
        (b1, b2)
    };
    let target = v[0] + b1 * (v[1] - v[0]) + b2 * (v[2] - v[0]);
    let origin = target + (side + 0.5 * rng.unit()).normalize() * (2.0 * s);
    let ray = Ray::new(origin, (target - origin).normalize());
    let hit = intersect_triangle(tm, v, &ray, 0.0, f32::INFINITY)?;
    let (p, err) = triangle_hit_point(v, hit.b1, hit.b2);
    let facing = if ray.dir.dot(geo_n) < 0.0 {
        geo_n
    } else {
        -geo_n
    };
    Some((ray, p, err, facing))
}

/// A1/A3 on a sphere of radius `r` whose centre is `center_dist` from the origin (the rows use
/// `4.2·r`, docs/stability.md, row A1), hit by camera rays from a few radii away.
pub fn sphere_self_hits(
    method: OffsetMethod,
    r: f32,
    center_dist: f32,
    n: usize,
    rng: &mut Pcg,
) -> SelfHits {
    let center = rng.unit() * center_dist;
    let sm = SphereMethod::Robust;
    let (mut points, mut acne, mut refl, mut trans) = (0, 0, 0, 0);
    for _ in 0..n {
        let Some((ray, p, err, nrm)) = sphere_sample(center, r, rng) else {
            continue;
        };
        points += 1;
        let hits = |dir: Vec3| {
            let o = offset_ray_origin(method, p, err, nrm, dir);
            intersect_sphere(sm, center, r, &Ray::new(o, dir), 0.0, f32::INFINITY)
        };
        // Shadow ray to a light on the outside (also grazing ones).
        let light_dir = (nrm + rng.range(0.0, 3.0) * rng.perpendicular(nrm)).normalize();
        acne += usize::from(hits(light_dir).is_some());
        // Reflection leaves a convex surface for good.
        let refl_dir = ray.dir - 2.0 * ray.dir.dot(nrm) * nrm;
        refl += usize::from(hits(refl_dir).is_some());
        // Transmission: must reach the far side (chord 2r·cos), not re-hit the entry point.
        let tdir = (-nrm + 0.8 * rng.perpendicular(nrm)).normalize();
        let chord = 2.0 * r * (-nrm.dot(tdir));
        trans += usize::from(hits(tdir).is_none_or(|t| t < 0.01 * chord));
    }
    let f = |c: usize| c as f64 / points.max(1) as f64;
    SelfHits {
        points,
        acne: f(acne),
        reflected: f(refl),
        transmitted: f(trans),
    }
}

/// A1/A3 on a random triangle of size `s` whose centre is `center_dist` from the origin, hit
/// from both sides with `tm`: any hit of its own plane by a secondary ray is wrong.
pub fn triangle_self_hits(
    method: OffsetMethod,
    tm: TriangleMethod,
    s: f32,
    center_dist: f32,
    n: usize,
    rng: &mut Pcg,
) -> SelfHits {
    let c = rng.unit() * center_dist;
    let v = [c + rng.unit() * s, c + rng.unit() * s, c + rng.unit() * s];
    let geo_n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    let (mut points, mut acne, mut refl, mut trans) = (0, 0, 0, 0);
    for _ in 0..n {
        let Some((ray, p, err, facing)) = triangle_sample(&v, geo_n, tm, s, rng) else {
            continue;
        };
        points += 1;
        let hits = |dir: Vec3| {
            let o = offset_ray_origin(method, p, err, geo_n, dir);
            intersect_triangle(tm, &v, &Ray::new(o, dir), 0.0, f32::INFINITY).is_some()
        };
        // Shadow ray to a light on the side the ray came from, down to grazing elevations.
        let light = (facing * rng.range(0.01, 1.0) + rng.perpendicular(facing)).normalize();
        acne += usize::from(hits(light));
        // Reflected and transmitted rays: neither may meet the plane again.
        let refl_dir = ray.dir - 2.0 * ray.dir.dot(geo_n) * geo_n;
        refl += usize::from(hits(refl_dir));
        trans += usize::from(hits(ray.dir));
    }
    let f = |c: usize| c as f64 / points.max(1) as f64;
    SelfHits {
        points,
        acne: f(acne),
        reflected: f(refl),
        transmitted: f(trans),
    }
}

/// A point on a ground triangle of size `s` (about `4.2·s` from the origin) with a small
/// occluder parallel to it at height `gap` right above; the shadow ray straight up must be
/// blocked. Returns whether it leaks.
pub fn contact_leaks(method: OffsetMethod, s: f32, gap: f32, rng: &mut Pcg) -> bool {
    let c = Vec3::new(4.2 * s, rng.range(-0.1, 0.1) * s, 0.3 * s);
    let ground = [
        c + Vec3::new(-s, 0.0, -s),
        c + Vec3::new(s, 0.0, -s),
        c + Vec3::new(0.0, 0.0, s),
    ];
    let ray = Ray::new(
        c + Vec3::new(0.1 * s, 2.0 * s, 0.05 * s),
        Vec3::new(-0.05, -1.0, -0.02).normalize(),
    );
    let Some(hit) = intersect_triangle(
        TriangleMethod::Watertight,
        &ground,
        &ray,
        0.0,
        f32::INFINITY,
    ) else {
        return false;
    };
    let (p, err) = triangle_hit_point(&ground, hit.b1, hit.b2);
    let h = p.y + gap;
    let occluder = [
        Vec3::new(p.x - 0.01 * s, h, p.z - 0.01 * s),
        Vec3::new(p.x + 0.01 * s, h, p.z - 0.01 * s),
        Vec3::new(p.x, h, p.z + 0.01 * s),
    ];
    let o = offset_ray_origin(method, p, err, Vec3::Y, Vec3::Y);
    intersect_triangle(
        TriangleMethod::Watertight,
        &occluder,
        &Ray::new(o, Vec3::Y),
        0.0,
        10.0 * s,
    )
    .is_none()
}

/// Share of `n` contact points whose shadow ray leaks through an occluder `gap` above.
pub fn contact_leak_rate(method: OffsetMethod, s: f32, gap: f32, n: usize, rng: &mut Pcg) -> f64 {
    let leaks = (0..n)
        .filter(|_| contact_leaks(method, s, gap, rng))
        .count();
    leaks as f64 / n.max(1) as f64
}

const A1_SCALES: [i32; 9] = [-3, -2, -1, 0, 1, 2, 3, 4, 5];

pub(super) fn row_a1(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let methods = [
        OffsetMethod::Fixed,
        OffsetMethod::NormalScaled,
        OffsetMethod::ErrorBound,
    ];
    let names = ["fixed 1e-4", "normal-scaled", "error-bound"];
    let mut acne = vec![Vec::new(); 3];
    let mut tri_acne = vec![Vec::new(); 3];
    let mut leak = vec![Vec::new(); 3];
    let n_contact = (o.rays / 20).max(50);
    for &k in &A1_SCALES {
        let s = p10(k);
        for (i, &m) in methods.iter().enumerate() {
            acne[i].push((
                s as f64,
                100.0 * sphere_self_hits(m, s, 4.2 * s, o.rays, rng).acne,
            ));
            let t = triangle_self_hits(m, TriangleMethod::MollerTrumbore, s, 4.2 * s, o.rays, rng);
            tri_acne[i].push((s as f64, 100.0 * t.acne));
            let l = contact_leak_rate(m, s, 1e-3 * s, n_contact, rng);
            leak[i].push((s as f64, 100.0 * l));
        }
    }
    // Small objects far from the origin: |centre| = 4.2e3 for S = 1e-2…1e2.
    let mut far = vec![Vec::new(); 3];
    for k in -2..=2 {
        let s = p10(k);
        for (i, &m) in methods.iter().enumerate() {
            far[i].push((
                s as f64,
                100.0 * sphere_self_hits(m, s, 4.2e3, o.rays, rng).acne,
            ));
        }
    }
    // The error-bound offset's contact leak against the gap, in ulp(|P|).
    let gaps = [1.0f32, 2.0, 5.0, 10.0, 20.0, 40.0, 100.0];
    let mut min_gap = 0.0;
    for &g in gaps.iter().rev() {
        let leaks: f64 = [-3, 0, 3]
            .iter()
            .map(|&k| {
                let s = p10(k);
                contact_leak_rate(
                    OffsetMethod::ErrorBound,
                    s,
                    g * ulp(4.2 * s),
                    n_contact,
                    rng,
                )
            })
            .sum();
        if leaks > 0.0 {
            break;
        }
        min_gap = g;
    }
    let eb_acne = acne[2]
        .iter()
        .chain(&tri_acne[2])
        .chain(&far[2])
        .map(|p| p.1)
        .fold(0.0, f64::max);
    let eb_leak = leak[2].iter().map(|p| p.1).fold(0.0, f64::max);
    let mut series = Vec::new();
    for i in 0..3 {
        series.push(Series::new(
            format!("acne, sphere, {}", names[i]),
            acne[i].clone(),
        ));
    }
    series.push(Series::new(
        "acne, MT triangle, fixed 1e-4",
        tri_acne[0].clone(),
    ));
    series.push(Series::new(
        "acne, sphere at 4.2e3, fixed 1e-4",
        far[0].clone(),
    ));
    for i in 0..3 {
        series.push(Series::new(format!("leak, {}", names[i]), leak[i].clone()));
    }
    Row {
        id: "A1",
        failure: "shadow acne and contact-shadow leaks against scene scale",
        naive_method: "fixed 1e-4 along n; 1e-5·max(1, |p|) along n",
        robust_method: "error-bound offset (pbrt-v4), rounded outwards",
        sweep: format!(
            "S = 1e-3…1e5 at |centre| 4.2·S, and S = 1e-2…1e2 at |centre| 4.2e3; {} rays per \
             cell, {n_contact} contact points",
            o.rays
        ),
        naive: format!(
            "fixed: sphere acne {:.0}% @1e3, {:.0}% @1e4, {:.0}% @1e5, MT-triangle acne {:.0}% @1e4; \
             small spheres at 4.2e3: {:.0}% @1e-2, {:.0}% @1; contact leak {:.0}% @1e-3, {:.0}% @1e-2 \
             (normal-scaled: {:.0}% @1e-3)",
            at(&acne[0], 1e3),
            at(&acne[0], 1e4),
            at(&acne[0], 1e5),
            at(&tri_acne[0], 1e4),
            at(&far[0], 1e-2),
            at(&far[0], 1.0),
            at(&leak[0], 1e-3),
            at(&leak[0], 1e-2),
            at(&leak[1], 1e-3),
        ),
        robust: format!(
            "acne {eb_acne:.2}% at every S (spheres, triangles, far small spheres); contact \
             leak {eb_leak:.1}% for gaps of 1e-3·S; 0 leaks down to a gap of {min_gap} ulp(|P|)"
        ),
        target: "0% acne at all S; 0% leak while gap ≥ 40 ulp(|P|)",
        verdict: yes_if(
            eb_acne == 0.0 && eb_leak == 0.0 && min_gap <= 40.0 && at(&acne[0], 1e4) > 10.0,
        ),
        chart: Some(chart(
            "A1: shadow acne and contact leaks against scene scale",
            "scene scale S",
            "% of shadow rays",
            false,
            series,
        )),
    }
}

// =============================================================================================
// A2: a grazing light

/// The surface an A2 sweep shines a grazing light on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Surface {
    Sphere,
    Triangle(TriangleMethod),
}

/// A2: acne fraction for a light at `elevation_deg` above the tangent plane, on a sphere of
/// radius `s` or a triangle of size `s`, `4.2·s` from the origin.
pub fn grazing_light_acne(
    method: OffsetMethod,
    surface: Surface,
    s: f32,
    elevation_deg: f32,
    n: usize,
    rng: &mut Pcg,
) -> f64 {
    let (sin_e, cos_e) = elevation_deg.to_radians().sin_cos();
    let c = rng.unit() * (4.2 * s);
    let tri = [c + rng.unit() * s, c + rng.unit() * s, c + rng.unit() * s];
    let tri_n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
    let (mut points, mut acne) = (0, 0);
    for _ in 0..n {
        match surface {
            Surface::Sphere => {
                let Some((_, p, err, nrm)) = sphere_sample(c, s, rng) else {
                    continue;
                };
                points += 1;
                let l = (cos_e * rng.perpendicular(nrm) + sin_e * nrm).normalize();
                let o = offset_ray_origin(method, p, err, nrm, l);
                let sm = SphereMethod::Robust;
                acne += usize::from(
                    intersect_sphere(sm, c, s, &Ray::new(o, l), 0.0, f32::INFINITY).is_some(),
                );
            }
            Surface::Triangle(tm) => {
                let Some((_, p, err, facing)) = triangle_sample(&tri, tri_n, tm, s, rng) else {
                    continue;
                };
                points += 1;
                let l = (cos_e * rng.perpendicular(facing) + sin_e * facing).normalize();
                let o = offset_ray_origin(method, p, err, tri_n, l);
                acne += usize::from(
                    intersect_triangle(tm, &tri, &Ray::new(o, l), 0.0, f32::INFINITY).is_some(),
                );
            }
        }
    }
    acne as f64 / points.max(1) as f64
}

pub(super) fn row_a2(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let elevations = [90.0f32, 30.0, 10.0, 3.0, 1.0, 0.3, 0.1, 0.03, 0.01];
    let cases = [
        (
            "sphere, fixed, S = 1e3",
            OffsetMethod::Fixed,
            Surface::Sphere,
            1e3f32,
        ),
        (
            "MT triangle, fixed, S = 1e3",
            OffsetMethod::Fixed,
            Surface::Triangle(TriangleMethod::MollerTrumbore),
            1e3,
        ),
        (
            "sphere, error-bound, S = 1e3",
            OffsetMethod::ErrorBound,
            Surface::Sphere,
            1e3,
        ),
        (
            "watertight triangle, error-bound, S = 1e3",
            OffsetMethod::ErrorBound,
            Surface::Triangle(TriangleMethod::Watertight),
            1e3,
        ),
        (
            "sphere, error-bound, S = 1",
            OffsetMethod::ErrorBound,
            Surface::Sphere,
            1.0,
        ),
        (
            "watertight triangle, error-bound, S = 1",
            OffsetMethod::ErrorBound,
            Surface::Triangle(TriangleMethod::Watertight),
            1.0,
        ),
    ];
    let n = (o.rays / 2).max(200);
    let series: Vec<Series> = cases
        .iter()
        .map(|&(name, m, surf, s)| {
            Series::new(
                name,
                elevations
                    .iter()
                    .map(|&e| (e as f64, 100.0 * grazing_light_acne(m, surf, s, e, n, rng)))
                    .collect(),
            )
        })
        .collect();
    let worst = |i: usize| series[i].points.iter().map(|p| p.1).fold(0.0, f64::max);
    let robust_worst = (2..6).map(worst).fold(0.0, f64::max);
    let at_grazing = |i: usize| series[i].points.last().map_or(0.0, |p| p.1);
    Row {
        id: "A2",
        failure: "shadow acne under a grazing light",
        naive_method: "fixed 1e-4",
        robust_method: "error-bound offset",
        sweep: format!("light elevation 90°…0.01°, S = 1 and 1e3, {n} points per cell"),
        naive: format!(
            "fixed at S = 1e3: sphere acne {:.0}% at 90°, {:.0}% at 0.01°; MT triangle {:.0}% at \
             90°, {:.0}% at 0.01° (a watertight triangle hides it: 0%)",
            series[0].points.first().map_or(0.0, |p| p.1),
            at_grazing(0),
            series[1].points.first().map_or(0.0, |p| p.1),
            at_grazing(1)
        ),
        robust: format!("error-bound: {robust_worst:.2}% at worst"),
        target: "0%",
        verdict: yes_if(robust_worst == 0.0),
        chart: Some(chart(
            "A2: acne against light elevation",
            "light elevation above the surface, degrees",
            "acne, % of shadow rays",
            false,
            series,
        )),
    }
}

pub(super) fn row_a3(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let methods = [
        (OffsetMethod::Fixed, "fixed 1e-4"),
        (OffsetMethod::ErrorBound, "error-bound"),
    ];
    let mut series = Vec::new();
    let mut robust_worst = 0.0f64;
    let mut naive_text = Vec::new();
    for (m, name) in methods {
        let mut refl = Vec::new();
        let mut trans = Vec::new();
        let mut tri = Vec::new();
        for &k in &A1_SCALES {
            let s = p10(k);
            let sh = sphere_self_hits(m, s, 4.2 * s, o.rays, rng);
            let th = triangle_self_hits(m, TriangleMethod::MollerTrumbore, s, 4.2 * s, o.rays, rng);
            refl.push((s as f64, 100.0 * sh.reflected));
            trans.push((s as f64, 100.0 * sh.transmitted));
            tri.push((s as f64, 50.0 * (th.reflected + th.transmitted)));
        }
        if m == OffsetMethod::ErrorBound {
            robust_worst = refl
                .iter()
                .chain(&trans)
                .chain(&tri)
                .map(|p| p.1)
                .fold(0.0, f64::max);
        } else {
            naive_text.push(format!(
                "fixed: sphere reflected {:.0}% / transmitted {:.0}% @1e4, MT triangle {:.0}% @1e4",
                at(&refl, 1e4),
                at(&trans, 1e4),
                at(&tri, 1e4)
            ));
        }
        series.push(Series::new(format!("sphere reflected, {name}"), refl));
        series.push(Series::new(format!("sphere transmitted, {name}"), trans));
        series.push(Series::new(format!("MT triangle, {name}"), tri));
    }
    Row {
        id: "A3",
        failure: "reflected and transmitted rays re-hit the surface they leave",
        naive_method: "fixed 1e-4",
        robust_method: "error-bound offset to the side of the outgoing direction",
        sweep: format!(
            "S = 1e-3…1e5 at |centre| 4.2·S, spheres and triangles, {} rays",
            o.rays
        ),
        naive: naive_text.join("; "),
        robust: format!("error-bound: {robust_worst:.2}% at worst"),
        target: "0%",
        verdict: yes_if(robust_worst == 0.0),
        chart: Some(chart(
            "A3: secondary rays that re-hit their own surface",
            "scene scale S",
            "% of secondary rays",
            false,
            series,
        )),
    }
}
