//! The stability matrix of `STABILITY.md`: for each row, the measurement (a function of the
//! method, the point of the sweep and a seeded RNG) and the row as a whole ([`super::rows`]: the
//! sweep, a headline for the naive and the robust method, a pass/fail against the target and
//! a chart). `raytree stability` prints the rows; `tests/stability.rs` and `tests/geometry.rs`
//! call the very same measurement functions with fewer rays and assert the documented points.
//!
//! Conventions (STABILITY.md): `f32` everywhere, the same `f32` inputs replayed in `f64` as the
//! oracle (`sphere_roots_f64`, `triangle_hit_f64`), log-spaced sweeps, a seeded [`Pcg`].

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::time::Instant;

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::meshes::{octasphere, triangles};
use crate::accel::{Accel, AccelKind, PrimSet};
use crate::geometry::sphere::sphere_roots_f64;
use crate::geometry::triangle::triangle_hit_f64;
use crate::geometry::{
    Methods, OffsetMethod, Ray, ShadingNormals, SphereMethod, TriangleMethod, intersect_sphere,
    intersect_triangle, next_float_up, offset_ray_origin, sphere_hit_point, triangle_hit_point,
};
use crate::render::render;
use crate::rng::Pcg;
use crate::scene::{
    Light, Material, MaterialId, MeshAttributes, Object, ObjectId, ObjectSource, Scene, Triangle,
};
use crate::shade::refract;
use crate::trace::{
    RayCounts, RayKind, Recorder, SampleInfo, ShadowTest, SurfaceHit, TraceSettings, Tracer,
};

/// The spacing of `f32` values at `|x|`.
pub fn ulp(x: f32) -> f32 {
    let x = x.abs();
    next_float_up(x) - x
}

/// `10^k` as `f32`.
pub fn p10(k: i32) -> f32 {
    10f32.powi(k)
}

/// `count` as a percentage of `of`.
pub fn pct(count: usize, of: usize) -> f64 {
    100.0 * count as f64 / of.max(1) as f64
}

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

/// `n` random trials of `trial`: each returns `None` when its setup is not one the oracle can
/// judge (skipped), else whether the method failed. Returns (trials judged, failures).
fn trials(
    n: usize,
    rng: &mut Pcg,
    mut trial: impl FnMut(&mut Pcg) -> Option<bool>,
) -> (usize, usize) {
    (0..n)
        .filter_map(|_| trial(rng))
        .fold((0, 0), |(tested, failed), f| {
            (tested + 1, failed + usize::from(f))
        })
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

// =============================================================================================
// T5: small triangles far from the ray origin

/// Rays from `distance` (in triangle sizes) at random triangles of size 1 near the origin, seen
/// at up to `max_tilt_deg` from face-on, through a point the `f64` oracle puts well inside
/// (every barycentric ≥ 0.1). Returns (tested, misses). The watertight test's conservative
/// `t > δt` check (pbrt-v4) grows with the ray-relative coordinates: far enough away it
/// rejects the hit itself.
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
            let mut scene = super::scaling::scaling_scene(8, 48, 36);
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

// =============================================================================================
// A1, A2, A3: ray-origin offsets against scale, grazing lights, secondary rays

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

/// A1/A3 on a sphere of radius `r` whose centre is `center_dist` from the origin (STABILITY:
/// `4.2·r`), hit by camera rays from a few radii away.
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

// =============================================================================================
// R1: refraction

/// The refraction as commonly written without the total-internal-reflection check: glam's
/// `Vec3::refract` (which returns the zero vector on TIR), normalised as a direction must be.
pub fn refract_unguarded(u: Vec3, n: Vec3, eta: f32) -> Vec3 {
    u.refract(n, eta).normalize()
}

/// R1 figures for one index of refraction and direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RefractCell {
    pub ior: f32,
    pub entering: bool,
    pub rays: usize,
    /// Rays past the critical angle (exact arithmetic on the `f32` inputs).
    pub tir: usize,
    /// NaN directions from [`refract_unguarded`].
    pub naive_nan: usize,
    /// NaN directions from `shade::refract`.
    pub guarded_nan: usize,
    /// Rays where `shade::refract` reports TIR and exact arithmetic does not, or the reverse
    /// (ignoring rays within `1e-6` of the critical angle).
    pub tir_mismatch: usize,
    /// Largest `| |T| − 1 |`.
    pub max_len_err: f64,
    /// Largest `|(ηt/ηi)·sin θt − sin θi|`, in `f64` from the `f32` vectors.
    pub max_snell_residual: f64,
    /// Largest `|refract(−T, −n, 1/η) + u|`: refraction reversed must give the incoming ray.
    /// Near the critical angle `cos θt = sqrt(k)` turns an `ε` error of `k` into `sqrt(ε)`.
    pub max_roundtrip_err: f64,
    /// The same for rays with `cos θi ≥ 0.1` and `cos θt ≥ 0.1` (neither grazing, away from
    /// the critical angle).
    pub max_roundtrip_err_regular: f64,
    /// Reversed refractions that reported TIR.
    pub roundtrip_tir: usize,
}

