//! Ray/triangle intersection: the lecture's plane-then-barycentric method (section
//! "Ray/Triangle Intersection"), Möller–Trumbore (1997) and the watertight test of Woop,
//! Benthin and Wald (2013, "Watertight Ray/Triangle Intersection", JCGT 2(1)).
//!
//! All three test both faces and report the barycentric weights `b1`, `b2` of vertices 1 and 2
//! (vertex 0 has `1 − b1 − b2`). Each returns a `t` that does not depend on `t_min`/`t_max`
//! except through the final range check, so accelerators that shrink `t_max` see the same hit.
//!
//! Where they fail (docs/stability.md, rows T1, T3): the lecture's method and Möller–Trumbore
//! decide "inside" per triangle with independently rounded quantities, so a ray through a shared
//! edge or vertex can be outside both neighbours (a leak, a crack in the image). Möller–Trumbore
//! also rejects `|det| <` [`MT_DET_EPSILON`], which is an absolute threshold on a quantity that
//! scales with the square of the triangle's size: triangles with edges below about `1e-4` are
//! missed altogether. The watertight test shears the triangle into a ray-aligned space where the
//! three edge functions of a shared edge are computed from the same numbers in both triangles, so
//! their signs agree exactly and no ray slips between; it rejects only `det == 0`.
use glam::{DVec3, Vec3, Vec3A, Vec3Swizzles, Vec4};
use serde::{Deserialize, Serialize};

use super::lanes::Lanes;
use super::{Ray, gamma};

/// How rays meet triangles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TriangleMethod {
    /// The lecture: intersect the plane `n·p = d`, then solve for barycentric coordinates.
    Lecture,
    /// Möller–Trumbore (1997).
    MollerTrumbore,
    /// Woop, Benthin, Wald (2013): no cracks along shared edges and vertices.
    #[default]
    Watertight,
}

crate::choice::choice!(TriangleMethod {
    Watertight => ("watertight", "Woop, Benthin, Wald 2013: no cracks along shared edges"),
    MollerTrumbore => ("moller-trumbore", "Moller-Trumbore 1997"),
    Lecture => ("lecture", "the lecture's plane, then barycentric coordinates"),
});

/// A ray/triangle hit: `t` and the barycentric weights of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Möller–Trumbore's "parallel ray" threshold on `|det| = |(d × e2)·e1|`, as in the common
/// implementations (the 1997 paper uses `1e-6`; `1e-8` is the usual `f32` choice).
///
/// `det` has units of length² (for a unit direction), so this absolute threshold silently drops
/// every triangle whose edges are shorter than about `1e-4` (docs/stability.md, row T3), and needle
/// triangles seen edge-on. Kept on purpose: it is the method as taught and the sweeps show its
/// failure.
pub const MT_DET_EPSILON: f32 = 1e-8;

/// Nearest hit in `(t_min, t_max)` of the ray with triangle `v` (both faces), if any.
#[inline]
pub fn intersect_triangle(
    method: TriangleMethod,
    v: &[Vec3; 3],
    ray: &Ray,
    t_min: f32,
    t_max: f32,
) -> Option<TriHit> {
    match method {
        TriangleMethod::Lecture => lecture(v, ray, t_min, t_max),
        TriangleMethod::MollerTrumbore => moller_trumbore(v, ray, t_min, t_max),
        TriangleMethod::Watertight => watertight(v, ray, t_min, t_max),
    }
}

/// The lecture: unit normal `n = normalize((A2 − A1) × (A3 − A1))`, plane `n·p = d` with
/// `d = n·A1`, `s = (d − n·P0)/(n·u)`, then the barycentric coordinates of `P = P0 + s·u` as
/// ratios of signed sub-triangle areas (`n·((Aj − P) × (Ak − P))` over the whole area), inside
/// when all three are ≥ 0. Naive on purpose; it only refuses to divide by `n·u == 0`.
fn lecture(v: &[Vec3; 3], ray: &Ray, t_min: f32, t_max: f32) -> Option<TriHit> {
    let [a1, a2, a3] = *v;
    let cross = (a2 - a1).cross(a3 - a1);
    let n = cross.normalize();
    let d = n.dot(a1);
    let n_dot_u = n.dot(ray.dir);
    // Also rejects NaN (a degenerate triangle has no normal).
    if n_dot_u == 0.0 || n_dot_u.is_nan() {
        return None;
    }
    let s = (d - n.dot(ray.origin)) / n_dot_u;
    if !(s > t_min && s < t_max) {
        return None;
    }
    let p = ray.at(s);
    let area = n.dot(cross);
    let w1 = n.dot((a2 - p).cross(a3 - p)) / area;
    let w2 = n.dot((a3 - p).cross(a1 - p)) / area;
    let w3 = n.dot((a1 - p).cross(a2 - p)) / area;
    if !(w1 >= 0.0 && w2 >= 0.0 && w3 >= 0.0) {
        return None;
    }
    Some(TriHit {
        t: s,
        b1: w2,
        b2: w3,
    })
}

/// Möller & Trumbore (1997), "Fast, Minimum Storage Ray/Triangle Intersection", both faces.
fn moller_trumbore(v: &[Vec3; 3], ray: &Ray, t_min: f32, t_max: f32) -> Option<TriHit> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det.is_nan() || det.abs() < MT_DET_EPSILON {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = ray.origin - v[0];
    let b1 = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = ray.dir.dot(q) * inv_det;
    if !(b2 >= 0.0 && b1 + b2 <= 1.0) {
        return None;
    }
    let t = e2.dot(q) * inv_det;
    if !(t > t_min && t < t_max) {
        return None;
    }
    Some(TriHit { t, b1, b2 })
}

