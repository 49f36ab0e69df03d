//! BVH (the lecture's "Bounding Volume Hierarchy") built with `obvhs`: a compressed wide BVH8
//! (Ylitie et al. 2017) over spheres and triangles in one tree.
//!
//! Build: the steps of `obvhs::cwbvh::builder::build_cwbvh` with preset
//! [`BvhBuildParams::medium_build`] (PLOC, reinsertion, `bvh2_to_cwbvh` with up to 3
//! primitives per leaf), done one by one so pathological input can be caught in between; then
//! the primitive copy is reordered by `primitive_indices` so leaves read it sequentially, each
//! entry keeping its original id.
//!
//! Pathological input (STABILITY B2). PLOC pairs neighbours whose union is cheapest and breaks
//! equal costs one way, so regular input (many identical boxes, boxes in a row, nested boxes
//! with one centre) merges only one pair per pass: the tree becomes a chain, the build is
//! quadratic (16k identical triangles: 9 s) and the BVH8 is deeper than `obvhs`' 32-entry
//! traversal stack (which then silently drops nodes). We therefore
//! - grow every box by a pseudo-random `< 2⁻¹²` of its size ([`jitter`]; still conservative)
//!   so equal costs become distinct;
//! - build a balanced median-split tree ourselves ([`median_bvh2`]) when more than
//!   [`MAX_STACKED`] primitives share one box centre, or when PLOC's tree is deeper than
//!   [`MAX_BVH2_DEPTH`] anyway.
//!
//! Traversal is our own loop, a transcription of `obvhs::traverse!` (same node order, same
//! child/primitive bit masks) with our own node test, because the stock one does not suit a
//! renderer that must agree exactly with brute force:
//! - `CwBvhNode::intersect_ray` clamps every box's entry `t` to `obvhs`' absolute `EPSILON =
//!   1e-4` and ignores `ray.tmin`: boxes that end within `1e-4` of the origin are culled, so
//!   at scene scales of `1e-3` and below (and for any occluder closer than `1e-4`) the BVH
//!   misses hits that brute force finds.
//! - `Ray::new` replaces direction components with `|d| ≤ f32::EPSILON` by `±1/EPSILON`, which
//!   narrows the slab intervals of nearly axis-parallel rays (not conservative).
//! - `CwBvh::ray_traverse` accepts a primitive only if `t < tmax` of the best so far, so a
//!   tie-break by id would need extra state anyway; `ray_traverse_anyhit` is not an occlusion
//!   query (it calls the closure for every primitive reached and never stops early;
//!   `ray_traverse_miss` is the one that stops at the first `t < tmax`).
//! - The fixed traversal stack (`StackStack<_, 32>`) silently overwrites its top entry when
//!   full; ours is a plain array and the build guarantees the tree fits it.
//!
//! Our node test: child boxes are decoded to world space and padded by a few ulp of the node's
//! magnitude ([`NODE_PAD_REL`], covering the 8-bit quantisation's rounding), slab `t` values
//! use `1/d` clamped to `±2⁶⁰` (no NaN), both ends of the interval are widened by `2γ(3)` of
//! their magnitude (pbrt-v4 widens the far end; the near end too so that a primitive whose
//! computed `t` is an ulp before its box's computed entry is not culled), and the interval is
//! clipped to the caller's `(t_min, best t]`, inclusive so equal `t` with a lower id is still
//! found.
use glam::{UVec2, Vec3, Vec3A, Vec4, uvec2, vec3a};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, node::Bvh2Node, reinsertion::ReinsertionOptimizer},
    cwbvh::{
        CwBvh, bvh2_to_cwbvh::bvh2_to_cwbvh, firstbithigh, node::CwBvhNode, node::extract_byte64,
    },
    ploc::PlocBuilder,
};

use super::{Prim, Visitor, box_t_slack};
use crate::geometry::Ray;

/// Padding of decoded child boxes, relative to `|node origin| + node extent` (per axis): the
/// decode `p + e·q` and the builder's `floor/ceil((b − p)/e)` each round by at most a few ulp
/// of that magnitude.
pub const NODE_PAD_REL: f32 = 8.0 * f32::EPSILON;

/// More primitives than this with exactly the same box centre (duplicates, concentric spheres)
/// make PLOC chain; the median-split builder is used instead.
pub const MAX_STACKED: usize = 64;

