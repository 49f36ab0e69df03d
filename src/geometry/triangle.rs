//! Ray/triangle intersection: the lecture's plane-then-barycentric method (section
//! "Ray/Triangle Intersection"), Möller–Trumbore (1997) and the watertight test of Woop,
//! Benthin and Wald (2013, "Watertight Ray/Triangle Intersection", JCGT 2(1)).
//!
//! All three test both faces and report the barycentric weights `b1`, `b2` of vertices 1 and 2
//! (vertex 0 has `1 − b1 − b2`). Each returns a `t` that does not depend on `t_min`/`t_max`
//! except through the final range check, so accelerators that shrink `t_max` see the same hit.
//!
//! Where they fail (STABILITY T1, T3): the lecture's method and Möller–Trumbore decide "inside"
//! per triangle with independently rounded quantities, so a ray through a shared edge or
//! vertex can be outside both neighbours (a leak, a crack in the image). Möller–Trumbore also
//! rejects `|det| <` [`MT_DET_EPSILON`], which is an absolute threshold on a quantity that scales
//! with the square of the triangle's size: triangles with edges below about `1e-4` are missed
//! altogether. The watertight test shears the triangle into a ray-aligned space where the three
//! edge functions of a shared edge are computed from the same numbers in both triangles, so
//! their signs agree exactly and no ray slips between; it rejects only `det == 0`.
use glam::{DVec3, Vec3, Vec3A, Vec3Swizzles, Vec4};
use serde::{Deserialize, Serialize};

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
/// every triangle whose edges are shorter than about `1e-4` (STABILITY T3), and needle triangles
/// seen edge-on. Kept on purpose: it is the method as taught and the sweeps show its failure.
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
/// 6. the scaled distance `T = U·z0 + V·z1 + W·z2` must have the sign of `det` (hit in front).
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
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 || det.is_nan() {
            return None;
        }
        let t_scaled = e0 * (sz * p0z) + e1 * (sz * p1z) + e2 * (sz * p2z);
        if t_scaled.is_nan() || (det < 0.0 && t_scaled >= 0.0) || (det > 0.0 && t_scaled <= 0.0) {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > t_min && t < t_max) {
            return None;
        }
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
            return None;
        }
        Some(TriHit {
            t,
            b1: e1 * inv_det,
            b2: e2 * inv_det,
        })
    }
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
    /// exactly 0 (the `f64` re-evaluation) are answered by the scalar test.
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
        let v = &tris.v;
        let (ox, oy, oz) = (
            Vec4::splat(ray.origin[KX]),
            Vec4::splat(ray.origin[KY]),
            Vec4::splat(ray.origin[KZ]),
        );
        let (sx, sy, sz) = (
            Vec4::splat(self.sx),
            Vec4::splat(self.sy),
            Vec4::splat(self.sz),
        );
        // Translate, permute and shear, as the scalar test.
        let vertex = |k: usize| {
            let z = v[3 * k + KZ] - oz;
            (v[3 * k + KX] - ox + sx * z, v[3 * k + KY] - oy + sy * z, z)
        };
        let (p0x, p0y, p0z) = vertex(0);
        let (p1x, p1y, p1z) = vertex(1);
        let (p2x, p2y, p2z) = vertex(2);
        let e0 = p1x * p2y - p1y * p2x;
        let e1 = p2x * p0y - p2y * p0x;
        let e2 = p0x * p1y - p0y * p1x;
        let zero = Vec4::ZERO;
        let on_edge = (e0.cmpeq(zero) | e1.cmpeq(zero) | e2.cmpeq(zero)).bitmask();
        let negative = e0.cmplt(zero) | e1.cmplt(zero) | e2.cmplt(zero);
        let positive = e0.cmpgt(zero) | e1.cmpgt(zero) | e2.cmpgt(zero);
        let det = e0 + e1 + e2;
        let t_scaled = e0 * (sz * p0z) + e1 * (sz * p1z) + e2 * (sz * p2z);
        let inv_det = Vec4::ONE / det;
        let t = t_scaled * inv_det;
        // Every rejection of the scalar test, negated: inside, det ≠ 0 and not NaN, T of det's
        // sign (and not NaN), t in range.
        let inside = !(negative & positive);
        let det_ok = det.cmpne(zero) & det.cmpeq(det);
        let t_sign_ok =
            (det.cmplt(zero) & t_scaled.cmplt(zero)) | (det.cmpgt(zero) & t_scaled.cmpgt(zero));
        let in_range = t.cmpgt(Vec4::splat(t_min)) & t.cmplt(Vec4::splat(t_max));
        let mut mask = (inside & det_ok & t_sign_ok & in_range).bitmask() & !on_edge;
        if mask != 0 {
            // pbrt-v4's conservative t > δt, as in the scalar test.
            let (z0, z1, z2) = ((sz * p0z).abs(), (sz * p1z).abs(), (sz * p2z).abs());
            let max_z = z0.max(z1).max(z2);
            let max_x = p0x.abs().max(p1x.abs()).max(p2x.abs());
            let max_y = p0y.abs().max(p1y.abs()).max(p2y.abs());
            let g = |n: u32| Vec4::splat(gamma(n));
            let delta_z = g(3) * max_z;
            let delta_x = g(5) * (max_x + max_z);
            let delta_y = g(5) * (max_y + max_z);
            let delta_e =
                Vec4::splat(2.0) * (g(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
            let max_e = e0.abs().max(e1.abs()).max(e2.abs());
            let delta_t = Vec4::splat(3.0)
                * (g(3) * max_e * max_z + delta_e * max_z + delta_z * max_e)
                * inv_det.abs();
            // `t <= δt` rejects (a NaN δt accepts, as in the scalar test).
            mask &= !t.cmple(delta_t).bitmask();
        }
        let mut hits = TriHits4 {
            mask,
            t: t.to_array(),
            b1: (e1 * inv_det).to_array(),
            b2: (e2 * inv_det).to_array(),
        };
        if on_edge != 0 {
            self.on_edges(&mut hits, on_edge, tris, ray, t_min, t_max);
        }
        hits
    }

    /// The lanes in `lanes` (an edge function exactly 0), answered by the scalar test.
    #[cold]
    #[inline(never)]
    fn on_edges(
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
            hits.set(
                lane,
                self.intersect(&tris.triangle(lane), ray, t_min, t_max),
            );
        }
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