/// Index of the largest component (pbrt-v4 `MaxComponentIndex`: ties go to the later axis).
#[inline]
fn max_component_index(a: Vec3) -> usize {
    if a.x > a.y {
        if a.x > a.z { 0 } else { 2 }
    } else if a.y > a.z {
        1
    } else {
        2
    }
}

/// Woop, Benthin & Wald (2013), as in the paper and pbrt-v4:
/// 1. translate the vertices by `−origin`;
/// 2. permute axes so `z` is the direction's largest `|component|`;
/// 3. shear so the ray is the `+z` axis (`Sx = −dx/dz`, `Sy = −dy/dz`, `Sz = 1/dz`);
/// 4. edge functions `U, V, W` of the sheared 2D triangle in plain `f32` products (no FMA, so a
///    shared edge gives exactly negated values in its two triangles), recomputed in `f64` when
///    any is exactly 0 (the ray passes through an edge or vertex);
/// 5. reject mixed signs (outside) and `det = U + V + W == 0` only;
/// 6. the scaled distance `T = U·z0 + V·z1 + W·z2` must have the sign of `det` (hit in front);
/// 7. pbrt-v4's conservative `t > δt` (δt bounds the rounding error of `t`).
///
/// Close calls are decided again in `f64` from the same `f32` inputs (translation and shear
/// included, see `close_hit_f64`): mixed signs with an edge function within its rounding
/// error of 0, `det == 0`, and `t ≤ δt`. In `f32` the translation by the origin rounds a
/// needle's width away once it is a few ulp of its ray-relative coordinates, and δt grows
/// like ε·t²/size on a small triangle far away until it passes `t` (docs/stability.md, rows
/// T3 and T5). Each of these only turns an `f32` miss into a hit that `f64` confirms, so
/// shared edges stay watertight. On ordinary geometry the one that occurs is a ray that starts
/// exactly on an axis-aligned floor or wall and leaves it (`t ≤ δt`): the lanes' test answers
/// that one without `f64` (see `leaves_plane_of`).
///
/// The range check `t_min < t < t_max` is made on the divided `t = T/det` (not on `T` against
/// `t_max·det`) so the answer is a pure function of the triangle and the ray: the accelerators
/// rely on that to agree bit for bit.
fn watertight(v: &[Vec3; 3], ray: &Ray, t_min: f32, t_max: f32) -> Option<TriHit> {
    Shear::new(ray.dir)?.intersect(v, ray, t_min, t_max)
}