/// A binary tree deeper than this is replaced by the median-split one. Real scenes stay far
/// below (PLOC gives about `1.5·log2(N)`: 24 for 1e5 random boxes); the conversion to BVH8
/// recurses this deep, and the BVH8 (depth about a third of it) must fit [`STACK_SIZE`].
pub const MAX_BVH2_DEPTH: usize = 96;

/// Traversal stack capacity: at least the BVH8's depth, which the build guarantees.
const STACK_SIZE: usize = 64;

pub(super) struct Bvh {
    cw: CwBvh,
    /// Primitives in `cw.primitive_indices` order.
    prims: Vec<Prim>,
    depth: usize,
}

impl Bvh {
    pub(super) fn build(prims: Vec<Prim>) -> Bvh {
        let boxes: Vec<Aabb> = prims
            .iter()
            .map(|p| {
                let (lo, hi) = p.bounds();
                Aabb::new(lo.into(), hi.into())
            })
            .collect();
        let params = BvhBuildParams::medium_build();
        let max_leaf = params.max_prims_per_leaf.clamp(1, 3);
        let mut cw = None;
        if max_stacked(&boxes) <= MAX_STACKED {
            let jittered: Vec<Aabb> = boxes
                .iter()
                .enumerate()
                .map(|(i, b)| jitter(b, i))
                .collect();
            let mut bvh2 = PlocBuilder::with_capacity(jittered.len()).build(
                params.ploc_search_distance,
                &jittered,
                (0..jittered.len() as u32).collect(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
            if bvh2_depth(&bvh2) <= MAX_BVH2_DEPTH {
                let tree = bvh2_to_cwbvh(&bvh2, max_leaf, true, false);
                if tree_depth(&tree) < STACK_SIZE {
                    cw = Some(tree);
                }
            }
        }
        let cw = cw.unwrap_or_else(|| bvh2_to_cwbvh(&median_bvh2(&boxes), max_leaf, true, false));
        let depth = tree_depth(&cw);
        // A balanced binary tree of 2³² leaves has depth 33, its BVH8 far less.
        debug_assert!(depth < STACK_SIZE);
        let ordered = cw
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        Bvh {
            cw,
            prims: ordered,
            depth,
        }
    }

    pub(super) fn memory_bytes(&self) -> usize {
        self.cw.nodes.capacity() * size_of::<CwBvhNode>()
            + self.cw.primitive_indices.capacity() * 4
            + self.prims.capacity() * size_of::<Prim>()
    }

    pub(super) fn depth(&self) -> usize {
        self.depth
    }

    /// `obvhs::traverse!`, transcribed, with [`intersect_node`] as the node test.
    pub(super) fn walk<V: Visitor>(&self, ray: &Ray, t_min: f32, v: &mut V) {
        if self.cw.nodes.is_empty() {
            return;
        }
        let r = TravRay {
            origin: ray.origin.into(),
            inv: trav_inv(ray.dir),
            oct_inv4: octant_inv4(ray.dir.into()),
            t_min,
        };
        let mut stack = [UVec2::ZERO; STACK_SIZE];
        let mut sp = 0usize;
        let mut current_group = uvec2(0, 0x8000_0000);
        let mut primitive_group = UVec2::ZERO;
        loop {
            while primitive_group.y != 0 {
                let local = firstbithigh(primitive_group.y);
                primitive_group.y &= !(1u32 << local);
                let index = (primitive_group.x + local) as usize;
                if v.visit(&self.prims[index]) {
                    return;
                }
            }
            if current_group.y & 0xff00_0000 != 0 {
                let hits_imask = current_group.y;
                let child_index_offset = firstbithigh(hits_imask);
                let child_index_base = current_group.x;
                current_group.y &= !(1u32 << child_index_offset);
                if current_group.y & 0xff00_0000 != 0 {
                    stack[sp] = current_group;
                    sp += 1;
                }
                let slot_index = (child_index_offset - 24) ^ (r.oct_inv4 & 0xff);
                let relative_index = (hits_imask & !(0xffff_ffffu32 << slot_index)).count_ones();
                let node = &self.cw.nodes[(child_index_base + relative_index) as usize];
                let hitmask = intersect_node(node, &r, v.limit());
                current_group = uvec2(
                    node.child_base_idx,
                    (hitmask & 0xff00_0000) | node.imask as u32,
                );
                primitive_group = uvec2(node.primitive_base_idx, hitmask & 0x00ff_ffff);
            } else {
                current_group = UVec2::ZERO;
            }
            if primitive_group.y == 0 && current_group.y & 0xff00_0000 == 0 {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                current_group = stack[sp];
            }
        }
    }
}

struct TravRay {
    origin: Vec3A,
    /// `1/d`, clamped to `±2⁶⁰` (zero components keep their sign): the node test multiplies it
    /// by extents and box offsets, and the clamp keeps those products finite for any scene
    /// below about `1e17` in size, so no `0·∞` NaN can appear. Treating `|d| < 2⁻⁶⁰` as `2⁻⁶⁰`
    /// is harmless: child boxes are padded, so an origin on an unpadded face is strictly inside.
    inv: Vec3A,
    oct_inv4: u32,
    t_min: f32,
}

/// Bound of `|1/d|` in [`TravRay::inv`].
const INV_DIR_CLAMP: f32 = (1u64 << 60) as f32;

fn trav_inv(d: Vec3) -> Vec3A {
    let f = |x: f32| {
        let i = 1.0 / x;
        if i.abs() < INV_DIR_CLAMP {
            i
        } else {
            INV_DIR_CLAMP.copysign(x)
        }
    };
    vec3a(f(d.x), f(d.y), f(d.z))
}

/// `obvhs`' private `ray_get_octant_inv4`: which child order to use for this direction.
#[inline(always)]
fn octant_inv4(dir: Vec3A) -> u32 {
    (if dir.x < 0.0 { 0 } else { 0x0404_0404 })
        | (if dir.y < 0.0 { 0 } else { 0x0202_0202 })
        | (if dir.z < 0.0 { 0 } else { 0x0101_0101 })
}

#[inline(always)]
fn quad(q: &[u8; 8], half: usize) -> Vec4 {
    let i = 4 * half;
    Vec4::new(
        q[i] as f32,
        q[i + 1] as f32,
        q[i + 2] as f32,
        q[i + 3] as f32,
    )
}

/// Conservative ray/child-box test of one CWBVH node, four children at a time (glam's `Vec4`
/// is SSE on x86); returns `obvhs`' hit mask layout (internal children in the top byte, leaf
/// primitives in the low 24 bits).
///
/// Per axis the slab `t` of a child face `p ± pad + e·q` is `q·(e/d) + (p ± pad − o)/d`; the
/// rounding of this form is a few ulp of `|p − o| + 255·e` (in distance), covered by the pad
/// (`|p| + 256·e` part) and the `2γ(3)` widening of both ends of the interval (the `|o|`
/// part, and the relative error of the primitives' own `t`).
#[inline(always)]
fn intersect_node(node: &CwBvhNode, r: &TravRay, t_max: f32) -> u32 {
    let e = node.compute_extent();
    let p = Vec3A::from(node.p);
    // Isotropic: a primitive's computed hit point is off by a few ulp of its largest
    // coordinate in *every* axis, even along an axis where the box is flat (a plane at z = 0).
    let pad = Vec3A::splat((p.abs() + e * 256.0).max_element() * NODE_PAD_REL);
    let scale = e * r.inv;
    let base_lo = (p - pad - r.origin) * r.inv;
    let base_hi = (p + pad - r.origin) * r.inv;
    let slack = box_t_slack();
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(r.oct_inv4);
    let mut hit_mask = 0;
    for half in 0..2 {
        let mut t_near = Vec4::splat(f32::NEG_INFINITY);
        let mut t_far = Vec4::splat(f32::INFINITY);
        let axes = [
            (&node.child_min_x, &node.child_max_x),
            (&node.child_min_y, &node.child_max_y),
            (&node.child_min_z, &node.child_max_z),
        ];
        for (axis, (q_min, q_max)) in axes.into_iter().enumerate() {
            let lo = quad(q_min, half) * scale[axis] + Vec4::splat(base_lo[axis]);
            let hi = quad(q_max, half) * scale[axis] + Vec4::splat(base_hi[axis]);
            // For a negative direction the max face is entered first.
            let (near, far) = if r.inv[axis] >= 0.0 {
                (lo, hi)
            } else {
                (hi, lo)
            };
            t_near = t_near.max(near);
            t_far = t_far.min(far);
        }
        // Widen both ends by the rounding of the slab arithmetic *and* of the primitives' own
        // t: a tie (equal t, lower id) in a flat box must not be culled by an ulp.
        let t_near = (t_near - t_near.abs() * slack).max(Vec4::splat(r.t_min));
        let t_far = (t_far + t_far.abs() * slack).min(Vec4::splat(t_max));
        let mask = t_near.cmple(t_far).bitmask();
        for j in 0..4 {
            if mask & (1 << j) != 0 {
                let child = 4 * half + j;
                hit_mask |= extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
            }
        }
    }
    hit_mask
}

/// Depth of the CWBVH (root = 1): the most stack entries a traversal can need.
fn tree_depth(cw: &CwBvh) -> usize {
    if cw.nodes.is_empty() {
        return 0;
    }
    let mut max = 0;
    let mut todo = vec![(0u32, 1usize)];
    while let Some((i, d)) = todo.pop() {
        max = max.max(d);
        let node = &cw.nodes[i as usize];
        for child in 0..8 {
            if !node.is_leaf(child) && !node.is_child_empty(child) {
                todo.push((node.child_node_index(child), d + 1));
            }
        }
    }
    max
}

/// Depth of a binary BVH (root = 1), iteratively.
fn bvh2_depth(bvh: &Bvh2) -> usize {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut max = 0;
    let mut todo = vec![(0usize, 1usize)];
    while let Some((i, d)) = todo.pop() {
        max = max.max(d);
        let node = &bvh.nodes[i];
        if node.prim_count == 0 {
            let c = node.first_index as usize;
            todo.push((c, d + 1));
            todo.push((c + 1, d + 1));
        }
    }
    max
}

/// The largest number of boxes sharing exactly the same centre.
fn max_stacked(boxes: &[Aabb]) -> usize {
    let mut keys: Vec<[u32; 3]> = boxes
        .iter()
        .map(|b| {
            let c = b.center();
            [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()]
        })
        .collect();
    keys.sort_unstable();
    let mut best = 0;
    let mut run = 0;
    for i in 0..keys.len() {
        run = if i > 0 && keys[i] == keys[i - 1] {
            run + 1
        } else {
            1
        };
        best = best.max(run);
    }
    best
}

/// `b` grown on every side by a pseudo-random fraction in `[0, 2⁻¹²)` of its largest extent
/// (a hash of `i`, so builds are deterministic). Breaks PLOC's equal-cost ties; costs a few
/// parts in 10⁴ of box size in traversal.
fn jitter(b: &Aabb, i: usize) -> Aabb {
    let mut x = (i as u32).wrapping_mul(0x9E37_79B9);
    x ^= x >> 16;
    x = x.wrapping_mul(0x85EB_CA6B);
    x ^= x >> 13;
    let h = (x >> 8) as f32 / (1u32 << 24) as f32;
    let grow = Vec3A::splat((b.max - b.min).max_element() * h * (1.0 / 4096.0));
    Aabb::new(b.min - grow, b.max + grow)
}

/// A balanced binary BVH with one primitive per leaf: split at the median centroid on the
/// widest centroid axis (ties by index), or in index halves when all centroids coincide.
/// Depth `ceil(log2 N) + 1` whatever the input.
fn median_bvh2(boxes: &[Aabb]) -> Bvh2 {
    let n = boxes.len();
    let centers: Vec<Vec3A> = boxes.iter().map(Aabb::center).collect();
    let mut bvh = Bvh2 {
        nodes: Vec::with_capacity(2 * n - 1),
        primitive_indices: (0..n as u32).collect(),
        children_are_ordered_after_parents: true,
        ..Default::default()
    };
    bvh.nodes.push(Bvh2Node::default());
    let mut todo = vec![(0usize, 0usize, n)];
    while let Some((node, start, end)) = todo.pop() {
        let idx = &mut bvh.primitive_indices[start..end];
        let mut aabb = Aabb::empty();
        let mut cb = Aabb::empty();
        for &i in idx.iter() {
            aabb = aabb.union(&boxes[i as usize]);
            cb.extend(centers[i as usize]);
        }
        if end - start == 1 {
            bvh.nodes[node] = Bvh2Node::new(aabb, 1, start as u32);
            continue;
        }
        let axis = cb.largest_axis();
        let mid = (end - start) / 2;
        if cb.diagonal()[axis] > 0.0 {
            idx.select_nth_unstable_by(mid, |&a, &b| {
                centers[a as usize][axis]
                    .total_cmp(&centers[b as usize][axis])
                    .then(a.cmp(&b))
            });
        }
        let first = bvh.nodes.len();
        bvh.nodes.push(Bvh2Node::default());
        bvh.nodes.push(Bvh2Node::default());
        bvh.nodes[node] = Bvh2Node::new(aabb, 0, first as u32);
        todo.push((first, start, start + mid));
        todo.push((first + 1, start + mid, end));
    }
    bvh.max_depth = bvh2_depth(&bvh).max(obvhs::bvh2::DEFAULT_MAX_STACK_DEPTH);
    bvh
}
