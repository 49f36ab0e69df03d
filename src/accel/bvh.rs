//! BVH (the lecture's "Bounding Volume Hierarchy"): a 4-wide BVH with `f32` child boxes over
//! spheres and triangles in one tree, built from a binary BVH made with `obvhs`.
//!
//! Build: `obvhs`' PLOC with the parameters of [`build_params`] (its `medium_build` preset,
//! `fast_build` from [`FAST_BUILD_MIN_PRIMS`] primitives on), then its
//! reinsertion optimiser (Meister et al. 2021, Meister & Bittner 2018), then our own collapse
//! to four children per node: a surface-area cost decides, bottom up, which subtrees of at
//! most [`MAX_LEAF`] primitives become leaves, and each node of the wide tree takes the two
//! children of its binary node and keeps opening the largest inner child until it has four
//! (the way Embree and Wald et al. 2008 collapse). The primitives are then copied in leaf
//! order, each keeping its original id, so a leaf reads a contiguous run.
//!
//! Why not `obvhs`' compressed wide BVH (CWBVH, Ylitie et al. 2017), which this module used
//! first: its child boxes are quantised to 8 bits, so every node visit decodes 48 bytes to
//! floats before the slab test (a third of the render's instructions went there), its stock
//! traversal has the pitfalls listed below, and its build converts with an `O(n·k²)` cost
//! table. Four `f32` boxes are one SSE slab test of six loads, six subtractions and six
//! multiplications; the node is 128 bytes (two cache lines) against CWBVH's 80, for
//! about a third as many nodes as leaves.
//!
//! Pathological input (STABILITY B2). PLOC pairs neighbours whose union is cheapest and breaks
//! equal costs one way, so regular input (many identical boxes, boxes in a row, nested boxes
//! with one centre) merges only one pair per pass: the tree becomes a chain and the build is
//! quadratic (16k identical triangles: 9 s). We therefore
//! - grow every box by a pseudo-random `< 2⁻¹²` of its size ([`jitter`]; still conservative)
//!   so equal costs become distinct;
//! - build a balanced median-split tree ourselves ([`median_bvh2`]) when more than
//!   [`MAX_STACKED`] primitives share one box centre, or when PLOC's tree is deeper than
//!   [`MAX_BVH2_DEPTH`], or when its wide tree could need more than [`STACK_SIZE`] traversal
//!   stack entries.
//!
//! Traversal, and what it must guarantee (the accelerators agree bit for bit with brute
//! force): child boxes are padded by a few ulp of their magnitude in every axis
//! ([`NODE_PAD_REL`]), slab `t` values use `1/d` clamped to `±2⁶⁰` (no NaN), both ends of the
//! interval are widened by `2γ(3)` of their magnitude (pbrt-v4 widens the far end; the near
//! end too so that a primitive whose computed `t` is an ulp before its box's computed entry
//! is not culled), and the interval is clipped to the caller's `(t_min, best t]`, inclusive so
//! an equal `t` with a lower id is still found. Closest-hit queries visit the hit children
//! nearest first and keep each pushed child's entry `t`, so a child is skipped when it is
//! popped behind the best hit found since; occlusion queries push in any order and stop at
//! the first hit. The stack is a plain array that the build guarantees is deep enough.
//!
//! Pitfalls of `obvhs`' stock traversals that this avoids (found while this module used them):
//! `CwBvhNode::intersect_ray` clamps every box's entry `t` to an absolute `1e-4` and ignores
//! `ray.tmin` (misses at scene scales of `1e-3` and below); `Ray::new` replaces small direction
//! components by `±1/EPSILON` (not conservative); `ray_traverse` accepts only `t < tmax` (no
//! tie-break by id); `ray_traverse_anyhit` never stops early; the fixed traversal stack
//! (`StackStack<_, 32>`) silently overwrites its top entry when full.
use glam::{Vec3, Vec3A, Vec4};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, node::Bvh2Node, reinsertion::ReinsertionOptimizer},
    ploc::PlocBuilder,
};
use rayon::prelude::*;

use super::{Prim, Shape, Visitor, box_t_slack};
use crate::geometry::{Ray, Triangles4};

