//! Acceleration structures behind one type: none (test every primitive), a uniform grid with
//! 3D-DDA traversal (the lecture's "spatial subdivision") and a BVH built with `obvhs`
//! (the lecture's "BVH"). All answer the same two queries, closest hit and occlusion, and give
//! the identical answer: the nearest `t`, ties broken by the lower primitive id.
//!
//! How "identical" is achieved: every accelerator calls the same `f32` intersection function on
//! the same primitive data (a compact copy taken at build time), and each function's `t` does
//! not depend on the `t_max` it is given (only the final range check does). The traversals are
//! conservative (padded boxes and cells, slab tests widened by their rounding error), so every
//! primitive whose reported hit point lies in its own bounding box is tested. Ties: a candidate
//! replaces the best hit when its `t` is smaller, or equal with a lower id.
//!
//! Caveat, by design: a method that reports hits far outside the primitive (the lecture's
//! sphere formula at `D/r ≥ 1e3`, whose "hits" are rounding noise) can be found by `None` and
//! not by the others. With the robust methods (the defaults) they agree exactly.
//!
//! Bad input: spheres with a non-finite centre or a radius that is not finite and positive, and
//! triangles with a non-finite vertex or an exactly zero (or non-finite) cross product, are
//! dropped at build time for every kind and counted ([`Accel::skipped_prims`]). Rays with a
//! non-finite origin or direction, a zero direction or an empty `(t_min, t_max)` hit nothing.
//! No traversal allocates, locks or returns `Result`.

mod bvh;
mod grid;
mod visits;

#[cfg(target_arch = "x86_64")]
pub(crate) use bvh::avx2;
pub use bvh::{PacketSimd, packet_simd, packet_uses_avx2, set_packet_simd};
pub use visits::{AccelBox, VisitedBox, Visits};

use glam::{Vec3, Vec3A};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::geometry::{
    Methods, Ray, Shear, TriHits4, TriangleMethod, Triangles4, intersect_sphere,
    intersect_triangle, intersect_triangles4, next_float_up,
};

/// Which accelerator to build. `Auto` picks from the scene's size.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AccelKind {
    #[default]
    Auto,
    None,
    Grid,
    Bvh,
}

crate::choice::choice!(AccelKind {
    Auto => ("auto", "picks from the scene's size (measured crossovers)"),
    None => ("none", "tests every primitive"),
    Grid => ("grid", "uniform grid, 3D-DDA traversal (spatial subdivision)"),
    Bvh => ("bvh", "bounding volume hierarchy (obvhs build, 8-wide nodes)"),
});

/// Geometry the accelerators see. Primitive ids: spheres are `0..spheres.len()`, triangles
/// follow, so id `spheres.len() + i` is triangle `i`.
#[derive(Clone, Debug, Default)]
pub struct PrimSet {
    /// (centre, radius) per sphere.
    pub spheres: Vec<(Vec3, f32)>,
    pub triangles: Vec<[Vec3; 3]>,
}

/// A closest hit: the parameter along the ray, the primitive id and, for triangles, the
/// barycentric weights of vertices 1 and 2 (vertex 0 has `1 − b1 − b2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimHit {
    pub t: f32,
    pub prim: u32,
    pub b1: f32,
    pub b2: f32,
}

/// `Auto` tests every primitive (no accelerator) below this many valid primitives, and builds
/// the BVH from here on, at every size.
///
/// Measured with `raytree bench default --no-sweep --out DIR` (the scaling sweep of
/// `experiments::scaling`: a tessellated sphere filling a 640×480 image, one sample, primary and
/// shadow rays, build + render, median of 3 runs, 2 shared cores): at 1–4 triangles the three
/// kinds are within noise of each other (15–68 ms), from 8 on the BVH is faster than none
/// (44–72 ms against 61–93 ms; 84–92 ms against 230–260 ms at 32). Three runs put the
/// crossover at about 4, 6 and 7.
///
/// The uniform grid is never chosen. On the sweep's sphere (the grid's best case: one even
/// surface, cells evenly filled) its cheaper build still wins a *single* frame from about 0.9M
/// triangles (after the parallel BVH build: 1M 0.65 s against 0.68 s, 2M 0.73 s against
/// 1.28 s). But on the peer bench's Whitted scene (a torus, mirror and glass spheres) the grid
/// renders about 10× slower and loses the first frame too (1M: 1.9 s against 0.93 s; 2M:
/// 2.8 s against 1.8 s), and a viewer renders many frames per build, where the BVH is 2–10×
/// faster each. `--accel grid` remains for the single frame of a huge even mesh.
pub const AUTO_MIN_BVH_PRIMS: usize = 6;