/// The per-ray part of the watertight test (steps 2 and 3: the permutation and the shear),
/// computed once per ray rather than once per triangle. [`Shear::intersect`] then does the
/// per-triangle steps with exactly the arithmetic of [`intersect_triangle`]'s watertight
/// method, so the results are identical bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shear {
    /// The axis that becomes `z` (the direction's largest `|component|`).
    kz: u8,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl Shear {
    /// `None` when the direction has no usable largest component (zero or NaN): such a ray
    /// hits no triangle.
    #[inline]
    pub fn new(d: Vec3) -> Option<Shear> {
        let kz = max_component_index(d.abs());
        // `(d[kx], d[ky], d[kz])` with `kx = kz + 1`, `ky = kx + 1` (mod 3): a rotation of the
        // components, so constant swizzles rather than three indexed reads.
        let p = match kz {
            0 => d.yzx(),
            1 => d.zxy(),
            _ => d,
        };
        let dz = p.z;
        if dz == 0.0 || dz.is_nan() {
            return None;
        }
        // One vector division for the three quotients (each lane rounds as a scalar `/`).
        let q = Vec3A::new(-p.x, -p.y, 1.0) / Vec3A::splat(dz);
        Some(Shear {
            kz: kz as u8,
            sx: q.x,
            sy: q.y,
            sz: q.z,
        })
    }

    /// Nearest hit in `(t_min, t_max)` of `ray` (whose direction made this shear) with
    /// triangle `v`, both faces.
    #[inline(always)]
    pub fn intersect(&self, v: &[Vec3; 3], ray: &Ray, t_min: f32, t_max: f32) -> Option<TriHit> {
        // One copy of the test per axis, so the permutation is constant indices.
        match self.kz {
            0 => self.intersect_k::<1, 2, 0>(v, ray, t_min, t_max),
            1 => self.intersect_k::<2, 0, 1>(v, ray, t_min, t_max),
            _ => self.intersect_k::<0, 1, 2>(v, ray, t_min, t_max),
        }
    }

    #[inline(always)]
    fn intersect_k<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        v: &[Vec3; 3],
        ray: &Ray,
        t_min: f32,
        t_max: f32,
    ) -> Option<TriHit> {
        let Shear { sx, sy, sz, .. } = *self;
        let p0 = v[0] - ray.origin;
        let p1 = v[1] - ray.origin;
        let p2 = v[2] - ray.origin;
        // Permute and shear x, y.
        let (p0x, p0y, p0z) = (p0[KX] + sx * p0[KZ], p0[KY] + sy * p0[KZ], p0[KZ]);
        let (p1x, p1y, p1z) = (p1[KX] + sx * p1[KZ], p1[KY] + sy * p1[KZ], p1[KZ]);
        let (p2x, p2y, p2z) = (p2[KX] + sx * p2[KZ], p2[KY] + sy * p2[KZ], p2[KZ]);

        let mut e0 = p1x * p2y - p1y * p2x;
        let mut e1 = p2x * p0y - p2y * p0x;
        let mut e2 = p0x * p1y - p0y * p1x;
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            // The products of two f32 are exact in f64; only the difference rounds, once.
            let f = |ax: f32, by: f32, ay: f32, bx: f32| {
                (f64::from(ax) * f64::from(by) - f64::from(ay) * f64::from(bx)) as f32
            };
            e0 = f(p1x, p2y, p1y, p2x);
            e1 = f(p2x, p0y, p2y, p0x);
            e2 = f(p0x, p1y, p0y, p1x);
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            // Outside, unless an edge function is within its rounding error of 0: a needle
            // thinner than a few ulp of its ray-relative coordinates has all of them there
            // (the translation by the origin rounds its width away). Decide those in f64.
            let m = p0x
                .abs()
                .max(p1x.abs())
                .max(p2x.abs())
                .max(p0y.abs())
                .max(p1y.abs())
                .max(p2y.abs());
            let mz = (sz * p0z).abs().max((sz * p1z).abs()).max((sz * p2z).abs());
            let bound = gamma(24) * ((m + mz) * m);
            if e0.abs() <= bound || e1.abs() <= bound || e2.abs() <= bound {
                return close_hit_f64::<KX, KY, KZ>(v, ray, t_min, t_max);
            }
            return None;
        }
        let det = e0 + e1 + e2;
        if det.is_nan() {
            return None;
        }
        if det == 0.0 {
            // All three 0 even from exact products: the rounded triangle is a segment through
            // the ray (a needle whose width rounded away), or the ray lies in its plane.
            return close_hit_f64::<KX, KY, KZ>(v, ray, t_min, t_max);
        }
        let t_scaled = e0 * (sz * p0z) + e1 * (sz * p1z) + e2 * (sz * p2z);
        if t_scaled.is_nan() || (det < 0.0 && t_scaled >= 0.0) || (det > 0.0 && t_scaled <= 0.0) {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // pbrt-v4: accept only a t conservatively greater than zero. A ray that starts on the
        // triangle's plane (an offset origin of a flat, axis-aligned floor has a zero error
        // bound along the normal) can otherwise compute a tiny positive t and shadow itself.
        let (z0, z1, z2) = ((sz * p0z).abs(), (sz * p1z).abs(), (sz * p2z).abs());
        let max_z = z0.max(z1).max(z2);
        let max_x = p0x.abs().max(p1x.abs()).max(p2x.abs());
        let max_y = p0y.abs().max(p1y.abs()).max(p2y.abs());
        let delta_z = gamma(3) * max_z;
        let delta_x = gamma(5) * (max_x + max_z);
        let delta_y = gamma(5) * (max_y + max_z);
        let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t =
            3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs();
        if t <= delta_t {
            // The bound grows like ε·t²/size on a small triangle far away, and like ε·t·L/w
            // on a needle of length L and width w: past t, it no longer tells a real hit from
            // one at the origin. Decide these in f64 (rare: the common case never gets here).
            return close_hit_f64::<KX, KY, KZ>(v, ray, t_min, t_max);
        }
        // The range check after the bound: a close call is range-checked on its f64 `t`
        // alone, so that the answer never depends on the order an accelerator tests in.
        if !(t > t_min && t < t_max) {
            return None;
        }
        Some(TriHit {
            t,
            b1: e1 * inv_det,
            b2: e2 * inv_det,
        })
    }
}

/// `γ(n)` of `f64` arithmetic: the relative error bound of `n` roundings.
fn gamma64(n: u32) -> f64 {
    let nu = f64::from(n) * (f64::EPSILON * 0.5);
    nu / (1.0 - nu)
}