/// Padding of child boxes in every axis, relative to the largest coordinate magnitude of the
/// box: a primitive's computed hit point is off by a few ulp of its largest coordinate in
/// *every* axis, even along an axis where the box is flat (a plane at z = 0).
pub const NODE_PAD_REL: f32 = 8.0 * f32::EPSILON;

/// More primitives than this with exactly the same box centre (duplicates, concentric spheres)
/// make PLOC chain; the median-split builder is used instead.
pub const MAX_STACKED: usize = 64;

/// A binary tree deeper than this is replaced by the median-split one. Real scenes stay far
/// below (PLOC gives about `1.5·log2(N)`: 24 for 1e5 random boxes).
pub const MAX_BVH2_DEPTH: usize = 96;

/// Traversal stack capacity in entries. The build checks the worst case of the tree (on any
/// root-to-leaf path, the sum of each node's children but one, plus 3 for the fixed-length
/// push) against it; the median-split
/// tree of up to 2²⁸ primitives needs at most 3 per level for about 13 levels.
pub const STACK_SIZE: usize = 64;

/// Entries of the stack a query starts with; deeper queries continue on a [`STACK_SIZE`] one.
const SHORT_STACK: usize = 16;

/// From this many primitives on the build uses obvhs's `fast_build` preset instead of
/// `medium_build`.
///
/// Measured on the issue-7 Whitted scene (`cargo bench --bench peer`'s torus, 4 samples a
/// pixel, 2 threads, median of 5 interleaved runs; minimum render time in brackets):
///
/// | triangles | medium: build / render | fast: build / render | very fast: build / render |
/// |---:|---|---|---|
/// | 320k | 0.174 / 0.318 (0.298) s | 0.154 / 0.314 (0.299) s | 0.140 / 0.320 (0.312) s |
/// | 1M | 0.604 / 0.382 (0.335) s | 0.524 / 0.347 (0.336) s | 0.421 / 0.345 (0.336) s |
/// | 2M | 1.058 / 0.343 (0.315) s | 0.917 / 0.317 (0.311) s | 0.844 / 0.332 (0.322) s |
///
/// The renders are within noise of each other (our own surface-area collapse to the 4-wide
/// tree evens out the binary trees' differences), the build is 13–15% faster with `fast`.
/// Below this size the build takes well under a third of a second anyway, and a scene less
/// even than the torus can profit from `medium`'s wider PLOC search; `very_fast` is not used
/// because its single reinsertion pass (1% of the nodes) leaves the most room for bad trees on
/// uneven input, for a further 10–20% of build time.
pub const FAST_BUILD_MIN_PRIMS: usize = 500_000;

/// obvhs's build preset for `prims` primitives (see [`FAST_BUILD_MIN_PRIMS`]).
pub fn build_params(prims: usize) -> BvhBuildParams {
    if prims < FAST_BUILD_MIN_PRIMS {
        BvhBuildParams::medium_build()
    } else {
        BvhBuildParams::fast_build()
    }
}

/// Most triangles in one leaf: one four-lane test. A leaf holds triangles or one sphere.
pub const MAX_LEAF: usize = 4;

/// Costs of a visit relative to each other, for the surface-area leaf decision: a node (four
/// box tests), a leaf of up to four triangles (one four-lane test), a sphere.
const NODE_COST: f32 = 1.0;
const PACKET_COST: f32 = 1.5;
const SPHERE_COST: f32 = 1.0;

/// A child word with this bit is a leaf, otherwise a node index. A triangle leaf is
/// `LEAF | packet << 2 | (count − 1)`, a sphere leaf `LEAF | SPHERE | index`.
const LEAF: u32 = 0x8000_0000;
const SPHERE: u32 = 0x4000_0000;

/// Most primitives the leaf words can address (2²⁸ packets of up to four triangles).
pub const MAX_PRIMS: usize = 1 << 28;

/// Up to four triangles of a leaf, one per lane, and their primitive ids.
#[derive(Clone, Copy, Debug)]
struct Packet {
    tris: Triangles4,
    ids: [u32; 4],
}

/// One node of the 4-wide tree: two cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    /// Child boxes by plane, one lane per child: min x, max x, min y, max y, min z, max z.
    /// Padded by [`NODE_PAD_REL`]; empty slots hold zeros and are masked by `valid`.
    planes: [Vec4; 6],
    /// Child words (see [`LEAF`]).
    child: [u32; 4],
    /// Bit `i` set when slot `i` holds a child.
    valid: u32,
}

