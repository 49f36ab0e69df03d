//! The accelerator made visible (the lecture's "BVH" and "spatial subdivision"): what one
//! query's traversal entered and tested, and the boxes of the structure level by level, for the
//! views to draw.
//!
//! A recording query runs the very traversal of [`Accel::closest_hit`] and [`Accel::occluded`]
//! with a visitor that wraps theirs and notes each box entered ([`Visitor::enter`], a no-op for
//! every other visitor) and each primitive tested, so its answer is theirs by construction.
//! Boxes are what the traversal tests: the BVH's padded child boxes (the root's box is the union
//! of its children's) and the grid's cells bounded by the planes its 3D-DDA crosses.

use glam::Vec3;

use super::{Accel, AnyHit, Closest, Imp, Prim, PrimHit, Query, Visitor, ray_is_usable};
use crate::geometry::{Methods, Ray, Triangles4};

/// What one query's traversal did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Visits {
    /// Boxes entered, in the order the traversal entered them: BVH nodes and leaves (with their
    /// level, root = 0) or grid cells (level 0, empty cells included); empty for `AccelKind::None`.
    pub boxes: Vec<VisitedBox>,
    /// Primitive ids tested, in order (ids as in [`super::PrimSet`]: spheres first, then
    /// triangles). The grid tests a primitive once per cell it lies in, so ids can repeat.
    pub prims: Vec<u32>,
    /// The query's answer, the same as [`Accel::closest_hit`] gives; for
    /// [`Accel::occluded_visits`], `Some` exactly when [`Accel::occluded`] is `true`, with the
    /// first hit found (not necessarily the nearest).
    pub hit: Option<PrimHit>,
}

/// One box a traversal entered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisitedBox {
    pub lo: Vec3,
    pub hi: Vec3,
    /// The BVH level (root = 0); 0 for grid cells.
    pub level: u32,
}

/// One box of the structure, with what it holds: a BVH node or leaf, or a non-empty grid cell.
#[derive(Clone, Debug, PartialEq)]
pub struct AccelBox {
    pub lo: Vec3,
    pub hi: Vec3,
    /// The BVH level (root = 0); 0 for grid cells.
    pub level: u32,
    /// Index in [`Accel::boxes`] of the enclosing BVH node; `None` for the root and for cells.
    pub parent: Option<usize>,
    /// The primitive ids of a BVH leaf or a grid cell; empty for inner BVH nodes.
    pub prims: Vec<u32>,
}

/// Where an occlusion query stopped: what to test again for the hit it found.
enum Stopped {
    Prim(Prim),
    Triangles(Triangles4, [u32; 4], usize),
}

/// Wraps a query's visitor and notes what its traversal does.
struct Record<V> {
    inner: V,
    keys: Vec<u32>,
    prims: Vec<u32>,
    stopped: Option<Stopped>,
}

impl<V> Record<V> {
    fn new(inner: V) -> Self {
        Self {
            inner,
            keys: Vec::new(),
            prims: Vec::new(),
            stopped: None,
        }
    }
}

impl<V: Visitor> Visitor for Record<V> {
    const ORDERED: bool = V::ORDERED;

    fn limit(&self) -> f32 {
        self.inner.limit()
    }

    fn visit(&mut self, prim: &Prim) -> bool {
        self.prims.push(prim.id);
        let stop = self.inner.visit(prim);
        if stop {
            self.stopped = Some(Stopped::Prim(*prim));
        }
        stop
    }

    fn visit_triangles(&mut self, tris: &Triangles4, ids: &[u32; 4], count: usize) -> bool {
        self.prims.extend_from_slice(&ids[..count]);
        let stop = self.inner.visit_triangles(tris, ids, count);
        if stop {
            self.stopped = Some(Stopped::Triangles(*tris, *ids, count));
        }
        stop
    }

    fn enter(&mut self, key: u32) {
        self.keys.push(key);
    }
}

impl Accel {
    /// [`Accel::closest_hit`], with the boxes its traversal entered and the primitives it
    /// tested.
    pub fn closest_hit_visits(&self, m: &Methods, ray: &Ray, t_min: f32, t_max: f32) -> Visits {
        if !ray_is_usable(ray, t_min, t_max) {
            return Visits::default();
        }
        let mut v = Record::new(Closest::new(m, ray, t_min, t_max));
        self.walk(ray, t_min, t_max, &mut v);
        Visits {
            boxes: self.entered(&v.keys, ray, t_min, t_max),
            prims: v.prims,
            hit: v.inner.hit(),
        }
    }