/// The watertight test's close cases (the computed `t` within its `f32` error bound `δt`),
/// decided again from the same `f32` inputs in `f64`: the translation, the shear, the edge
/// functions, `t`, and the same kind of bound `δt`, now in units of `f64` rounding (2⁻⁵³,
/// some 5·10⁸ times smaller). A hit is kept when the `f64` edge functions agree in sign and
/// `t > δt` there; `t` and the barycentrics then come from `f64`. Only hits the `f32` test
/// would have dropped are added, so the test stays watertight, and the answer is still a pure
/// function of the triangle and the ray.
#[cold]
#[inline(never)]
fn close_hit_f64<const KX: usize, const KY: usize, const KZ: usize>(
    v: &[Vec3; 3],
    ray: &Ray,
    t_min: f32,
    t_max: f32,
) -> Option<TriHit> {
    let d = DVec3::from(ray.dir);
    let (sx, sy, sz) = (-d[KX] / d[KZ], -d[KY] / d[KZ], 1.0 / d[KZ]);
    let o = DVec3::from(ray.origin);
    let p = v.map(|p| DVec3::from(p) - o);
    let x = p.map(|p| p[KX] + sx * p[KZ]);
    let y = p.map(|p| p[KY] + sy * p[KZ]);
    let z = p.map(|p| sz * p[KZ]);
    let e = [
        x[1] * y[2] - y[1] * x[2],
        x[2] * y[0] - y[2] * x[0],
        x[0] * y[1] - y[0] * x[1],
    ];
    if e.iter().any(|&e| e < 0.0) && e.iter().any(|&e| e > 0.0) {
        return None;
    }
    let det = e[0] + e[1] + e[2];
    let t_scaled = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
    if det == 0.0 || !det.is_finite() || !t_scaled.is_finite() {
        return None;
    }
    let t = t_scaled / det;
    let abs_max = |a: [f64; 3]| a[0].abs().max(a[1].abs()).max(a[2].abs());
    let (max_x, max_y, max_z, max_e) = (abs_max(x), abs_max(y), abs_max(z), abs_max(e));
    let delta_z = gamma64(3) * max_z;
    let delta_x = gamma64(5) * (max_x + max_z);
    let delta_y = gamma64(5) * (max_y + max_z);
    let delta_e = 2.0 * (gamma64(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let delta_t =
        3.0 * (gamma64(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) / det.abs();
    // The sign of `t` itself is part of the test (`t > δt ≥ 0`).
    if t.is_nan() || t <= delta_t {
        return None;
    }
    let t32 = t as f32;
    if !(t32 > t_min && t32 < t_max) {
        return None;
    }
    Some(TriHit {
        t: t32,
        b1: (e[1] / det) as f32,
        b2: (e[2] / det) as f32,
    })
}

/// Four triangles, one per lane (structure of arrays): `v[3·k + axis]` holds the coordinate
/// on `axis` of vertex `k` of each triangle. Unused lanes repeat a used one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangles4 {
    pub v: [Vec4; 9],
}

impl Triangles4 {
    /// Lane `lane`'s triangle (repeated into lanes `tris.len()..4`); `tris` holds 1 to 4.
    pub fn new(tris: &[[Vec3; 3]]) -> Triangles4 {
        let mut v = [Vec4::ZERO; 9];
        for lane in 0..4 {
            let t = &tris[lane.min(tris.len() - 1)];
            for k in 0..3 {
                for axis in 0..3 {
                    v[3 * k + axis][lane] = t[k][axis];
                }
            }
        }
        Triangles4 { v }
    }

    /// The triangle in `lane`.
    #[inline]
    pub fn triangle(&self, lane: usize) -> [Vec3; 3] {
        let c = |k: usize| {
            Vec3::new(
                self.v[3 * k][lane],
                self.v[3 * k + 1][lane],
                self.v[3 * k + 2][lane],
            )
        };
        [c(0), c(1), c(2)]
    }
}

/// The answers of a four-lane test: bit `i` of `mask` set when lane `i` hit, with its `t` and
/// barycentrics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TriHits4 {
    pub mask: u32,
    pub t: [f32; 4],
    pub b1: [f32; 4],
    pub b2: [f32; 4],
}

impl TriHits4 {
    /// Lane `lane`'s answer, as [`intersect_triangle`] gives it.
    #[inline]
    pub fn get(&self, lane: usize) -> Option<TriHit> {
        (self.mask & (1 << lane) != 0).then(|| TriHit {
            t: self.t[lane],
            b1: self.b1[lane],
            b2: self.b2[lane],
        })
    }

    #[inline]
    fn set(&mut self, lane: usize, hit: Option<TriHit>) {
        match hit {
            Some(h) => {
                self.mask |= 1 << lane;
                self.t[lane] = h.t;
                self.b1[lane] = h.b1;
                self.b2[lane] = h.b2;
            }
            None => self.mask &= !(1 << lane),
        }
    }
}

impl Shear {
    /// [`Shear::intersect`] for the four lanes of `tris` at once (SSE through glam's `Vec4`):
    /// the same operations in the same order on each lane, and IEEE `f32` arithmetic rounds
    /// the same in a vector lane as in a scalar register, so every lane's answer is
    /// bit-identical to the scalar test of its triangle. Lanes where an edge function is
    /// exactly 0 or `t` is within its error bound (the `f64` re-evaluations) are answered by
    /// the scalar test.
    #[inline(always)]
    pub fn intersect4(&self, tris: &Triangles4, ray: &Ray, t_min: f32, t_max: f32) -> TriHits4 {
        match self.kz {
            0 => self.intersect4_k::<1, 2, 0>(tris, ray, t_min, t_max),
            1 => self.intersect4_k::<2, 0, 1>(tris, ray, t_min, t_max),
            _ => self.intersect4_k::<0, 1, 2>(tris, ray, t_min, t_max),
        }
    }

    #[inline(always)]
    fn intersect4_k<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        tris: &Triangles4,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
    ) -> TriHits4 {
        let o = [KX, KY, KZ].map(|k| Vec4::splat(ray.origin[k]));
        let s = [self.sx, self.sy, self.sz].map(Vec4::splat);
        let (min, max) = (Vec4::splat(t_min), Vec4::splat(t_max));
        let found = watertight_lanes::<Vec4, KX, KY, KZ>(&tris.v, o, s, min, max);
        let mut hits = TriHits4 {
            mask: found.mask,
            t: found.t.to_array(),
            b1: found.b1.to_array(),
            b2: found.b2.to_array(),
        };
        if found.slow != 0 {
            self.slow_lanes(&mut hits, found.slow, tris, ray, t_min, t_max);
        }
        hits
    }

    /// [`Shear::intersect4`] of two rays (`a` and `b`: each its shear, ray, `t_min` and
    /// `t_max`) against the same four triangles in one eight-lane test (AVX2): each ray's
    /// answers are those of its own four-lane test, bit for bit (the same operations, see
    /// [`super::lanes`]). `None` when the rays' shears permute differently (a different
    /// largest direction component), which one test cannot hold.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn intersect4_pair(
        simd: pulp::x86::V3,
        a: (&Shear, &Ray, f32, f32),
        b: (&Shear, &Ray, f32, f32),
        tris: &Triangles4,
    ) -> Option<(TriHits4, TriHits4)> {
        if a.0.kz != b.0.kz {
            return None;
        }
        Some(match a.0.kz {
            0 => Self::pair_k::<1, 2, 0>(simd, a, b, tris),
            1 => Self::pair_k::<2, 0, 1>(simd, a, b, tris),
            _ => Self::pair_k::<0, 1, 2>(simd, a, b, tris),
        })
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn pair_k<const KX: usize, const KY: usize, const KZ: usize>(
        simd: pulp::x86::V3,
        (sa, ra, a_min, a_max): (&Shear, &Ray, f32, f32),
        (sb, rb, b_min, b_max): (&Shear, &Ray, f32, f32),
        tris: &Triangles4,
    ) -> (TriHits4, TriHits4) {
        // No closures (see `watertight_lanes`).
        use super::lanes::F32x8;
        let mut v = [F32x8::pair(simd, 0.0, 0.0); 9];
        for (to, c) in v.iter_mut().zip(&tris.v) {
            *to = F32x8::halves(simd, *c, *c);
        }
        let o = [
            F32x8::pair(simd, ra.origin[KX], rb.origin[KX]),
            F32x8::pair(simd, ra.origin[KY], rb.origin[KY]),
            F32x8::pair(simd, ra.origin[KZ], rb.origin[KZ]),
        ];
        let s = [
            F32x8::pair(simd, sa.sx, sb.sx),
            F32x8::pair(simd, sa.sy, sb.sy),
            F32x8::pair(simd, sa.sz, sb.sz),
        ];
        let (min, max) = (
            F32x8::pair(simd, a_min, b_min),
            F32x8::pair(simd, a_max, b_max),
        );
        let found = watertight_lanes::<F32x8, KX, KY, KZ>(&v, o, s, min, max);
        let (t, b1, b2) = (found.t.split(), found.b1.split(), found.b2.split());
        let mut ha = TriHits4 {
            mask: found.mask & 0xf,
            t: t.0,
            b1: b1.0,
            b2: b2.0,
        };
        let mut hb = TriHits4 {
            mask: found.mask >> 4,
            t: t.1,
            b1: b1.1,
            b2: b2.1,
        };
        if found.slow & 0xf != 0 {
            sa.slow_lanes(&mut ha, found.slow & 0xf, tris, ra, a_min, a_max);
        }
        if found.slow >> 4 != 0 {
            sb.slow_lanes(&mut hb, found.slow >> 4, tris, rb, b_min, b_max);
        }
        (ha, hb)
    }

    /// The lanes in `lanes` (an edge function exactly 0, or `t` within its error bound),
    /// answered by the scalar test.
    #[cold]
    #[inline(never)]
    fn slow_lanes(
        &self,
        hits: &mut TriHits4,
        mut lanes: u32,
        tris: &Triangles4,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
    ) {
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let tri = tris.triangle(lane);
            let hit = if leaves_plane_of(&tri, ray) {
                None
            } else {
                self.intersect(&tri, ray, t_min, t_max)
            };
            hits.set(lane, hit);
        }
    }
}