pub(super) struct Bvh {
    nodes: Vec<Node>,
    /// Triangle leaves, in tree order.
    packets: Vec<Packet>,
    /// Sphere leaves.
    spheres: Vec<Prim>,
    depth: usize,
}

impl Bvh {
    pub(super) fn build(prims: Vec<Prim>) -> Bvh {
        // `Accel` refuses to build this far (see there); ids would not fit a leaf word.
        assert!(prims.len() <= MAX_PRIMS, "more than 2^28 primitives");
        let bounds = |prims: &[Prim]| -> Vec<Aabb> {
            prims
                .par_iter()
                .map(|p| {
                    let (lo, hi) = p.bounds();
                    Aabb::new(lo.into(), hi.into())
                })
                .collect()
        };
        let params = build_params(prims.len());
        let mut built = None;
        let mut boxes = bounds(&prims);
        if max_stacked(&boxes) <= MAX_STACKED {
            boxes
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, b)| *b = jitter(b, i));
            let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
                params.ploc_search_distance,
                &boxes,
                (0..boxes.len() as u32).collect(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
            // Peak memory: the boxes are not needed by the collapse (the fallback below makes
            // its own, unjittered).
            drop(boxes);
            built = collapse(bvh2, &prims).filter(|b| stack_need(&b.nodes) + 3 <= STACK_SIZE);
        } else {
            drop(boxes);
        }
        built.unwrap_or_else(|| {
            let b = collapse(median_bvh2(&bounds(&prims)), &prims).unwrap_or_else(|| Bvh {
                nodes: Vec::new(),
                packets: Vec::new(),
                spheres: Vec::new(),
                depth: 0,
            });
            // A balanced binary tree of 2²⁸ leaves has depth 29; its 4-wide collapse needs
            // fewer than 3·15 stack entries.
            debug_assert!(stack_need(&b.nodes) + 3 <= STACK_SIZE);
            b
        })
    }

    pub(super) fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Node>()
            + self.packets.capacity() * size_of::<Packet>()
            + self.spheres.capacity() * size_of::<Prim>()
    }

    pub(super) fn depth(&self) -> usize {
        self.depth
    }

    /// Visits every primitive whose padded box the ray's `(t_min, v.limit()]` interval meets;
    /// nearest child first when [`Visitor::ORDERED`].
    #[inline]
    pub(super) fn walk<V: Visitor>(&self, ray: &Ray, t_min: f32, v: &mut V) {
        if self.nodes.is_empty() {
            return;
        }
        let r = TravRay::new(ray, t_min);
        self.walk_from::<V, SHORT_STACK>(&r, v, &[], 0);
    }

    /// The traversal loop from child word `word` with `seed` on a stack of `N` entries. A
    /// query starts on a short stack (clearing it is part of every query's cost) and, in the
    /// rare case it would overflow, continues on a [`STACK_SIZE`] one.
    #[inline(always)]
    fn walk_from<V: Visitor, const N: usize>(
        &self,
        r: &TravRay,
        v: &mut V,
        seed: &[(u32, f32)],
        mut word: u32,
    ) {
        let mut stack = [(0u32, 0f32); N];
        // Element by element: these copies are short, and `copy_from_slice` of a variable
        // length calls `memcpy`.
        for (to, from) in stack.iter_mut().zip(seed) {
            *to = *from;
        }
        let mut sp = seed.len();
        let (nx, ny, nz) = (r.near[0], r.near[1], r.near[2]);
        let (fx, fy, fz) = (nx ^ 1, ny ^ 1, nz ^ 1);
        loop {
            if word & LEAF != 0 {
                let stop = if word & SPHERE != 0 {
                    v.visit(&self.spheres[(word & !(LEAF | SPHERE)) as usize])
                } else {
                    let packet = &self.packets[((word & !LEAF) >> 2) as usize];
                    v.visit_triangles(&packet.tris, &packet.ids, (word & 3) as usize + 1)
                };
                if stop {
                    return;
                }
            } else {
                let node = &self.nodes[word as usize];
                let p = &node.planes;
                let t_near = ((p[nx] - r.ox) * r.ix)
                    .max((p[ny] - r.oy) * r.iy)
                    .max((p[nz] - r.oz) * r.iz);
                let t_far = ((p[fx] - r.ox) * r.ix)
                    .min((p[fy] - r.oy) * r.iy)
                    .min((p[fz] - r.oz) * r.iz);
                // Widen both ends by the rounding of the slab arithmetic *and* of the
                // primitives' own t: a tie (equal t, lower id) in a flat box must not be
                // culled by an ulp.
                let slack = Vec4::splat(box_t_slack());
                let t_near = (t_near - t_near.abs() * slack).max(r.t_min);
                let t_far = (t_far + t_far.abs() * slack).min(Vec4::splat(v.limit()));
                let mut mask = t_near.cmple(t_far).bitmask() & node.valid;
                if mask != 0 {
                    if mask & (mask - 1) == 0 {
                        word = node.child[mask.trailing_zeros() as usize];
                        continue;
                    }
                    let t = t_near.to_array();
                    // Up to four hits; all but the one taken next are pushed with their
                    // entry t (sorted farthest first when ordered, so the nearest is next).
                    let mut hits = [(0u32, 0f32); 4];
                    let mut k = 0;
                    while mask != 0 {
                        let i = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        let mut j = k;
                        if V::ORDERED {
                            while j > 0 && hits[j - 1].1 < t[i] {
                                hits[j] = hits[j - 1];
                                j -= 1;
                            }
                        }
                        hits[j] = (node.child[i], t[i]);
                        k += 1;
                    }
                    word = hits[k - 1].0;
                    // Three entries are always written (only `k − 1` are kept): a fixed-length
                    // copy, where a loop of 1 to 3 would mispredict.
                    if N < STACK_SIZE && sp + 3 > N {
                        let mut deeper = [(0u32, 0f32); STACK_SIZE];
                        deeper[..sp].copy_from_slice(&stack[..sp]);
                        deeper[sp..sp + k - 1].copy_from_slice(&hits[..k - 1]);
                        let seed = &deeper[..sp + k - 1];
                        return self.walk_from::<V, STACK_SIZE>(r, v, seed, word);
                    }
                    stack[sp] = hits[0];
                    stack[sp + 1] = hits[1];
                    stack[sp + 2] = hits[2];
                    sp += k - 1;
                    continue;
                }
            }
            // Pop the next child whose entry is not behind the best hit found since.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (w, t) = stack[sp];
                if t <= v.limit() {
                    word = w;
                    break;
                }
            }
        }
    }
}

