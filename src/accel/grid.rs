//! Uniform grid ("spatial subdivision" in the lecture) with 3D-DDA traversal (Amanatides & Woo
//! 1987, "A Fast Voxel Traversal Algorithm for Ray Tracing").
//!
//! Build: the scene's bounds (padded, so flat scenes such as a ground plane have thickness) are
//! cut into `res[0]·res[1]·res[2]` cells, about [`GRID_DENSITY`] cells per primitive, at most
//! [`GRID_MAX_RES`] per axis. Each primitive goes into every cell its padded bounding box
//! overlaps (cell lists stored compactly, CSR style).
//!
//! Traversal: the ray is clipped to the grid box; per axis the next cell-boundary crossing is
//! computed directly as `(plane_i − o)/d` from the boundary index (not accumulated), so all `t`
//! values are within a few ulp of exact and the cells visited are consistent with them. The
//! walk stops once the best hit so far is no farther than the current cell's exit.
//!
//! Why the padding ([`GRID_PRIM_PAD`]): the DDA's crossing times carry a relative error of about
//! `γ(3)`, i.e. a distance error of `γ(3)·t` along the ray. Primitive boxes padded by `1e-3` of a
//! cell absorb that for ray origins up to about 40 grid sizes away, which is far beyond any
//! camera in practice.
use glam::{IVec3, Vec3};

use super::{Prim, Visitor, safe_inv, slab};

/// Target cells per primitive (the `λ` in `res = cbrt(λ·N/V)·extent`): 4, the usual middle of
/// the 2…8 range.
pub const GRID_DENSITY: f32 = 4.0;

/// Cells per axis at most (so at most `128³ ≈ 2.1e6` cells).
pub const GRID_MAX_RES: i32 = 128;

/// Cap on the total number of cell references (primitive-in-cell entries):
/// `GRID_MAX_REFS_PER_PRIM · N + GRID_MAX_REFS_EXTRA`. The resolution is halved until the scene
/// fits, so huge or stacked primitives (each in every cell) cannot blow up memory; a typical
/// scene needs 2–5 references per primitive.
pub const GRID_MAX_REFS_PER_PRIM: usize = 16;

/// See [`GRID_MAX_REFS_PER_PRIM`]: room for a few primitives that cover the whole grid.
pub const GRID_MAX_REFS_EXTRA: usize = 1 << 20;

/// Padding of each primitive's box when it is inserted, as a fraction of the cell size.
pub const GRID_PRIM_PAD: f32 = 1e-3;

/// Padding of the scene bounds, as a fraction of their largest extent (gives flat scenes a
/// thickness and keeps padded primitives inside the grid).
pub const GRID_BOUNDS_PAD: f32 = 4e-3;

pub(super) struct Grid {
    /// Primitives in id order; cells refer to them by index.
    prims: Vec<Prim>,
    /// Cell boundary 0 on each axis; boundary `i` is `lo + i·cell` (always computed so).
    lo: Vec3,
    cell: Vec3,
    inv_cell: Vec3,
    res: IVec3,
    /// `cell_start[c]..cell_start[c + 1]` indexes `items` for cell `c`.
    cell_start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    pub(super) fn build(prims: Vec<Prim>) -> Grid {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let boxes: Vec<(Vec3, Vec3)> = prims.iter().map(Prim::bounds).collect();
        for (a, b) in &boxes {
            lo = lo.min(*a);
            hi = hi.max(*b);
        }
        if prims.is_empty() {
            lo = Vec3::ZERO;
            hi = Vec3::ONE;
        }
        let magnitude = lo.abs().max(hi.abs()).max_element();
        let pad = GRID_BOUNDS_PAD * (hi - lo).max_element() + 64.0 * f32::EPSILON * magnitude;
        let pad = pad.max(f32::MIN_POSITIVE);
        let lo = lo - Vec3::splat(pad);
        let hi = hi + Vec3::splat(pad);
        let extent = hi - lo;

        let mut res = resolution(extent, prims.len());
        let max_refs = GRID_MAX_REFS_PER_PRIM * prims.len() + GRID_MAX_REFS_EXTRA;
        loop {
            let grid = Self::with_res(lo, extent, res);
            let refs = grid.count_refs(&boxes, magnitude);
            if refs <= max_refs || res == IVec3::ONE {
                return grid.fill(prims, &boxes, magnitude, refs);
            }
            res = (res / 2).max(IVec3::ONE);
        }
    }