/// Whether `ray` starts exactly in the plane of the axis-aligned triangle `v` and leaves it
/// (`v`'s three vertices and the origin share one coordinate, and the direction's is not 0):
/// the ray then meets that plane only at `t = 0`, so the watertight test cannot find a hit
/// in any `(t_min ≥ 0, t_max)`: its `t ≤ δt` close call rejects it in `f64`. This answers it
/// at once. It is the common close call: a shadow or secondary ray from a floor or wall at a
/// round coordinate (`y = 0`), where the hit point is exact, so its error bound and offset
/// are 0 and the ray starts on the surface (docs/performance.md).
#[inline]
fn leaves_plane_of(v: &[Vec3; 3], ray: &Ray) -> bool {
    (0..3).any(|k| {
        let c = ray.origin[k];
        ray.dir[k] != 0.0 && v[0][k] == c && v[1][k] == c && v[2][k] == c
    })
}

/// What [`watertight_lanes`] finds: bit `i` of `mask` when lane `i` hits (lanes with an edge
/// function exactly 0, or a `t` within its error bound, excluded: they are in `slow`, for the
/// scalar test), and every lane's `t` and barycentrics.
struct LaneHits<L> {
    mask: u32,
    slow: u32,
    t: L,
    b1: L,
    b2: L,
}