/// The accelerator `Auto` builds for `valid_prims` primitives (see [`AUTO_MIN_BVH_PRIMS`] for
/// the measurements behind the rule).
pub fn auto_kind(valid_prims: usize) -> AccelKind {
    if valid_prims < AUTO_MIN_BVH_PRIMS {
        AccelKind::None
    } else {
        AccelKind::Bvh
    }
}

/// The shape of one primitive, as the accelerators store it.
#[derive(Clone, Copy, Debug)]
enum Shape {
    Sphere { center: Vec3, radius: f32 },
    Triangle([Vec3; 3]),
}

/// One primitive of the compact copy, with its original id.
#[derive(Clone, Copy, Debug)]
struct Prim {
    shape: Shape,
    id: u32,
}

impl Prim {
    /// The shared intersection call: `(t, b1, b2)` (barycentrics are 0 for spheres). `shear`
    /// is the ray's [`Shear`], computed once per query (the watertight method's per-ray part).
    #[inline(always)]
    fn intersect(
        &self,
        m: &Methods,
        ray: &Ray,
        shear: &Option<Shear>,
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, f32, f32)> {
        match &self.shape {
            Shape::Sphere { center, radius } => {
                intersect_sphere(m.sphere, *center, *radius, ray, t_min, t_max)
                    .map(|t| (t, 0.0, 0.0))
            }
            Shape::Triangle(v) => match m.triangle {
                TriangleMethod::Watertight => shear.as_ref()?.intersect(v, ray, t_min, t_max),
                method => intersect_triangle(method, v, ray, t_min, t_max),
            }
            .map(|h| (h.t, h.b1, h.b2)),
        }
    }

    /// A bounding box that contains the primitive despite the rounding of `c ± r`.
    fn bounds(&self) -> (Vec3, Vec3) {
        match &self.shape {
            Shape::Sphere { center, radius } => {
                let r = Vec3::splat(*radius);
                let pad = (center.abs() + r) * (2.0 * f32::EPSILON);
                (*center - r - pad, *center + r + pad)
            }
            Shape::Triangle([a, b, c]) => (a.min(*b).min(*c), a.max(*b).max(*c)),
        }
    }
}

/// What a traversal does with each primitive it reaches; generic so the loops monomorphise.
trait Visitor {
    /// Whether the BVH should visit nearer children first (closest hit) or may take any
    /// order (occlusion).
    const ORDERED: bool = true;
    /// The farthest `t` still of interest (boxes and cells entered beyond it are skipped).
    fn limit(&self) -> f32;
    /// Test one primitive; `true` stops the traversal.
    fn visit(&mut self, prim: &Prim) -> bool;
    /// Test the triangles in lanes `0..count` of `tris` (ids `ids`), in lane order, with one
    /// four-lane test; the same answer as visiting them one by one. `true` stops.
    fn visit_triangles(&mut self, tris: &Triangles4, ids: &[u32; 4], count: usize) -> bool;
    /// The query and `t_max` of the four-lane test [`Visitor::visit_triangles`] would run now,
    /// when a test of two rays at once ([`pair_triangles4`]) may stand in for it; `None`: this
    /// visitor tests alone.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn pair_query(&self) -> Option<(&Query<'_>, f32)> {
        None
    }
    /// [`Visitor::visit_triangles`] given `hits`, the answers of the test of
    /// [`Visitor::pair_query`] (a visitor without one tests alone).
    #[inline(always)]
    fn take_triangles(
        &mut self,
        hits: &TriHits4,
        tris: &Triangles4,
        ids: &[u32; 4],
        count: usize,
    ) -> bool {
        let _ = hits;
        self.visit_triangles(tris, ids, count)
    }
    /// The traversal enters a box: a BVH child word (node or leaf) or a grid cell index. Only
    /// the recording visitor of [`visits`] looks; for the others this compiles away, so the
    /// queries of a render are not slowed by it.
    #[inline(always)]
    fn enter(&mut self, _key: u32) {}
}