    fn with_res(lo: Vec3, extent: Vec3, res: IVec3) -> Grid {
        let resf = res.as_vec3();
        Grid {
            prims: Vec::new(),
            lo,
            cell: extent / resf,
            inv_cell: resf / extent,
            res,
            cell_start: Vec::new(),
            items: Vec::new(),
        }
    }

    #[inline(always)]
    fn plane(&self, axis: usize, i: i32) -> f32 {
        self.lo[axis] + i as f32 * self.cell[axis]
    }

    /// The inclusive cell range on `axis` of the closed interval `[a, b]`, consistent with
    /// [`Grid::plane`] (cell `i` is `[plane(i), plane(i + 1)]`).
    fn cell_range(&self, axis: usize, a: f32, b: f32) -> (i32, i32) {
        let n = self.res[axis];
        let index =
            |x: f32| (((x - self.lo[axis]) * self.inv_cell[axis]).floor() as i32).clamp(0, n - 1);
        let mut i0 = index(a);
        while i0 > 0 && self.plane(axis, i0) >= a {
            i0 -= 1;
        }
        while i0 < n - 1 && self.plane(axis, i0 + 1) < a {
            i0 += 1;
        }
        let mut i1 = index(b).max(i0);
        while i1 < n - 1 && self.plane(axis, i1 + 1) <= b {
            i1 += 1;
        }
        while i1 > i0 && self.plane(axis, i1) > b {
            i1 -= 1;
        }
        (i0, i1)
    }

    fn padded(&self, b: &(Vec3, Vec3), magnitude: f32) -> (Vec3, Vec3) {
        let pad = GRID_PRIM_PAD * self.cell + Vec3::splat(16.0 * f32::EPSILON * magnitude);
        (b.0 - pad, b.1 + pad)
    }

    fn ranges(&self, b: &(Vec3, Vec3), magnitude: f32) -> [(i32, i32); 3] {
        let (a, b) = self.padded(b, magnitude);
        [0, 1, 2].map(|axis| self.cell_range(axis, a[axis], b[axis]))
    }

    fn count_refs(&self, boxes: &[(Vec3, Vec3)], magnitude: f32) -> usize {
        boxes
            .iter()
            .map(|b| {
                self.ranges(b, magnitude)
                    .iter()
                    .map(|(i0, i1)| (i1 - i0 + 1) as usize)
                    .product::<usize>()
            })
            .sum()
    }

    /// Cell boundary `res` on each axis: the grid box is `[lo, far_corner()]`.
    fn far_corner(&self) -> Vec3 {
        Vec3::new(
            self.plane(0, self.res.x),
            self.plane(1, self.res.y),
            self.plane(2, self.res.z),
        )
    }

    /// The box of cell `c` (a [`Grid::cell_index`]), bounded by the same planes the traversal
    /// crosses.
    pub(super) fn cell_box(&self, c: usize) -> (Vec3, Vec3) {
        let (nx, ny) = (self.res.x as usize, self.res.y as usize);
        let i = [c % nx, (c / nx) % ny, c / (nx * ny)].map(|i| i as i32);
        let lo = Vec3::new(
            self.plane(0, i[0]),
            self.plane(1, i[1]),
            self.plane(2, i[2]),
        );
        let hi = Vec3::new(
            self.plane(0, i[0] + 1),
            self.plane(1, i[1] + 1),
            self.plane(2, i[2] + 1),
        );
        (lo, hi)
    }