/// A ray prepared for the node test.
struct TravRay {
    ox: Vec4,
    oy: Vec4,
    oz: Vec4,
    ix: Vec4,
    iy: Vec4,
    iz: Vec4,
    /// Per axis, the plane index entered first: `2·axis`, `+1` (the max plane) for a
    /// negative direction.
    near: [usize; 3],
    t_min: Vec4,
}

impl TravRay {
    #[inline(always)]
    fn new(ray: &Ray, t_min: f32) -> Self {
        let inv = trav_inv(ray.dir);
        let o = ray.origin;
        let near = |i: f32, axis: usize| 2 * axis + usize::from(i < 0.0);
        TravRay {
            ox: Vec4::splat(o.x),
            oy: Vec4::splat(o.y),
            oz: Vec4::splat(o.z),
            ix: Vec4::splat(inv.x),
            iy: Vec4::splat(inv.y),
            iz: Vec4::splat(inv.z),
            near: [near(inv.x, 0), near(inv.y, 1), near(inv.z, 2)],
            t_min: Vec4::splat(t_min),
        }
    }
}

/// `1/d`, clamped to `±2⁶⁰` (zero components keep their sign): the node test multiplies it by
/// box offsets, and the clamp keeps those products finite for any scene below about `1e17` in
/// size, so no `0·∞` NaN can appear. Treating `|d| < 2⁻⁶⁰` as `2⁻⁶⁰` is harmless: child boxes
/// are padded, so an origin on an unpadded face is strictly inside.
#[inline(always)]
fn trav_inv(d: Vec3) -> Vec3A {
    let d = Vec3A::from(d);
    let i = Vec3A::ONE / d;
    let clamp = Vec3A::splat(INV_DIR_CLAMP);
    Vec3A::select(i.abs().cmplt(clamp), i, clamp.copysign(d))
}