/// R1: `n` rays with `cos θi` evenly from 1 to 0 at random orientations, into (`entering`) or
/// out of a medium of index `ior`.
pub fn refract_cell(ior: f32, entering: bool, n: usize, rng: &mut Pcg) -> RefractCell {
    let eta = if entering { 1.0 / ior } else { ior };
    let mut cell = RefractCell {
        ior,
        entering,
        rays: n,
        ..RefractCell::default()
    };
    for i in 0..n {
        let cos_i = 1.0 - i as f32 / (n.max(2) - 1) as f32;
        let nrm = rng.unit();
        let tangent = rng.perpendicular(nrm);
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        let u = (sin_i * tangent - cos_i * nrm).normalize();
        // Exact TIR test on the f32 inputs.
        let cos_exact = -DVec3::from(u).dot(DVec3::from(nrm));
        let k = 1.0 - f64::from(eta).powi(2) * (1.0 - cos_exact * cos_exact);
        let tir = k < 0.0;
        cell.tir += usize::from(tir);
        cell.naive_nan += usize::from(refract_unguarded(u, nrm, eta).is_nan());
        let guarded = refract(u, nrm, eta);
        if guarded.is_none() != tir && k.abs() > 1e-6 {
            cell.tir_mismatch += 1;
        }
        let Some(t) = guarded else { continue };
        cell.guarded_nan += usize::from(t.is_nan());
        let (td, ud, nd) = (DVec3::from(t), DVec3::from(u), DVec3::from(nrm));
        cell.max_len_err = cell.max_len_err.max((td.length() - 1.0).abs());
        let sin_t = td.cross(nd).length() / td.length();
        let sin_i = ud.cross(nd).length() / ud.length();
        // STABILITY's form: η·sin θt − sin θi with η = ηt/ηi = 1/eta.
        let residual = (sin_t / f64::from(eta) - sin_i).abs();
        cell.max_snell_residual = cell.max_snell_residual.max(residual);
        match refract(-t, -nrm, 1.0 / eta) {
            Some(back) => {
                let err = (DVec3::from(back) + ud).length();
                cell.max_roundtrip_err = cell.max_roundtrip_err.max(err);
                if td.dot(nd).abs() >= 0.1 && cos_exact >= 0.1 {
                    cell.max_roundtrip_err_regular = cell.max_roundtrip_err_regular.max(err);
                }
            }
            None => cell.roundtrip_tir += 1,
        }
    }
    cell
}

/// `refract` with `η = 1`: the largest `|T − u|` over `n` random rays (STABILITY: `T = u`).
pub fn refract_identity_err(n: usize, rng: &mut Pcg) -> f64 {
    let mut worst = 0f64;
    for _ in 0..n {
        let nrm = rng.unit();
        let mut u = rng.unit();
        if u.dot(nrm) > 0.0 {
            u = -u;
        }
        if let Some(t) = refract(u, nrm, 1.0) {
            worst = worst.max((DVec3::from(t) - DVec3::from(u)).length());
        } else {
            worst = f64::INFINITY;
        }
    }
    worst
}

// =============================================================================================
// B2: pathological BVH builds

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

// =============================================================================================
// N1–N3: shading normals on flat triangles (Hanika 2021 for N1)