    /// The ids of the primitives listed in cell `c`.
    pub(super) fn cell_prims(&self, c: usize) -> impl Iterator<Item = u32> + '_ {
        let (s, e) = (self.cell_start[c] as usize, self.cell_start[c + 1] as usize);
        self.items[s..e].iter().map(|&p| self.prims[p as usize].id)
    }

    /// Number of cells.
    pub(super) fn cells(&self) -> usize {
        self.cell_start.len() - 1
    }

    #[inline(always)]
    fn cell_index(&self, x: i32, y: i32, z: i32) -> usize {
        (x + self.res.x * (y + self.res.y * z)) as usize
    }

    fn fill(
        mut self,
        prims: Vec<Prim>,
        boxes: &[(Vec3, Vec3)],
        magnitude: f32,
        refs: usize,
    ) -> Grid {
        let cells = (self.res.x * self.res.y * self.res.z) as usize;
        let mut counts = vec![0u32; cells + 1];
        let ranges: Vec<[(i32, i32); 3]> =
            boxes.iter().map(|b| self.ranges(b, magnitude)).collect();
        let for_each_cell = |r: &[(i32, i32); 3], f: &mut dyn FnMut(usize)| {
            for z in r[2].0..=r[2].1 {
                for y in r[1].0..=r[1].1 {
                    for x in r[0].0..=r[0].1 {
                        f(self.cell_index(x, y, z));
                    }
                }
            }
        };
        for r in &ranges {
            for_each_cell(r, &mut |c| counts[c + 1] += 1);
        }
        for c in 0..cells {
            counts[c + 1] += counts[c];
        }
        let mut items = vec![0u32; refs];
        let mut cursor = counts.clone();
        for (i, r) in ranges.iter().enumerate() {
            for_each_cell(r, &mut |c| {
                items[cursor[c] as usize] = i as u32;
                cursor[c] += 1;
            });
        }
        self.cell_start = counts;
        self.items = items;
        self.prims = prims;
        self
    }

    pub(super) fn memory_bytes(&self) -> usize {
        self.prims.capacity() * size_of::<Prim>()
            + self.cell_start.capacity() * 4
            + self.items.capacity() * 4
    }

    /// 3D-DDA over the cells the ray crosses in `(t_min, t_max)`, visiting their primitives in
    /// order along the ray; stops when the visitor asks or its limit lies within the cell.
    pub(super) fn walk<V: Visitor>(
        &self,
        ray: &crate::geometry::Ray,
        t_min: f32,
        t_max: f32,
        v: &mut V,
    ) {
        let o = ray.origin;
        let d = ray.dir;
        let inv = safe_inv(d);
        let t_plane = |axis: usize, i: i32| (self.plane(axis, i) - o[axis]) * inv[axis];

        // Clip to the grid box [plane(0), plane(res)], widened by the slab test's rounding.
        let (t_enter, t_exit) = slab(o, inv, self.lo, self.far_corner());
        let t0 = t_enter.max(t_min);
        let t1 = t_exit.min(t_max);
        if t0.is_nan() || t1.is_nan() || t0 > t1 {
            return;
        }

        // Starting cell, made consistent with the crossing times on each axis.
        let mut idx = [0i32; 3];
        let mut step = [0i32; 3];
        let mut t_next = [0f32; 3];
        for axis in 0..3 {
            let n = self.res[axis];
            let x = if t0.is_finite() {
                o[axis] + t0 * d[axis]
            } else {
                o[axis]
            };
            let mut i =
                (((x - self.lo[axis]) * self.inv_cell[axis]).floor() as i32).clamp(0, n - 1);
            if inv[axis] > 0.0 {
                // Cell i spans t in [t_plane(i), t_plane(i + 1)].
                while i + 1 < n && t_plane(axis, i + 1) <= t0 {
                    i += 1;
                }
                while i > 0 && t_plane(axis, i) > t0 {
                    i -= 1;
                }
                step[axis] = 1;
                t_next[axis] = t_plane(axis, i + 1);
            } else {
                // Cell i spans t in [t_plane(i + 1), t_plane(i)].
                while i > 0 && t_plane(axis, i) <= t0 {
                    i -= 1;
                }
                while i + 1 < n && t_plane(axis, i + 1) > t0 {
                    i += 1;
                }
                step[axis] = -1;
                t_next[axis] = t_plane(axis, i);
            }
            idx[axis] = i;
        }

        loop {
            let c = self.cell_index(idx[0], idx[1], idx[2]);
            v.enter(c as u32);
            let (s, e) = (self.cell_start[c] as usize, self.cell_start[c + 1] as usize);
            for &p in &self.items[s..e] {
                if v.visit(&self.prims[p as usize]) {
                    return;
                }
            }
            let t_cell_exit = t_next[0].min(t_next[1]).min(t_next[2]);
            if v.limit() <= t_cell_exit || t_cell_exit >= t1 {
                return;
            }
            let axis = if t_next[0] <= t_next[1] && t_next[0] <= t_next[2] {
                0
            } else if t_next[1] <= t_next[2] {
                1
            } else {
                2
            };
            idx[axis] += step[axis];
            if idx[axis] < 0 || idx[axis] >= self.res[axis] {
                return;
            }
            t_next[axis] = if step[axis] > 0 {
                t_plane(axis, idx[axis] + 1)
            } else {
                t_plane(axis, idx[axis])
            };
        }
    }
}