/// Bound of `|1/d|` in [`trav_inv`].
const INV_DIR_CLAMP: f32 = (1u64 << 60) as f32;

/// The box of a binary node, padded by [`NODE_PAD_REL`] of its largest magnitude.
fn padded(b: &Aabb) -> (Vec3A, Vec3A) {
    let magnitude = b.min.abs().max(b.max.abs()).max_element();
    let pad = Vec3A::splat((magnitude * NODE_PAD_REL).max(f32::MIN_POSITIVE));
    (b.min - pad, b.max + pad)
}

/// One node of a binary BVH copied in pre-order (depth first, left child first): the left
/// child of an inner node `i` is `i + 1`, and a subtree is a contiguous run. 28 bytes.
#[derive(Clone, Copy)]
struct FlatNode {
    min: [f32; 3],
    max: [f32; 3],
    /// The right child (inner nodes) or, with [`FLAT_LEAF`], the primitive index (leaves).
    link: u32,
}

/// The leaf flag of [`FlatNode::link`] (primitive and node indices stay below 2²⁹).
const FLAT_LEAF: u32 = 1 << 31;

impl FlatNode {
    fn leaf(&self) -> bool {
        self.link & FLAT_LEAF != 0
    }
    fn prim(&self) -> u32 {
        self.link & !FLAT_LEAF
    }
    fn aabb(&self) -> Aabb {
        Aabb::new(Vec3A::from_array(self.min), Vec3A::from_array(self.max))
    }
    /// As [`Aabb::half_area`] (same operations, so the same tree as before the copy).
    fn half_area(&self) -> f32 {
        let d = Vec3::from_array(self.max) - Vec3::from_array(self.min);
        (d.x + d.y) * d.z + d.x * d.y
    }
}

/// `bvh2` in pre-order, or `None` when it is empty or deeper than [`MAX_BVH2_DEPTH`]. This is
/// the one pass that follows the build's node order (after reinsertion, scattered over memory:
/// a cache miss per node); everything after it reads the copy front to back or back to front.
fn preorder(bvh2: &Bvh2) -> Option<Vec<FlatNode>> {
    if bvh2.nodes.is_empty() {
        return None;
    }
    let mut flat: Vec<FlatNode> = Vec::with_capacity(bvh2.nodes.len());
    // (binary node, pre-order index of the parent whose right child it is, depth)
    let mut todo = vec![(0u32, u32::MAX, 1usize)];
    while let Some((i, parent, d)) = todo.pop() {
        if d > MAX_BVH2_DEPTH {
            return None;
        }
        let here = flat.len() as u32;
        if parent != u32::MAX {
            flat[parent as usize].link = here;
        }
        let node = &bvh2.nodes[i as usize];
        let (min, max) = (node.aabb.min.to_array(), node.aabb.max.to_array());
        if node.prim_count == 0 {
            flat.push(FlatNode { min, max, link: 0 });
            todo.push((node.first_index + 1, here, d + 1));
            todo.push((node.first_index, u32::MAX, d + 1));
        } else {
            assert!(node.prim_count == 1, "binary leaves hold one primitive");
            flat.push(FlatNode {
                min,
                max,
                link: FLAT_LEAF | bvh2.primitive_indices[node.first_index as usize],
            });
        }
    }
    Some(flat)
}