/// What the measurements of N1–N3 need from one traced primary ray: its hit's normals, the
/// first light's shadow test, and the directions (and corrections) of its children. A
/// [`Recorder`] over the tracer's own code, so the measured behaviour is the renderer's.
#[derive(Default)]
struct FirstHit {
    depth: Vec<u32>,
    shading: Option<Vec3>,
    geometric: Option<Vec3>,
    shadow: Option<ShadowTest>,
    /// (reflected?, direction, corrected) of each child of the primary hit.
    children: Vec<(bool, Vec3, bool)>,
}

impl Recorder for FirstHit {
    const ENABLED: bool = true;
    fn enter(&mut self, kind: RayKind, depth: u32, ray: &Ray, _weight: Vec3) {
        self.depth.push(depth);
        if depth == 1 {
            self.children
                .push((kind == RayKind::Reflected, ray.dir, false));
        }
    }
    fn direction_corrected(&mut self) {
        if self.depth.last() == Some(&1)
            && let Some(c) = self.children.last_mut()
        {
            c.2 = true;
        }
    }
    fn hit(&mut self, hit: &SurfaceHit, _view: Vec3) {
        if self.depth.last() == Some(&0) {
            self.shading = Some(hit.normal);
            self.geometric = Some(hit.geometric_normal);
        }
    }
    fn shadow(&mut self, test: &ShadowTest) {
        if self.depth.last() == Some(&0) && self.shadow.is_none() {
            self.shadow = Some(*test);
        }
    }
    fn leave(&mut self, _color: Vec3) {
        self.depth.pop();
    }
}

/// A scene of one mesh given as vertices, triangles and unit vertex normals (shared by index),
/// material `material`, lit by white point light `light`, no ambient light, depth `max_depth`.
pub fn smooth_mesh_scene(
    verts: &[Vec3],
    tris: &[[usize; 3]],
    normals: &[Vec3],
    material: Material,
    light: Vec3,
    max_depth: u32,
) -> Scene {
    let mut scene = Scene {
        materials: vec![material],
        objects: vec![Object {
            name: "mesh".into(),
            source: ObjectSource::Triangle,
        }],
        lights: vec![Light {
            name: "light".into(),
            position: light,
            color: Vec3::ONE,
            radius: 0.0,
            follow_camera: false,
        }],
        ..Scene::default()
    };
    scene.render.ambient_light = Vec3::ZERO;
    scene.render.max_depth = max_depth;
    scene.triangles = tris
        .iter()
        .map(|t| Triangle {
            vertices: t.map(|i| verts[i]),
            material: MaterialId(0),
            object: ObjectId(0),
        })
        .collect::<Vec<_>>()
        .into();
    scene.attributes.push(Arc::new(MeshAttributes {
        first_triangle: 0,
        triangle_count: tris.len() as u32,
        normals: normals.to_vec(),
        normal_indices: tris.iter().map(|t| t.map(|i| i as u32)).collect(),
        ..MeshAttributes::default()
    }));
    scene
}

fn tracer_for(scene: Scene, shading_normals: ShadingNormals) -> Tracer {
    let settings = TraceSettings {
        accel: AccelKind::Bvh,
        methods: Methods {
            shading_normals,
            ..Methods::default()
        },
        cutoff: 0.0,
    };
    Tracer::new(Arc::new(scene), settings)
}

fn trace_first(tracer: &Tracer, ray: &Ray) -> (Vec3, FirstHit) {
    let mut rec = FirstHit::default();
    let mut counts = RayCounts::default();
    let mut info = SampleInfo::default();
    let c = tracer.trace(
        ray,
        RayKind::Primary,
        0,
        Vec3::ONE,
        &mut counts,
        &mut info,
        &mut rec,
    );
    (c, rec)
}