/// What every visitor tests primitives with: the methods, the ray, its shear (for the
/// watertight test) and the near end of the interval.
struct Query<'a> {
    m: &'a Methods,
    ray: &'a Ray,
    shear: Option<Shear>,
    t_min: f32,
}

impl<'a> Query<'a> {
    fn new(m: &'a Methods, ray: &'a Ray, t_min: f32) -> Self {
        Self {
            m,
            ray,
            shear: Shear::new(ray.dir),
            t_min,
        }
    }

    #[inline(always)]
    fn prim(&self, prim: &Prim, t_max: f32) -> Option<(f32, f32, f32)> {
        prim.intersect(self.m, self.ray, &self.shear, self.t_min, t_max)
    }

    #[inline(always)]
    fn triangles4(&self, tris: &Triangles4, count: usize, t_max: f32) -> TriHits4 {
        let shear = self.shear.as_ref();
        intersect_triangles4(
            self.m.triangle,
            shear,
            tris,
            count,
            self.ray,
            self.t_min,
            t_max,
        )
    }
}

/// Closest hit with the id tie-break.
struct Closest<'a> {
    q: Query<'a>,
    t: f32,
    prim: u32,
    b1: f32,
    b2: f32,
}

impl<'a> Closest<'a> {
    fn new(m: &'a Methods, ray: &'a Ray, t_min: f32, t_max: f32) -> Self {
        Self {
            q: Query::new(m, ray, t_min),
            t: t_max,
            prim: u32::MAX,
            b1: 0.0,
            b2: 0.0,
        }
    }

    fn hit(&self) -> Option<PrimHit> {
        (self.prim != u32::MAX).then_some(PrimHit {
            t: self.t,
            prim: self.prim,
            b1: self.b1,
            b2: self.b2,
        })
    }
}

impl Visitor for Closest<'_> {
    #[inline(always)]
    fn limit(&self) -> f32 {
        self.t
    }

    #[inline(always)]
    fn visit(&mut self, prim: &Prim) -> bool {
        // Once we have a hit, ask for hits up to and *including* its t (the functions' t_max
        // is exclusive), so an equal t with a lower id can still win.
        let limit = if self.prim == u32::MAX {
            self.t
        } else {
            next_float_up(self.t)
        };
        if let Some((t, b1, b2)) = self.q.prim(prim, limit)
            && (t < self.t || (t == self.t && prim.id < self.prim))
        {
            self.t = t;
            self.prim = prim.id;
            self.b1 = b1;
            self.b2 = b2;
        }
        false
    }

    #[inline(always)]
    fn visit_triangles(&mut self, tris: &Triangles4, ids: &[u32; 4], count: usize) -> bool {
        let hits = self.q.triangles4(tris, count, self.tri_limit());
        self.take_triangles(&hits, tris, ids, count)
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn pair_query(&self) -> Option<(&Query<'_>, f32)> {
        Some((&self.q, self.tri_limit()))
    }

    #[inline(always)]
    fn take_triangles(
        &mut self,
        hits: &TriHits4,
        _tris: &Triangles4,
        ids: &[u32; 4],
        _count: usize,
    ) -> bool {
        // Each lane's t does not depend on the limit, and the limit only shrinks from lane to
        // lane, so testing all lanes against the first limit and then re-checking each
        // candidate against the current one in lane order is what `visit` one by one does.
        let mut mask = hits.mask;
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let (t, id) = (hits.t[lane], ids[lane]);
            if t < self.tri_limit() && (t < self.t || (t == self.t && id < self.prim)) {
                self.t = t;
                self.prim = id;
                self.b1 = hits.b1[lane];
                self.b2 = hits.b2[lane];
            }
        }
        false
    }
}