    /// [`Accel::occluded`], with the boxes its traversal entered, the primitives it tested and
    /// the hit that stopped it.
    pub fn occluded_visits(&self, m: &Methods, ray: &Ray, t_min: f32, t_max: f32) -> Visits {
        if !ray_is_usable(ray, t_min, t_max) {
            return Visits::default();
        }
        let mut v = Record::new(AnyHit {
            q: Query::new(m, ray, t_min),
            t_max,
            hit: false,
        });
        self.walk(ray, t_min, t_max, &mut v);
        // The same test again on what stopped the walk gives the hit `AnyHit` only counted.
        let q = &v.inner.q;
        let hit = match &v.stopped {
            Some(Stopped::Prim(p)) => q.prim(p, t_max).map(|(t, b1, b2)| PrimHit {
                t,
                prim: p.id,
                b1,
                b2,
            }),
            Some(Stopped::Triangles(tris, ids, count)) => {
                let hits = q.triangles4(tris, *count, t_max);
                let lane = hits.mask.trailing_zeros() as usize;
                hits.get(lane).map(|h| PrimHit {
                    t: h.t,
                    prim: ids[lane],
                    b1: h.b1,
                    b2: h.b2,
                })
            }
            None => None,
        };
        debug_assert_eq!(hit.is_some(), v.inner.hit);
        Visits {
            boxes: self.entered(&v.keys, ray, t_min, t_max),
            prims: v.prims,
            hit,
        }
    }

    /// The boxes of the keys a traversal passed to [`Visitor::enter`].
    fn entered(&self, keys: &[u32], ray: &Ray, t_min: f32, t_max: f32) -> Vec<VisitedBox> {
        match &self.imp {
            Imp::None(_) => Vec::new(),
            Imp::Grid(g) => keys
                .iter()
                .map(|&c| {
                    let (lo, hi) = g.cell_box(c as usize);
                    VisitedBox { lo, hi, level: 0 }
                })
                .collect(),
            Imp::Bvh(b) => b.entered_boxes(keys, ray, t_min, t_max),
        }
    }

    /// Levels of the BVH: the root is level 0 and the deepest leaves are level `levels() − 1`.
    /// 0 for the other kinds and for an empty BVH.
    pub fn levels(&self) -> u32 {
        match &self.imp {
            // A wide node at depth d (root = 1) is at level d − 1; its child boxes at level d.
            Imp::Bvh(b) if b.depth() > 0 => b.depth() as u32 + 1,
            _ => 0,
        }
    }

    /// The boxes of the tree cut at `level` (root = 0): every BVH box at that level, and the
    /// leaves that end above it (so the boxes of each level hold every primitive, and those of
    /// level `k + 1` lie inside those of level `k`); for the grid, its non-empty cells at level
    /// 0; empty for `AccelKind::None` and for levels from [`Accel::levels`] on.
    pub fn level_boxes(&self, level: u32) -> Vec<(Vec3, Vec3)> {
        match &self.imp {
            Imp::None(_) => Vec::new(),
            Imp::Grid(g) if level == 0 => (0..g.cells())
                .filter(|&c| g.cell_prims(c).next().is_some())
                .map(|c| g.cell_box(c))
                .collect(),
            Imp::Grid(_) => Vec::new(),
            Imp::Bvh(b) => {
                let mut out = Vec::new();
                if level < self.levels() {
                    b.for_each_box(|t, _, leaf| {
                        if t.level == level || (leaf.is_some() && t.level < level) {
                            out.push((t.lo, t.hi));
                        }
                    });
                }
                out
            }
        }
    }

    /// Every box of the structure with what it holds: the BVH's boxes, parents before children
    /// (the root first), or the grid's non-empty cells; empty for `AccelKind::None`.
    pub fn boxes(&self) -> Vec<AccelBox> {
        match &self.imp {
            Imp::None(_) => Vec::new(),
            Imp::Grid(g) => (0..g.cells())
                .filter_map(|c| {
                    let prims: Vec<u32> = g.cell_prims(c).collect();
                    let (lo, hi) = g.cell_box(c);
                    (!prims.is_empty()).then_some(AccelBox {
                        lo,
                        hi,
                        level: 0,
                        parent: None,
                        prims,
                    })
                })
                .collect(),
            Imp::Bvh(b) => {
                let mut out = Vec::new();
                b.for_each_box(|t, parent, leaf| {
                    out.push(AccelBox {
                        lo: t.lo,
                        hi: t.hi,
                        level: t.level,
                        parent,
                        prims: leaf.map(|w| b.leaf_prims(w)).unwrap_or_default(),
                    });
                });
                out
            }
        }
    }
}