/// The 4-wide tree of a binary BVH whose leaves hold one primitive each (PLOC's and
/// [`median_bvh2`]'s do); `None` for an empty tree or one deeper than [`MAX_BVH2_DEPTH`].
fn collapse(bvh2: Bvh2, prims: &[Prim]) -> Option<Bvh> {
    let flat = preorder(&bvh2)?;
    // The copy is all that is needed from here on.
    drop(bvh2);
    let n = flat.len();
    let right = |i: usize| flat[i].link as usize;
    // Bottom up (reverse pre-order): primitives under each node and the surface-area cost of
    // its best subtree; `leaf[i]` when the node's subtree is cheaper as one leaf.
    // `Accel` lists the spheres first: an index tells the kind without reading the primitive
    // (reading them in tree order misses the cache on every one).
    let sphere_count = prims
        .iter()
        .take_while(|p| matches!(p.shape, Shape::Sphere { .. }))
        .count();
    debug_assert!(
        prims[sphere_count..]
            .iter()
            .all(|p| matches!(p.shape, Shape::Triangle(_)))
    );
    let is_sphere = |i: usize| i < sphere_count;
    let mut count = vec![0u32; n];
    let mut spheres = vec![0u32; n];
    let mut cost = vec![0f32; n];
    let mut leaf = vec![false; n];
    for i in (0..n).rev() {
        let node = &flat[i];
        let area = node.half_area().max(0.0);
        if node.leaf() {
            let sphere = is_sphere(node.prim() as usize);
            count[i] = 1;
            spheres[i] = u32::from(sphere);
            cost[i] = if sphere { SPHERE_COST } else { PACKET_COST } * area;
            leaf[i] = true;
        } else {
            let (l, r) = (i + 1, right(i));
            count[i] = count[l] + count[r];
            spheres[i] = spheres[l] + spheres[r];
            let split = NODE_COST * area + cost[l] + cost[r];
            let as_leaf = PACKET_COST * area;
            if spheres[i] == 0 && count[i] as usize <= MAX_LEAF && as_leaf <= split {
                cost[i] = as_leaf;
                leaf[i] = true;
            } else {
                cost[i] = split;
            }
        }
    }

    let mut nodes: Vec<Node> = Vec::new();
    let mut sphere_leaves: Vec<Prim> = Vec::new();
    // Each triangle leaf's primitive indices, four per leaf (the first repeated); gathered into
    // packets afterwards in one tight loop, whose independent loads overlap their cache misses.
    let mut leaf_prims: Vec<[u32; 4]> = Vec::new();
    let mut depth = 0;
    // (binary node, wide node to fill, its depth); the root's slots are the root's children,
    // or the root itself when it is a leaf.
    let mut todo = vec![(0usize, 0u32, 1usize)];
    nodes.push(empty_node());
    while let Some((b, w, d)) = todo.pop() {
        depth = depth.max(d);
        // (binary node, how many times opened); a tie in area opens the shallower child, so
        // equal boxes (a median-split tree of duplicates) collapse evenly.
        let mut slots = [(0usize, 0u32); 4];
        let mut len = if leaf[b] {
            slots[0] = (b, 0);
            1
        } else {
            slots[0] = (b + 1, 0);
            slots[1] = (right(b), 0);
            2
        };
        // Open the largest inner child until there are four.
        while len < 4 {
            let mut best: Option<(usize, f32, u32)> = None;
            for (k, &(s, opened)) in slots[..len].iter().enumerate() {
                if leaf[s] {
                    continue;
                }
                let area = flat[s].half_area();
                let better = match best {
                    None => true,
                    Some((_, a, o)) => area > a || (area == a && opened < o),
                };
                if better {
                    best = Some((k, area, opened));
                }
            }
            let Some((k, _, opened)) = best else { break };
            let s = slots[k].0;
            slots.copy_within(k + 1..len, k + 2);
            slots[k] = (s + 1, opened + 1);
            slots[k + 1] = (right(s), opened + 1);
            len += 1;
        }
        let mut node = empty_node();
        for (slot, &(s, _)) in slots[..len].iter().enumerate() {
            let (lo, hi) = padded(&flat[s].aabb());
            for (axis, (l, h)) in [(lo.x, hi.x), (lo.y, hi.y), (lo.z, hi.z)]
                .into_iter()
                .enumerate()
            {
                node.planes[2 * axis][slot] = l;
                node.planes[2 * axis + 1][slot] = h;
            }
            node.valid |= 1 << slot;
            if leaf[s] && spheres[s] == 1 {
                node.child[slot] = LEAF | SPHERE | sphere_leaves.len() as u32;
                sphere_leaves.push(prims[flat[s].prim() as usize]);
            } else if leaf[s] {
                // The subtree's triangles, left to right: the leaves of its run of
                // `2·count − 1` nodes, as one packet.
                let c = count[s] as usize;
                let mut ids = [0u32; 4];
                for (k, f) in flat[s..s + 2 * c - 1]
                    .iter()
                    .filter(|f| f.leaf())
                    .enumerate()
                {
                    ids[k] = f.prim();
                }
                for k in c..4 {
                    ids[k] = ids[0];
                }
                node.child[slot] = LEAF | ((leaf_prims.len() as u32) << 2) | (c as u32 - 1);
                leaf_prims.push(ids);
            } else {
                let index = nodes.len() as u32;
                nodes.push(empty_node());
                node.child[slot] = index;
                todo.push((s, index, d + 1));
            }
        }
        nodes[w as usize] = node;
    }
    drop(flat);
    nodes.shrink_to_fit();
    let triangle = |i: u32| match prims[i as usize].shape {
        Shape::Triangle(v) => (v, prims[i as usize].id),
        // Leaves hold no spheres (`spheres[s] == 0`).
        Shape::Sphere { .. } => unreachable!("a sphere in a triangle leaf"),
    };
    // Random reads of the primitives: split over the threads.
    let packets = leaf_prims
        .par_iter()
        .map(|ids| {
            let t = ids.map(triangle);
            Packet {
                tris: Triangles4::new(&t.map(|(v, _)| v)),
                ids: t.map(|(_, id)| id),
            }
        })
        .collect();
    Some(Bvh {
        nodes,
        packets,
        spheres: sphere_leaves,
        depth,
    })
}