impl Closest<'_> {
    /// The `t_max` of a triangle test now: the best `t` itself once there is a hit (the
    /// tests' `t_max` is exclusive), so an equal `t` with a lower id can still win.
    #[inline(always)]
    fn tri_limit(&self) -> f32 {
        if self.prim == u32::MAX {
            self.t
        } else {
            next_float_up(self.t)
        }
    }
}

/// Any hit in `(t_min, t_max)`: stops at the first.
struct AnyHit<'a> {
    q: Query<'a>,
    t_max: f32,
    hit: bool,
}

impl Visitor for AnyHit<'_> {
    const ORDERED: bool = false;

    #[inline(always)]
    fn limit(&self) -> f32 {
        self.t_max
    }

    #[inline(always)]
    fn visit(&mut self, prim: &Prim) -> bool {
        self.hit = self.q.prim(prim, self.t_max).is_some();
        self.hit
    }

    #[inline(always)]
    fn visit_triangles(&mut self, tris: &Triangles4, ids: &[u32; 4], count: usize) -> bool {
        let hits = self.q.triangles4(tris, count, self.t_max);
        self.take_triangles(&hits, tris, ids, count)
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn pair_query(&self) -> Option<(&Query<'_>, f32)> {
        Some((&self.q, self.t_max))
    }

    #[inline(always)]
    fn take_triangles(
        &mut self,
        hits: &TriHits4,
        _tris: &Triangles4,
        _ids: &[u32; 4],
        _count: usize,
    ) -> bool {
        self.hit = hits.mask != 0;
        self.hit
    }
}

/// The four-lane tests of two queries (`a` and `b`, each with the `t_max` its visitor would
/// test with) against lanes `0..count` of `tris`, as one eight-lane AVX2 test
/// ([`Shear::intersect4_pair`]): each answer bit for bit its own query's
/// [`intersect_triangles4`]. `None` when one test cannot hold both (another method, no shear,
/// or differently permuted shears).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn pair_triangles4(
    simd: pulp::x86::V3,
    (a, a_max): (&Query<'_>, f32),
    (b, b_max): (&Query<'_>, f32),
    tris: &Triangles4,
    count: usize,
) -> Option<(TriHits4, TriHits4)> {
    let (Some(sa), Some(sb)) = (a.shear.as_ref(), b.shear.as_ref()) else {
        return None;
    };
    if a.m.triangle != TriangleMethod::Watertight || b.m.triangle != TriangleMethod::Watertight {
        return None;
    }
    let (mut ha, mut hb) = Shear::intersect4_pair(
        simd,
        (sa, a.ray, a.t_min, a_max),
        (sb, b.ray, b.t_min, b_max),
        tris,
    )?;
    let used = (1u32 << count) - 1;
    ha.mask &= used;
    hb.mask &= used;
    Some((ha, hb))
}

/// The valid primitives of a build, in the order the accelerators number them (spheres
/// first, then triangles), read where the caller keeps them.
pub(in crate::accel) trait Prims: Sync {
    /// How many.
    fn count(&self) -> usize;
    /// Primitive `i` (`i < count()`).
    fn get(&self, i: usize) -> Prim;
    /// How many of the first are spheres (all the spheres).
    fn spheres(&self) -> usize;
    /// All of them, copied.
    fn to_vec(&self) -> Vec<Prim> {
        (0..self.count())
            .into_par_iter()
            .map(|i| self.get(i))
            .collect()
    }
}

impl Prims for [Prim] {
    fn count(&self) -> usize {
        self.len()
    }
    fn get(&self, i: usize) -> Prim {
        self[i]
    }
    fn spheres(&self) -> usize {
        self.iter()
            .take_while(|p| matches!(p.shape, Shape::Sphere { .. }))
            .count()
    }
}

/// The valid spheres (copied: they are few) and the valid triangles, read through the
/// caller's function.
struct Source<'a> {
    spheres: Vec<Prim>,
    triangle: &'a (dyn Fn(usize) -> [Vec3; 3] + Sync),
    /// The caller's index of each valid triangle, in order.
    valid: Vec<u32>,
    /// The id of the caller's first triangle (the number of spheres, valid or not).
    first_id: u32,
}