/// One cell of N1: a unit octasphere of `8·4^level` triangles with exact (radial) vertex
/// normals, diffuse only, lit by a distant light, sampled at `n` points spread uniformly over
/// the sphere (each ray aimed at the centre).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TerminatorCell {
    pub triangles: usize,
    /// Samples whose shading normal faces the light (`N·L > 0`).
    pub lit_by_normal: usize,
    /// Of those, the ones the mesh shadows itself (blocked by its own triangles, or — robust —
    /// counted as behind the geometric surface).
    pub self_shadowed: usize,
    /// The widest self-shadowed band: the largest `N·L` of a self-shadowed sample, as the angle
    /// above the terminator in degrees.
    pub band_deg: f64,
    /// The angle between neighbouring vertex normals (the facets' curvature error), degrees.
    pub facet_deg: f64,
    /// Mean |mesh − analytic sphere| of the diffuse value over all samples.
    pub mean_err: f64,
    /// The same for the shadow-free smooth mesh (`max(N·L, 0)`): the flat-free limit.
    pub limit_err: f64,
}

/// N1 at one tessellation level and light direction `to_light`.
pub fn terminator_cell(
    shading_normals: ShadingNormals,
    level: u32,
    to_light: Vec3,
    n: usize,
    rng: &mut Pcg,
) -> TerminatorCell {
    let (verts, tris) = octasphere(level, 1.0, Vec3::ZERO);
    let material = Material {
        ambient: Vec3::ZERO,
        diffuse: Vec3::ONE,
        specular: Vec3::ZERO,
        ..Material::default()
    };
    let l = to_light.normalize();
    let scene = smooth_mesh_scene(&verts, &tris, &verts, material, 1e3 * l, 0);
    let tracer = tracer_for(scene, shading_normals);
    let facet_deg = tris.first().map_or(0.0, |t| {
        verts[t[0]].angle_between(verts[t[1]]).to_degrees() as f64
    });
    let mut cell = TerminatorCell {
        triangles: tris.len(),
        facet_deg,
        ..TerminatorCell::default()
    };
    let (mut err, mut limit) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let q = rng.unit();
        let ray = Ray::new(3.0 * q, -q);
        let (c, rec) = trace_first(&tracer, &ray);
        // The analytic sphere's value where the same ray meets it (at q, normal q).
        let analytic = q.dot((1e3 * l - q).normalize()).max(0.0);
        err += f64::from((c.x - analytic).abs());
        let (Some(ns), Some(test)) = (rec.shading, rec.shadow) else {
            continue;
        };
        let ideal = ns.dot(test.to_light).max(0.0);
        limit += f64::from((ideal - analytic).abs());
        if ns.dot(test.to_light) > 0.0 {
            cell.lit_by_normal += 1;
            let shadowed = test.behind_surface || test.blocked_by == Some(ObjectId(0));
            if shadowed {
                cell.self_shadowed += 1;
                let above = f64::from(ns.dot(test.to_light))
                    .clamp(-1.0, 1.0)
                    .asin()
                    .to_degrees();
                cell.band_deg = cell.band_deg.max(above);
            }
        }
    }
    cell.mean_err = err / n.max(1) as f64;
    cell.limit_err = limit / n.max(1) as f64;
    cell
}

/// One cell of N2: reflected (or refracted) directions about the shading normal of a smooth
/// octasphere, for rays meeting it at `view_deg` from its (analytic) normal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SideCell {
    pub triangles: usize,
    pub view_deg: f32,
    pub children: usize,
    /// Children on the wrong side of the geometric plane of the surface they leave.
    pub wrong_side: usize,
    /// Children the tracer marked as corrected.
    pub corrected: usize,
}