fn empty_node() -> Node {
    Node {
        planes: [Vec4::ZERO; 6],
        child: [0; 4],
        valid: 0,
    }
}

/// The most stack entries a traversal of `nodes` can need: on the worst root-to-leaf path,
/// each node pushes all its children but one.
fn stack_need(nodes: &[Node]) -> usize {
    if nodes.is_empty() {
        return 0;
    }
    let mut worst = 0;
    let mut todo = vec![(0u32, 0usize)];
    while let Some((i, above)) = todo.pop() {
        let node = &nodes[i as usize];
        let here = above + (node.valid.count_ones() as usize).saturating_sub(1);
        worst = worst.max(here);
        for slot in 0..4 {
            if node.valid & (1 << slot) != 0 && node.child[slot] & LEAF == 0 {
                todo.push((node.child[slot], here));
            }
        }
    }
    worst
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
        .par_iter()
        .map(|b| {
            let c = b.center();
            [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()]
        })
        .collect();
    keys.par_sort_unstable();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Closest;
    use crate::geometry::Methods;

    #[test]
    fn the_preset_follows_the_scene_size() {
        let ratio = |n| build_params(n).reinsertion_batch_ratio;
        let (medium, fast) = (
            BvhBuildParams::medium_build().reinsertion_batch_ratio,
            BvhBuildParams::fast_build().reinsertion_batch_ratio,
        );
        assert_ne!(medium, fast);
        assert_eq!(ratio(0), medium);
        assert_eq!(ratio(FAST_BUILD_MIN_PRIMS - 1), medium);
        assert_eq!(ratio(FAST_BUILD_MIN_PRIMS), fast);
        assert_eq!(ratio(MAX_PRIMS), fast);
    }

    /// A query that overflows the short stack continues on the long one and finds what brute
    /// force finds: a one-entry short stack overflows on nearly every query.
    #[test]
    fn overflow_to_the_long_stack_finds_the_same_hits() {
        let mut seed = 7u32;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32 * 2.0 - 1.0
        };
        let mut prims = Vec::new();
        for id in 0..3000u32 {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 2.0;
            let v = [0, 1, 2].map(|_| c + Vec3::new(rnd(), rnd(), rnd()) * 0.3);
            prims.push(Prim {
                shape: Shape::Triangle(v),
                id,
            });
        }
        let bvh = Bvh::build(prims.clone());
        assert!(stack_need(&bvh.nodes) > 1);
        let m = Methods::default();
        let mut hits = 0;
        for _ in 0..2000 {
            let o = Vec3::new(rnd(), rnd(), rnd()) * 4.0;
            let ray = Ray::new(o, (Vec3::new(rnd(), rnd(), rnd()) - o).normalize());
            let mut brute = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            for p in &prims {
                brute.visit(p);
            }
            let mut tiny = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            bvh.walk_from::<_, 1>(&TravRay::new(&ray, 0.0), &mut tiny, &[], 0);
            let mut short = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            bvh.walk(&ray, 0.0, &mut short);
            assert_eq!(tiny.hit(), brute.hit());
            assert_eq!(short.hit(), brute.hit());
            hits += usize::from(brute.hit().is_some());
        }
        assert!(hits > 1000, "{hits}");
    }
}