impl Prims for Source<'_> {
    fn count(&self) -> usize {
        self.spheres.len() + self.valid.len()
    }
    fn get(&self, i: usize) -> Prim {
        match self.spheres.get(i) {
            Some(p) => *p,
            None => {
                let t = self.valid[i - self.spheres.len()];
                Prim {
                    shape: Shape::Triangle((self.triangle)(t as usize)),
                    id: self.first_id + t,
                }
            }
        }
    }
    fn spheres(&self) -> usize {
        self.spheres.len()
    }
}

enum Imp {
    /// Every primitive in id order (also used for empty sets of every kind).
    None(Vec<Prim>),
    Grid(grid::Grid),
    Bvh(bvh::Bvh),
}

/// An acceleration structure over a compact copy of a [`PrimSet`]. Immutable after
/// [`Accel::build`]; shared by reference between worker threads.
pub struct Accel {
    kind: AccelKind,
    imp: Imp,
    prim_count: usize,
    skipped: usize,
}

impl std::fmt::Debug for Accel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Accel")
            .field("kind", &self.kind)
            .field("prims", &self.prim_count)
            .field("skipped", &self.skipped)
            .field("memory_bytes", &self.memory_bytes())
            .finish()
    }
}

impl Accel {
    /// Build the accelerator `kind` over `prims` (copied; invalid primitives dropped and
    /// counted). `Auto` resolves to a concrete kind, see [`auto_kind`].
    pub fn build(kind: AccelKind, prims: &PrimSet) -> Accel {
        Self::build_from(kind, &prims.spheres, prims.triangles.len(), &|i: usize| {
            prims.triangles[i]
        })
    }

    /// [`Accel::build`] over `spheres` and the `triangle_count` triangles that `triangle(i)`
    /// gives, read where they are (a scene's own list) instead of from a [`PrimSet`] copy: the
    /// same accelerator, with less memory at the build's peak. The BVH holds no list of
    /// primitives while `obvhs` builds (it reads each triangle twice: for its box, then for
    /// its leaf).
    pub fn build_from(
        kind: AccelKind,
        spheres: &[(Vec3, f32)],
        triangle_count: usize,
        triangle: &(dyn Fn(usize) -> [Vec3; 3] + Sync),
    ) -> Accel {
        // Spheres first (the BVH tells kinds apart by index), then triangles; ids are the
        // indices in the input (spheres, then triangles), kept by invalid ones too. In
        // parallel: a million triangles take tens of milliseconds to check.
        let first_id = spheres.len() as u32;
        let spheres: Vec<Prim> = spheres
            .iter()
            .enumerate()
            .filter_map(|(i, &(center, radius))| {
                (center.is_finite() && radius.is_finite() && radius > 0.0).then_some(Prim {
                    shape: Shape::Sphere { center, radius },
                    id: i as u32,
                })
            })
            .collect();
        let valid: Vec<u32> = (0..triangle_count)
            .into_par_iter()
            .filter(|&i| {
                let v = triangle(i);
                let cross = (v[1] - v[0]).cross(v[2] - v[0]);
                v.iter().all(|p| p.is_finite()) && cross.is_finite() && cross != Vec3::ZERO
            })
            .map(|i| i as u32)
            .collect();
        let source = Source {
            spheres,
            triangle,
            valid,
            first_id,
        };
        let prim_count = source.count();
        let skipped = first_id as usize + triangle_count - prim_count;
        let kind = match kind {
            AccelKind::Auto => auto_kind(prim_count),
            k => k,
        };
        let imp = match kind {
            _ if prim_count == 0 => Imp::None(Vec::new()),
            AccelKind::Grid => Imp::Grid(grid::Grid::build(source.to_vec())),
            AccelKind::Bvh => Imp::Bvh(bvh::Bvh::build_from(&source)),
            _ => Imp::None(source.to_vec()),
        };
        Accel {
            kind,
            imp,
            prim_count,
            skipped,
        }
    }