/// Cells per axis: about `GRID_DENSITY·n` cells of equal size, clamped to
/// `1..=GRID_MAX_RES`. Axes that come out thinner than one cell (flat scenes) get one cell
/// and the budget is spread over the others.
fn resolution(extent: Vec3, n: usize) -> IVec3 {
    let budget = (GRID_DENSITY * n.max(1) as f32).max(1.0);
    let mut res = IVec3::ONE;
    let mut free = [true; 3];
    for _ in 0..3 {
        let dims = free.iter().filter(|f| **f).count();
        if dims == 0 {
            break;
        }
        let volume: f32 = (0..3).filter(|&a| free[a]).map(|a| extent[a]).product();
        let k = (budget / volume).powf(1.0 / dims as f32);
        let mut changed = false;
        for a in 0..3 {
            if free[a] {
                let r = extent[a] * k;
                if r < 1.0 {
                    free[a] = false;
                    changed = true;
                    res[a] = 1;
                } else {
                    res[a] = (r.round() as i32).clamp(1, GRID_MAX_RES);
                }
            }
        }
        if !changed {
            break;
        }
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Closest, Shape};
    use crate::geometry::{Methods, Ray};

    /// Rays that start exactly on cell boundaries (and run along them) must see what brute
    /// force sees: this is where the starting cell's rounding matters.
    #[test]
    fn rays_starting_on_cell_planes_match_brute_force() {
        let mut rnd = crate::rng::uniform(0x2545_f491_4f6c_dd1d);
        let mut prims = Vec::new();
        for id in 0..400u32 {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 4.0 - 2.0;
            let shape = if id % 3 == 0 {
                Shape::Sphere {
                    center: c,
                    radius: 0.05 + 0.2 * rnd(),
                }
            } else {
                let e =
                    |r: &mut dyn FnMut() -> f32| Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 0.6;
                Shape::Triangle([c, c + e(&mut rnd), c + e(&mut rnd)])
            };
            prims.push(Prim { shape, id });
        }
        let grid = Grid::build(prims.clone());
        let m = Methods::default();
        let mut checked = 0;
        for k in 0..6000 {
            let axis = k % 3;
            let i = (rnd() * (grid.res[axis] + 1) as f32) as i32;
            let mut o = Vec3::new(rnd(), rnd(), rnd()) * 5.0 - 2.5;
            o[axis] = grid.plane(axis, i.min(grid.res[axis]));
            let mut d = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
            match k % 4 {
                0 => d[axis] = 0.0,           // along the plane
                1 => d[(axis + 1) % 3] = 0.0, // axis-parallel component
                _ => {}
            }
            let ray = Ray::new(o, d.normalize());
            let mut brute = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            prims.iter().for_each(|p| {
                brute.visit(p);
            });
            let mut walked = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            grid.walk(&ray, 0.0, f32::INFINITY, &mut walked);
            assert_eq!(walked.hit(), brute.hit(), "ray {k}: {ray:?}");
            checked += usize::from(brute.hit().is_some());
        }
        assert!(checked > 1000, "{checked}");
    }
}