/// N2 at one tessellation level and view angle from the shading normal; `refract`: a glass sphere (its refracted
/// children), else a mirror (its reflected children).
pub fn side_cell(
    shading_normals: ShadingNormals,
    level: u32,
    view_deg: f32,
    refract: bool,
    n: usize,
    rng: &mut Pcg,
) -> SideCell {
    let (verts, tris) = octasphere(level, 1.0, Vec3::ZERO);
    let material = Material {
        reflectivity: Vec3::splat(if refract { 0.0 } else { 1.0 }),
        transparency: Vec3::splat(if refract { 1.0 } else { 0.0 }),
        ior: 1.5,
        ..Material::default()
    };
    let scene = smooth_mesh_scene(&verts, &tris, &verts, material, Vec3::splat(100.0), 1);
    let tracer = tracer_for(scene, shading_normals);
    let mut cell = SideCell {
        triangles: tris.len(),
        view_deg,
        ..SideCell::default()
    };
    let theta = view_deg.to_radians();
    for _ in 0..n {
        // A point spread over the mesh, and a ray meeting it at `view_deg` from its shading
        // normal (from outside; a ray coming at the face from behind meets another first).
        let tri = tris[rng.below(tris.len())];
        let (mut b1, mut b2) = (rng.f32(), rng.f32());
        if b1 + b2 > 1.0 {
            (b1, b2) = (1.0 - b1, 1.0 - b2);
        }
        let b = [1.0 - b1 - b2, b1, b2];
        let p = b[0] * verts[tri[0]] + b[1] * verts[tri[1]] + b[2] * verts[tri[2]];
        let ns = p.normalize();
        let t = rng.perpendicular(ns);
        let d = -(theta.cos() * ns + theta.sin() * t);
        let ray = Ray::new(p - 3.0 * d, d);
        let (_, rec) = trace_first(&tracer, &ray);
        let Some(ng) = rec.geometric else { continue };
        for &(reflected, dir, corrected) in &rec.children {
            if reflected == refract {
                continue;
            }
            cell.children += 1;
            let side = dir.dot(ng);
            let wrong = if reflected { side <= 0.0 } else { side >= 0.0 };
            cell.wrong_side += usize::from(wrong);
            cell.corrected += usize::from(corrected);
        }
    }
    cell
}

/// One cell of N3: a large flat wall (the plane z = 0, seen from z > 0) whose vertex normals
/// are tilted by `tilt_deg`, and a light behind it at `below_deg` under its plane; the share
/// of the wall's samples that the light reaches through it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LeakCell3 {
    pub tilt_deg: f32,
    pub below_deg: f32,
    pub samples: usize,
    /// Samples whose shading normal faces the light (the candidates for a leak).
    pub facing: usize,
    /// Samples lit by the light behind the wall.
    pub leaks: usize,
}

/// N3 at one normal tilt and light angle.
pub fn leak_cell(
    shading_normals: ShadingNormals,
    tilt_deg: f32,
    below_deg: f32,
    n: usize,
    rng: &mut Pcg,
) -> LeakCell3 {
    // A 2×2 grid of quads over ±100, so the wall separates the light from every sample.
    let s = 100.0;
    let verts: Vec<Vec3> = (0..9)
        .map(|i| Vec3::new(((i % 3) as f32 - 1.0) * s, ((i / 3) as f32 - 1.0) * s, 0.0))
        .collect();
    let mut tris = Vec::new();
    for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let a = y * 3 + x;
        tris.push([a, a + 1, a + 4]);
        tris.push([a, a + 4, a + 3]);
    }
    // Normals tilted towards +x (alternating direction by vertex, as a badly exported file).
    let tilt = tilt_deg.to_radians();
    let normals: Vec<Vec3> = (0..9)
        .map(|i| {
            let sign = if i % 2 == 0 { 1.0 } else { 0.5 };
            Vec3::new(sign * tilt.sin(), 0.0, tilt.cos()).normalize()
        })
        .collect();
    let below = below_deg.to_radians();
    // The light behind the wall, towards +x: the tilted normals face it.
    let light = Vec3::new(20.0 * below.cos(), 0.0, -20.0 * below.sin());
    let scene = smooth_mesh_scene(&verts, &tris, &normals, Material::default(), light, 0);
    let tracer = tracer_for(scene, shading_normals);
    let mut cell = LeakCell3 {
        tilt_deg,
        below_deg,
        ..LeakCell3::default()
    };
    for _ in 0..n {
        let p = Vec3::new(rng.range(-20.0, 20.0), rng.range(-20.0, 20.0), 0.0);
        let ray = Ray::new(p + Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let (_, rec) = trace_first(&tracer, &ray);
        let Some(test) = rec.shadow else { continue };
        cell.samples += 1;
        if test.terms.n_dot_l > 0.0 {
            cell.facing += 1;
            if test.blocked_by.is_none() && !test.behind_surface {
                cell.leaks += 1;
            }
        }
    }
    cell
}