    /// The kind actually built (`Auto` resolved).
    pub fn kind(&self) -> AccelKind {
        self.kind
    }

    /// Valid primitives in the structure.
    pub fn prim_count(&self) -> usize {
        self.prim_count
    }

    /// Primitives dropped at build time (non-finite, zero-area, non-positive radius).
    pub fn skipped_prims(&self) -> usize {
        self.skipped
    }

    /// Depth of the BVH (root = 1), `None` for the other kinds (reported in docs/stability.md,
    /// row B2).
    pub fn bvh_depth(&self) -> Option<usize> {
        match &self.imp {
            Imp::Bvh(b) => Some(b.depth()),
            _ => None,
        }
    }

    /// Approximate heap memory of the structure, in bytes.
    pub fn memory_bytes(&self) -> usize {
        match &self.imp {
            Imp::None(p) => p.capacity() * size_of::<Prim>(),
            Imp::Grid(g) => g.memory_bytes(),
            Imp::Bvh(b) => b.memory_bytes(),
        }
    }

    /// The nearest hit in `(t_min, t_max)`, ties broken by the lower primitive id.
    pub fn closest_hit(&self, m: &Methods, ray: &Ray, t_min: f32, t_max: f32) -> Option<PrimHit> {
        if !ray_is_usable(ray, t_min, t_max) {
            return None;
        }
        let mut v = Closest::new(m, ray, t_min, t_max);
        self.walk(ray, t_min, t_max, &mut v);
        v.hit()
    }

    /// Whether anything is hit in `(t_min, t_max)` (stops at the first hit found).
    pub fn occluded(&self, m: &Methods, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        if !ray_is_usable(ray, t_min, t_max) {
            return false;
        }
        let mut v = AnyHit {
            q: Query::new(m, ray, t_min),
            t_max,
            hit: false,
        };
        self.walk(ray, t_min, t_max, &mut v);
        v.hit
    }

    /// [`Accel::closest_hit`] in `(0, ∞)` of each ray of a packet whose bit is set in
    /// `active` (bit `i` for `rays[i]`), into `out[i]`; the other entries of `out` are left
    /// alone. The BVH walks the rays together (`Bvh::walk_packet`); every answer
    /// is the single query's, bit for bit.
    #[inline(always)]
    pub fn closest_hits<const K: usize>(
        &self,
        m: &Methods,
        rays: &[Ray; K],
        active: u32,
        out: &mut [Option<PrimHit>; K],
    ) {
        let Imp::Bvh(bvh) = &self.imp else {
            for (i, ray) in rays.iter().enumerate() {
                if active & (1 << i) != 0 {
                    out[i] = self.closest_hit(m, ray, 0.0, f32::INFINITY);
                }
            }
            return;
        };
        let usable = active & usable_mask(rays, |_| f32::INFINITY);
        let mut vs: [Closest<'_>; K] =
            std::array::from_fn(|i| Closest::new(m, &rays[i], 0.0, f32::INFINITY));
        bvh.walk_packet(rays, 0.0, &mut vs, usable);
        for (i, v) in vs.iter().enumerate() {
            if active_bit(active, i) {
                out[i] = if active_bit(usable, i) { v.hit() } else { None };
            }
        }
    }

    /// [`Accel::occluded`] in `(0, lengths[i])` of each ray of a packet whose bit is set in
    /// `active`: the mask of those that are blocked. The BVH walks the rays together; every
    /// answer is the single query's.
    #[inline(always)]
    pub fn occluded_packet<const K: usize>(
        &self,
        m: &Methods,
        rays: &[Ray; K],
        lengths: &[f32; K],
        active: u32,
    ) -> u32 {
        let Imp::Bvh(bvh) = &self.imp else {
            let mut blocked = 0;
            for (i, ray) in rays.iter().enumerate() {
                if active & (1 << i) != 0 && self.occluded(m, ray, 0.0, lengths[i]) {
                    blocked |= 1 << i;
                }
            }
            return blocked;
        };
        let active = active & usable_mask(rays, |i| lengths[i]);
        let mut vs: [AnyHit<'_>; K] = std::array::from_fn(|i| AnyHit {
            q: Query::new(m, &rays[i], 0.0),
            t_max: lengths[i],
            hit: false,
        });
        bvh.walk_packet(rays, 0.0, &mut vs, active);
        let mut blocked = 0;
        for (i, v) in vs.iter().enumerate() {
            if active_bit(active, i) && v.hit {
                blocked |= 1 << i;
            }
        }
        blocked
    }