/// The watertight test lane by lane (one triangle and one ray per lane), with the scalar
/// test's operations in its order: the vertices `v` (by component, as [`Triangles4::v`]),
/// the ray's origin `o` and shear `s` already permuted (`[x, y, z]` of the sheared frame),
/// and the interval `(t_min, t_max)`.
#[inline(always)]
fn watertight_lanes<L: Lanes, const KX: usize, const KY: usize, const KZ: usize>(
    v: &[L; 9],
    o: [L; 3],
    s: [L; 3],
    t_min: L,
    t_max: L,
) -> LaneHits<L> {
    // No closures here: a closure is compiled without the AVX2 features of the test around
    // it, and the eight-lane operations in it would not be inlined.
    let [ox, oy, oz] = o;
    let [sx, sy, sz] = s;
    // Translate, permute and shear, as the scalar test.
    let (p0z, p1z, p2z) = (v[KZ] - oz, v[3 + KZ] - oz, v[6 + KZ] - oz);
    let (p0x, p0y) = (v[KX] - ox + sx * p0z, v[KY] - oy + sy * p0z);
    let (p1x, p1y) = (v[3 + KX] - ox + sx * p1z, v[3 + KY] - oy + sy * p1z);
    let (p2x, p2y) = (v[6 + KX] - ox + sx * p2z, v[6 + KY] - oy + sy * p2z);
    let e0 = p1x * p2y - p1y * p2x;
    let e1 = p2x * p0y - p2y * p0x;
    let e2 = p0x * p1y - p0y * p1x;
    let zero = ox.splat_as(0.0);
    let on_edge = L::bits(e0.cmp_eq(zero) | e1.cmp_eq(zero) | e2.cmp_eq(zero));
    let negative = e0.cmp_lt(zero) | e1.cmp_lt(zero) | e2.cmp_lt(zero);
    let positive = e0.cmp_gt(zero) | e1.cmp_gt(zero) | e2.cmp_gt(zero);
    let det = e0 + e1 + e2;
    let t_scaled = e0 * (sz * p0z) + e1 * (sz * p1z) + e2 * (sz * p2z);
    let inv_det = zero.splat_as(1.0) / det;
    let t = t_scaled * inv_det;
    // Every rejection of the scalar test, negated: inside, det ≠ 0 and not NaN, T of det's
    // sign (and not NaN), t in range.
    let inside = !(negative & positive);
    // Outside but an edge function within its rounding error of 0 (a needle thinner than a
    // few ulp), as in the scalar test: for the scalar test, which decides it in `f64`.
    let m = p0x
        .abs_lanes()
        .max_lanes(p1x.abs_lanes())
        .max_lanes(p2x.abs_lanes())
        .max_lanes(p0y.abs_lanes())
        .max_lanes(p1y.abs_lanes())
        .max_lanes(p2y.abs_lanes());
    let mz = (sz * p0z)
        .abs_lanes()
        .max_lanes((sz * p1z).abs_lanes())
        .max_lanes((sz * p2z).abs_lanes());
    let bound = zero.splat_as(gamma(24)) * ((m + mz) * m);
    let uncertain = L::bits(
        negative
            & positive
            & (e0.abs_lanes().cmp_le(bound)
                | e1.abs_lanes().cmp_le(bound)
                | e2.abs_lanes().cmp_le(bound)),
    );
    let det_ok = det.cmp_ne(zero) & det.cmp_eq(det);
    let t_sign_ok =
        (det.cmp_lt(zero) & t_scaled.cmp_lt(zero)) | (det.cmp_gt(zero) & t_scaled.cmp_gt(zero));
    let in_range = t.cmp_gt(t_min) & t.cmp_lt(t_max);
    // In front and inside; the range is checked after the bound, as in the scalar test.
    let mut mask = L::bits(inside & det_ok & t_sign_ok) & !on_edge;
    let mut close = 0;
    if mask != 0 {
        // pbrt-v4's conservative t > δt, as in the scalar test.
        let (z0, z1, z2) = (
            (sz * p0z).abs_lanes(),
            (sz * p1z).abs_lanes(),
            (sz * p2z).abs_lanes(),
        );
        let max_z = z0.max_lanes(z1).max_lanes(z2);
        let max_x = p0x
            .abs_lanes()
            .max_lanes(p1x.abs_lanes())
            .max_lanes(p2x.abs_lanes());
        let max_y = p0y
            .abs_lanes()
            .max_lanes(p1y.abs_lanes())
            .max_lanes(p2y.abs_lanes());
        let (g2, g3, g5) = (
            zero.splat_as(gamma(2)),
            zero.splat_as(gamma(3)),
            zero.splat_as(gamma(5)),
        );
        let delta_z = g3 * max_z;
        let delta_x = g5 * (max_x + max_z);
        let delta_y = g5 * (max_y + max_z);
        let delta_e = zero.splat_as(2.0) * (g2 * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = e0
            .abs_lanes()
            .max_lanes(e1.abs_lanes())
            .max_lanes(e2.abs_lanes());
        let delta_t = zero.splat_as(3.0)
            * (g3 * max_e * max_z + delta_e * max_z + delta_z * max_e)
            * inv_det.abs_lanes();
        // `t <= δt` goes to the scalar test, which decides it in `f64` (a NaN δt accepts,
        // as in the scalar test).
        close = L::bits(t.cmp_le(delta_t)) & mask;
        mask &= !close & L::bits(in_range);
    }
    LaneHits {
        mask,
        slow: on_edge | close | uncertain | L::bits(det.cmp_eq(zero)),
        t,
        b1: e1 * inv_det,
        b2: e2 * inv_det,
    }
}

/// [`intersect_triangle`] of every lane of `tris`, in lanes `0..count` (the others miss).
#[inline(always)]
pub fn intersect_triangles4(
    method: TriangleMethod,
    shear: Option<&Shear>,
    tris: &Triangles4,
    count: usize,
    ray: &Ray,
    t_min: f32,
    t_max: f32,
) -> TriHits4 {
    let used = (1u32 << count) - 1;
    match (method, shear) {
        (TriangleMethod::Watertight, Some(shear)) => {
            let mut hits = shear.intersect4(tris, ray, t_min, t_max);
            hits.mask &= used;
            hits
        }
        (TriangleMethod::Watertight, None) => TriHits4::default(),
        (method, _) => one_by_one(method, tris, count, ray, t_min, t_max),
    }
}

/// The methods without a four-lane form, lane by lane.
#[inline(never)]
fn one_by_one(
    method: TriangleMethod,
    tris: &Triangles4,
    count: usize,
    ray: &Ray,
    t_min: f32,
    t_max: f32,
) -> TriHits4 {
    let mut hits = TriHits4::default();
    for lane in 0..count {
        let tri = tris.triangle(lane);
        hits.set(lane, intersect_triangle(method, &tri, ray, t_min, t_max));
    }
    hits
}

/// The point with barycentric weights `(1 − b1 − b2, b1, b2)` and a per-axis bound on its
/// absolute error (pbrt-v4: `γ(7)·(|b0·v0| + |b1·v1| + |b2·v2|)`). Interpolating the vertices
/// keeps the point on the triangle's plane whatever the error of `t`.
pub fn triangle_hit_point(v: &[Vec3; 3], b1: f32, b2: f32) -> (Vec3, Vec3) {
    let b0 = 1.0 - b1 - b2;
    let (w0, w1, w2) = (b0 * v[0], b1 * v[1], b2 * v[2]);
    let p = w0 + w1 + w2;
    let err = gamma(7) * (w0.abs() + w1.abs() + w2.abs());
    (p, err)
}

/// `f64` replay of the ray/triangle test on the same `f32` inputs (barycentrics by Cramer's
/// rule in double precision), used by the stability tests as the oracle: `(t, b0, b1, b2)` of
/// the ray's line with the triangle's plane, or `None` when parallel or degenerate. The caller
/// decides what "inside" means (all `b ≥ 0`) and what margin to allow.
pub fn triangle_hit_f64(v: &[Vec3; 3], ray: &Ray) -> Option<(f64, f64, f64, f64)> {
    let v0 = DVec3::from(v[0]);
    let e1 = DVec3::from(v[1]) - v0;
    let e2 = DVec3::from(v[2]) - v0;
    let d = DVec3::from(ray.dir);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let s = DVec3::from(ray.origin) - v0;
    let b1 = s.dot(p) / det;
    let q = s.cross(e1);
    let b2 = d.dot(q) / det;
    let t = e2.dot(q) / det;
    Some((t, 1.0 - b1 - b2, b1, b2))
}

#[cfg(test)]
mod plane_tests {
    use super::*;

    /// A ray that starts exactly in an axis-aligned triangle's plane and leaves it (a shadow
    /// ray from a floor at `y = 0`): the full watertight test, `f64` close call included,
    /// finds no hit, as `leaves_plane_of` answers; the lane test, which takes that answer,
    /// agrees; and a ray lying in the plane is not taken for one that leaves it.
    #[test]
    fn a_ray_leaving_an_axis_aligned_triangles_plane_never_hits_it() {
        let mut rnd = crate::rng::signed(0x51ab_0f17);
        for round in 0..20_000 {
            let k = round % 3;
            let c = [0.0, 1.5, -3.25, 1000.0, 1e-3][round % 5];
            let scale = [1.0, 12.0, 0.01][round % 3];
            let on_plane = |rnd: &mut dyn FnMut() -> f32| {
                let mut p = Vec3::new(rnd(), rnd(), rnd()) * scale;
                p[k] = c;
                p
            };
            let v = [on_plane(&mut rnd), on_plane(&mut rnd), on_plane(&mut rnd)];
            // The origin inside the triangle (a hit point), on a vertex, or anywhere on the plane.
            let origin = match round % 4 {
                0 => v[1],
                1 => on_plane(&mut rnd),
                _ => {
                    let (a, b) = (rnd().abs(), rnd().abs());
                    let (a, b) = if a + b > 1.0 {
                        (1.0 - a, 1.0 - b)
                    } else {
                        (a, b)
                    };
                    let mut p = v[0] + a * (v[1] - v[0]) + b * (v[2] - v[0]);
                    p[k] = c;
                    p
                }
            };
            let mut dir = Vec3::new(rnd(), rnd(), rnd());
            dir[k] = if round % 7 == 0 { 1e-4 } else { dir[k] };
            let Some(dir) = dir.try_normalize() else {
                continue;
            };
            if dir[k] == 0.0 {
                continue;
            }
            let ray = Ray::new(origin, dir);
            assert!(leaves_plane_of(&v, &ray), "round {round}");
            let Some(shear) = Shear::new(ray.dir) else {
                continue;
            };
            let full = shear.intersect(&v, &ray, 0.0, f32::INFINITY);
            assert!(
                full.is_none(),
                "round {round}: {v:?} {ray:?} hit at {full:?}"
            );
            let lanes = shear.intersect4(&Triangles4::new(&[v]), &ray, 0.0, f32::INFINITY);
            assert_eq!(lanes.mask & 1, 0, "round {round}: the lane test hit");
            let mut flat = ray;
            flat.dir[k] = 0.0;
            assert!(
                !leaves_plane_of(&v, &flat),
                "a ray in the plane does not leave it"
            );
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod pair_tests {
    use super::*;

    /// Two rays in one eight-lane test ([`Shear::intersect4_pair`]) get, bit for bit, what
    /// their own four-lane tests give: hits, misses, lanes exactly on an edge or a vertex
    /// (answered by the scalar test), degenerate triangles; and rays whose shears permute
    /// differently are refused, not answered.
    /// A test's answers as bits (a degenerate lane's NaN `t` is not equal to itself).
    fn bits(h: &TriHits4) -> (u32, [[u32; 4]; 3]) {
        (h.mask, [h.t, h.b1, h.b2].map(|a| a.map(f32::to_bits)))
    }

    /// Both rays' answers as bits.
    fn both(h: &(TriHits4, TriHits4)) -> [(u32, [[u32; 4]; 3]); 2] {
        [bits(&h.0), bits(&h.1)]
    }

    #[test]
    fn two_rays_in_one_test_answer_as_each_alone() {
        let simd = pulp::x86::V3::try_new()
            .expect("this test needs a CPU with AVX2 and FMA (x86-64-v3), as the bench machines");
        let mut rnd = crate::rng::signed(0x2545_f491);
        let (mut compared, mut hits, mut refused) = (0, 0, 0);
        for round in 0..4000 {
            // Small integer coordinates on some rounds, so rays through grid points land
            // exactly on edges and vertices.
            let grid = round % 3 == 0;
            let mut point = || {
                let p = Vec3::new(rnd(), rnd(), rnd()) * 2.0;
                if grid { p.round() } else { p }
            };
            let tris: Vec<[Vec3; 3]> = (0..4)
                .map(|k| {
                    if k == 3 && round % 5 == 0 {
                        let a = point();
                        [a, a, point()]
                    } else {
                        [point(), point(), point()]
                    }
                })
                .collect();
            let packet = Triangles4::new(&tris);
            let mut ray = |grid: bool| {
                let o = Vec3::new(rnd(), rnd(), rnd()).normalize_or(Vec3::Z) * 5.0;
                let aim = if grid {
                    Vec3::new(rnd(), rnd(), rnd()).round()
                } else {
                    Vec3::new(rnd(), rnd(), rnd())
                };
                Ray::new(o, (aim - o).normalize())
            };
            let (ra, rb) = (ray(grid), ray(grid && round % 2 == 0));
            let (Some(sa), Some(sb)) = (Shear::new(ra.dir), Shear::new(rb.dir)) else {
                continue;
            };
            let (a_min, a_max) = (0.0, if round % 7 == 0 { 4.5 } else { f32::INFINITY });
            let (b_min, b_max) = (1e-3, f32::INFINITY);
            let alone = (
                sa.intersect4(&packet, &ra, a_min, a_max),
                sb.intersect4(&packet, &rb, b_min, b_max),
            );
            match Shear::intersect4_pair(
                simd,
                (&sa, &ra, a_min, a_max),
                (&sb, &rb, b_min, b_max),
                &packet,
            ) {
                Some(pair) => {
                    assert_eq!(both(&pair), both(&alone), "round {round}");
                    compared += 1;
                    hits += (alone.0.mask | alone.1.mask).count_ones();
                }
                None => {
                    assert_ne!(sa.kz, sb.kz);
                    refused += 1;
                }
            }
        }
        // Rays straight down onto an edge shared by two triangles and onto a vertex: edge
        // functions exactly 0, answered by the scalar test in both.
        let z = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        let tris = [
            [z(-1.0, -1.0), z(1.0, -1.0), z(0.0, 1.0)],
            [z(-1.0, -1.0), z(0.0, -3.0), z(1.0, -1.0)],
            [z(0.0, 1.0), z(1.0, -1.0), z(2.0, 1.0)],
            [z(3.0, 3.0), z(4.0, 3.0), z(3.0, 4.0)],
        ];
        let packet = Triangles4::new(&tris);
        let down = |x: f32, y: f32| Ray::new(Vec3::new(x, y, 5.0), Vec3::NEG_Z);
        for (ra, rb) in [
            (down(0.0, -1.0), down(0.0, 1.0)),
            (down(1.0, -1.0), down(0.5, 0.0)),
        ] {
            let shear = |r: &Ray| Shear::new(r.dir).expect("a straight-down ray has a shear");
            let (sa, sb) = (shear(&ra), shear(&rb));
            let alone = (
                sa.intersect4(&packet, &ra, 0.0, f32::INFINITY),
                sb.intersect4(&packet, &rb, 0.0, f32::INFINITY),
            );
            let pair = Shear::intersect4_pair(
                simd,
                (&sa, &ra, 0.0, f32::INFINITY),
                (&sb, &rb, 0.0, f32::INFINITY),
                &packet,
            );
            assert_eq!(pair.map(|p| both(&p)), Some(both(&alone)));
            assert!(alone.0.mask != 0 && alone.1.mask != 0, "{alone:?}");
        }
        assert!(
            compared > 1000 && hits > 500,
            "{compared} compared, {hits} hits"
        );
        assert!(refused > 0, "no pair of differently permuted rays");
    }
}