    #[inline]
    fn walk<V: Visitor>(&self, ray: &Ray, t_min: f32, t_max: f32, v: &mut V) {
        match &self.imp {
            Imp::None(prims) => {
                for p in prims {
                    if v.visit(p) {
                        return;
                    }
                }
            }
            Imp::Grid(g) => g.walk(ray, t_min, t_max, v),
            Imp::Bvh(b) => b.walk(ray, t_min, v),
        }
    }
}

/// The bits of the rays of a packet that [`ray_is_usable`] in `(0, t_max(i))`.
#[inline]
fn usable_mask(rays: &[Ray], t_max: impl Fn(usize) -> f32) -> u32 {
    let mut mask = 0;
    for (i, ray) in rays.iter().enumerate() {
        if ray_is_usable(ray, 0.0, t_max(i)) {
            mask |= 1 << i;
        }
    }
    mask
}

#[inline(always)]
fn active_bit(mask: u32, i: usize) -> bool {
    mask & (1 << i) != 0
}

/// Whether a query can be asked of `ray` in `(t_min, t_max)`: finite origin and direction, a
/// direction not zero, an interval not empty. Without branches, three components at a time
/// (`Vec3`'s `is_finite` tests them one by one, a branch each, and packets ask this of every
/// ray: 2 % of the camera- and shadow-ray frame's instructions).
#[inline(always)]
fn ray_is_usable(ray: &Ray, t_min: f32, t_max: f32) -> bool {
    let (o, d) = (Vec3A::from(ray.origin), Vec3A::from(ray.dir));
    let finite = (o.is_finite_mask() & d.is_finite_mask()).all();
    let moving = d.cmpne(Vec3A::ZERO).any();
    finite & moving & (t_min < t_max)
}

/// `1/d` per axis with zero (or subnormal) components mapped to `±f32::MAX` (sign of the zero):
/// the slab products `(plane − o)·inv` are then `±∞`, `0` or finite, never NaN.
#[inline]
fn safe_inv(d: Vec3) -> Vec3 {
    let f = |x: f32| {
        let i = 1.0 / x;
        if i.is_finite() {
            i
        } else {
            f32::MAX.copysign(x)
        }
    };
    Vec3::new(f(d.x), f(d.y), f(d.z))
}

/// The `t` interval in which the ray `o + t·d` (with `inv` = `1/d` per axis) meets the box
/// `[lo, hi]`, both ends widened by [`box_t_slack`]; empty (or NaN) when it misses.
#[inline(always)]
fn slab(o: Vec3, inv: Vec3, lo: Vec3, hi: Vec3) -> (f32, f32) {
    let mut t_enter = f32::NEG_INFINITY;
    let mut t_exit = f32::INFINITY;
    for axis in 0..3 {
        let ta = (lo[axis] - o[axis]) * inv[axis];
        let tb = (hi[axis] - o[axis]) * inv[axis];
        t_enter = t_enter.max(ta.min(tb));
        t_exit = t_exit.min(ta.max(tb));
    }
    // An infinite end (an axis-parallel ray beside the box: `±∞` from the clamped `1/d`) is
    // kept as it is: widening it would give `∞ − ∞ = NaN`, which `max`/`min` with the query's
    // interval then silently drop, turning a miss into a walk over the whole box.
    let slack = box_t_slack();
    let widen = |t: f32, by: f32| if t.is_finite() { t + by } else { t };
    (
        widen(t_enter, -t_enter.abs() * slack),
        widen(t_exit, t_exit.abs() * slack),
    )
}

/// Relative widening of both ends of a slab test's `t` interval (pbrt-v4 widens the far end:
/// `tFar *= 1 + 2γ(3)`), covering the rounding of `(plane − o)·(1/d)`.
#[inline]
fn box_t_slack() -> f32 {
    2.0 * crate::geometry::gamma(3)
}

/// [`box_t_slack`] as the factors the BVH's node tests scale a box's entry and exit `t` by,
/// `(1 − slack, 1 + slack)`: one product each instead of `t ∓ |t|·slack`. For `t ≥ 0` that is
/// the same widening but for the last rounding. A negative entry gives way to the query's
/// `t_min` either way, as long as `t_min ≥ 0` (it is 0 for every query the tracer, the
/// packets and the experiments ask; the BVH walks assert it in debug builds); a negative exit
/// stays negative either way: the rounded slab products keep the signs of the exact ones, so
/// the box lies behind the origin. The clamped `1/d` keeps the products finite for any scene
/// within bounds, so no `∞ − ∞` appears.
#[inline(always)]
pub(crate) fn box_t_scales() -> (f32, f32) {
    let slack = box_t_slack();
    (1.0 - slack, 1.0 + slack)
}

/// Asks for the cache lines of `at` ahead of their use: a hint, with no effect on any answer.
/// (`pulp`'s SSE token makes the prefetch instruction a safe call; SSE is part of x86-64.)
#[inline(always)]
pub fn prefetch<T>(at: &T) {
    #[cfg(target_arch = "x86_64")]
    if let Some(sse) = pulp::core_arch::x86::Sse::try_new() {
        use std::arch::x86_64::_MM_HINT_T0;
        let p = (at as *const T).cast::<i8>();
        // Every line from the first byte to the last.
        for line in (0..size_of::<T>()).step_by(64) {
            sse._mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(line));
        }
        sse._mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(size_of::<T>().saturating_sub(1)));
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branch-free usability test answers as the component-by-component one for every mix
    /// of finite, signed-zero, subnormal, huge, infinite and NaN components.
    #[test]
    fn usable_rays_are_those_with_finite_moving_directions() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -2.5,
            f32::MIN_POSITIVE / 8.0,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let reference = |ray: &Ray, t_min: f32, t_max: f32| {
            ray.origin.is_finite() && ray.dir.is_finite() && ray.dir != Vec3::ZERO && t_min < t_max
        };
        let mut usable = 0;
        let mut k = 0usize;
        for &a in &values {
            for &b in &values {
                for &c in &values {
                    // Origin and direction from the same triple, rotated, and a plain one.
                    let dir = Vec3::new(a, b, c);
                    let origins = [Vec3::new(c, a, b), Vec3::new(0.5, -1.0, 2.0)];
                    for origin in origins {
                        let ray = Ray::new(origin, dir);
                        let (t_min, t_max) = [(0.0, f32::INFINITY), (0.0, 1.0), (1.0, 1.0)][k % 3];
                        k += 1;
                        let expected = reference(&ray, t_min, t_max);
                        assert_eq!(
                            ray_is_usable(&ray, t_min, t_max),
                            expected,
                            "{ray:?} in ({t_min}, {t_max})"
                        );
                        usable += usize::from(expected);
                    }
                }
            }
        }
        assert!(usable > 200 && usable < k - 200, "{usable} of {k}");
    }
}
