//! Construction of the 8-wide [`Bvh`]: a binary BVH from `obvhs`, collapsed to [`WIDTH`]
//! children per node, and the build presets.
//!
//! Build: `obvhs`' PLOC with the parameters of [`build_params`] (its `medium_build` preset,
//! `fast_build` from [`FAST_BUILD_MIN_PRIMS`] primitives on), then its
//! reinsertion optimiser (Meister et al. 2021, Meister & Bittner 2018), then our own collapse
//! to eight children per node: a surface-area cost decides, bottom up, which subtrees of at
//! most [`MAX_LEAF`] primitives become leaves, and each node of the wide tree takes the two
//! children of its binary node and keeps opening the largest inner child until it has eight
//! (the way Embree and Wald et al. 2008 collapse). The primitives are then copied in leaf
//! order, each keeping its original id, so a leaf reads a contiguous run.
//!
//! Pathological input (docs/stability.md, row B2). PLOC pairs neighbours whose union is cheapest
//! and breaks equal costs one way, so regular input (many identical boxes, boxes in a row, nested
//! boxes with one centre) merges only one pair per pass: the tree becomes a chain and the build is
//! quadratic (16k identical triangles: 9 s). We therefore
//! - grow every box by a pseudo-random `< 2⁻¹²` of its size ([`jitter`]; still conservative)
//!   so equal costs become distinct;
//! - build a balanced median-split tree ourselves ([`median_bvh2`]) when more than
//!   [`MAX_STACKED`] primitives share one box centre, or when PLOC's tree is deeper than
//!   [`MAX_BVH2_DEPTH`], or when its wide tree could need more than [`STACK_SIZE`] traversal
//!   stack entries.
use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, node::Bvh2Node, reinsertion::ReinsertionOptimizer},
    ploc::{PlocBuilder, PlocSearchDistance},
};
use rayon::prelude::*;

use super::{
    Bvh, LEAF, MAX_LEAF, MAX_PRIMS, NARROW, NARROW_WIDTH, NODE_PAD_REL, Node, Packet, SPHERE,
    STACK_SIZE, WIDTH,
};
use crate::accel::{Prim, Prims, Shape};
use crate::geometry::Triangles4;

/// More primitives than this with exactly the same box centre (duplicates, concentric spheres)
/// make PLOC chain; the median-split builder is used instead.
pub const MAX_STACKED: usize = 64;

/// A binary tree deeper than this is replaced by the median-split one. Real scenes stay far
/// below (PLOC gives about `1.5·log2(N)`: 24 for 1e5 random boxes).
pub const MAX_BVH2_DEPTH: usize = 96;

/// From this many primitives on the build uses obvhs's `fast_build` preset instead of
/// `medium_build`.
///
/// Measured on the peer bench's Whitted scene (`cargo bench --bench peer`'s torus, 4 samples a
/// pixel, 2 threads, median of 5 interleaved runs; minimum render time in brackets):
///
/// | triangles | medium: build / render | fast: build / render | very fast: build / render |
/// |---:|---|---|---|
/// | 320k | 0.174 / 0.318 (0.298) s | 0.154 / 0.314 (0.299) s | 0.140 / 0.320 (0.312) s |
/// | 1M | 0.604 / 0.382 (0.335) s | 0.524 / 0.347 (0.336) s | 0.421 / 0.345 (0.336) s |
/// | 2M | 1.058 / 0.343 (0.315) s | 0.917 / 0.317 (0.311) s | 0.844 / 0.332 (0.322) s |
///
/// The renders are within noise of each other (our own surface-area collapse to the wide
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

/// Costs of a visit relative to each other, for the surface-area leaf decision: a node (one
/// box test of the binary tree's), a leaf of up to four triangles (one four-lane test), a sphere.
const NODE_COST: f32 = 1.0;
const PACKET_COST: f32 = 1.5;
const SPHERE_COST: f32 = 1.0;

impl Bvh {
    /// The tree over a list of primitives (the unit tests' way).
    #[cfg(test)]
    pub(in crate::accel) fn build(prims: Vec<Prim>) -> Bvh {
        Self::build_from(&prims[..])
    }

    /// The tree over `prims`. Memory: while `obvhs` builds, only its own lists and the binary
    /// tree exist (the leaves' boxes are its node list, filled here; no list of boxes or of
    /// primitives beside it); the primitives are read again for the leaves.
    pub(in crate::accel) fn build_from<P: Prims + ?Sized>(prims: &P) -> Bvh {
        Self::build_split(prims, SPLIT_BUILD_MIN_PRIMS, SPLIT_PART_MAX_PRIMS)
    }

    /// [`Bvh::build_from`] with the split build from `split_min` primitives on (at least 4),
    /// in parts of at most `part_max` primitives (the tests lower both).
    fn build_split<P: Prims + ?Sized>(prims: &P, split_min: usize, part_max: usize) -> Bvh {
        let n = prims.count();
        // Loaded scenes stay far below (the file-size caps and the memory budget bound them);
        // beyond this, ids would not fit a leaf word.
        assert!(n <= MAX_PRIMS, "more than 2^28 primitives");
        let bounds = |i: usize| {
            let (lo, hi) = prims.get(i).bounds();
            Aabb::new(lo.into(), hi.into())
        };
        let params = build_params(n);
        let mut built = None;
        if max_stacked(n, &bounds) <= MAX_STACKED {
            let flat = if n >= split_min.max(4) {
                split_ploc(n, &bounds, &params, part_max)
            } else {
                let leaves: Vec<Bvh2Node> = (0..n)
                    .into_par_iter()
                    .map(|i| Bvh2Node::new(jitter(&bounds(i), i), 1, i as u32))
                    .collect();
                let mut bvh2 = ploc(leaves, &params);
                ReinsertionOptimizer::default().run(
                    &mut bvh2,
                    params.reinsertion_batch_ratio,
                    None,
                );
                preorder(&bvh2)
            };
            built = flat
                .and_then(|flat| collapse_flat(flat, prims))
                .filter(|b| stack_need(b) + WIDTH - 1 <= STACK_SIZE);
        }
        built.unwrap_or_else(|| {
            let boxes: Vec<Aabb> = (0..n).into_par_iter().map(bounds).collect();
            let b = collapse(median_bvh2(&boxes), prims).unwrap_or_else(|| Bvh {
                nodes: Vec::new(),
                narrow: Vec::new(),
                packets: Vec::new(),
                spheres: Vec::new(),
                depth: 0,
            });
            // A balanced binary tree of 2²⁸ leaves has depth 29; its 8-wide collapse needs
            // fewer than 7·10 + 7 stack entries.
            debug_assert!(stack_need(&b) + WIDTH - 1 <= STACK_SIZE);
            b
        })
    }
}

/// From this many primitives on, the binary tree is built as several PLOC trees of at most
/// [`SPLIT_PART_MAX_PRIMS`] primitives each, one after the other, under a few levels of median
/// splits: obvhs' PLOC needs about 210 bytes per primitive while it builds (its node lists of
/// 48-byte nodes: the leaves, their sorted copy and the tree of `2N − 1`), so parts built one
/// at a time cut that peak to a part's. Below this size the peak is small and one tree keeps
/// the whole build to PLOC.
pub const SPLIT_BUILD_MIN_PRIMS: usize = 500_000;

/// The most primitives of one PLOC tree in the split build ([`SPLIT_BUILD_MIN_PRIMS`]): parts
/// are halved until they fit, so 1M triangles are built as four trees of 250k: built as two
/// halves of 500k, they peaked at 2.01 times the memory the tracer keeps afterwards (whose
/// tree, with narrow nodes, is small).
pub const SPLIT_PART_MAX_PRIMS: usize = 1 << 18;

/// The pre-order binary tree of [`SPLIT_BUILD_MIN_PRIMS`]: while a part holds more than
/// `part_max` primitives, a node splitting it at the median of its box centres along the
/// widest axis of those centres (ties by index) into a lower and an upper half, and each part
/// that fits, the PLOC tree (optimised by reinsertion) of its primitives.
fn split_ploc(
    n: usize,
    bounds: &(impl Fn(usize) -> Aabb + Sync),
    params: &BvhBuildParams,
    part_max: usize,
) -> Option<Vec<FlatNode>> {
    let mut ids: Vec<u32> = (0..n as u32).collect();
    let mut flat: Vec<FlatNode> = Vec::with_capacity(2 * n - 1);
    split_into(&mut ids, bounds, params, part_max.max(1), &mut flat, 1)?;
    Some(flat)
}

/// Appends the split tree of the primitives `ids` (see [`split_ploc`]) in pre-order to `flat`,
/// its root at depth `depth`; returns its box. `None` when deeper than [`MAX_BVH2_DEPTH`].
fn split_into(
    ids: &mut [u32],
    bounds: &(impl Fn(usize) -> Aabb + Sync),
    params: &BvhBuildParams,
    part_max: usize,
    flat: &mut Vec<FlatNode>,
    depth: usize,
) -> Option<Aabb> {
    if ids.len() <= part_max {
        // In index order: neighbours in the input are often neighbours in space.
        ids.par_sort_unstable();
        let leaves: Vec<Bvh2Node> = ids
            .par_iter()
            .enumerate()
            .map(|(local, &i)| {
                Bvh2Node::new(jitter(&bounds(i as usize), i as usize), 1, local as u32)
            })
            .collect();
        let mut bvh2 = ploc(leaves, params);
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        preorder_into(&bvh2, ids, flat, depth)?;
        return Some(bvh2.nodes[0].aabb);
    }
    if depth > MAX_BVH2_DEPTH {
        return None;
    }
    let centers = ids
        .par_iter()
        .map(|&i| {
            let c = bounds(i as usize).center();
            Aabb::new(c, c)
        })
        .reduce(Aabb::empty, |a, b| a.union(&b));
    let axis = centers.largest_axis();
    let mut keyed: Vec<(f32, u32)> = ids
        .par_iter()
        .map(|&i| (bounds(i as usize).center()[axis], i))
        .collect();
    let half = ids.len() / 2;
    keyed.select_nth_unstable_by(half, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (id, (_, i)) in ids.iter_mut().zip(keyed) {
        *id = i;
    }
    let here = flat.len();
    flat.push(FlatNode {
        min: [0.0; 3],
        max: [0.0; 3],
        link: 0,
    });
    let (low, high) = ids.split_at_mut(half);
    let a = split_into(low, bounds, params, part_max, flat, depth + 1)?;
    flat[here].link = flat.len() as u32;
    let b = split_into(high, bounds, params, part_max, flat, depth + 1)?;
    let both = a.union(&b);
    flat[here].min = both.min.to_array();
    flat[here].max = both.max.to_array();
    Some(both)
}

/// obvhs' PLOC over `leaves` (one primitive each, primitive `i` at `i`), as
/// `PlocBuilder::build` makes it from the leaves' boxes: the same tree, without the list of
/// boxes beside the builder's own node lists.
fn ploc(leaves: Vec<Bvh2Node>, params: &BvhBuildParams) -> Bvh2 {
    let n = leaves.len();
    let total = leaves
        .par_iter()
        .map(|l| l.aabb)
        .reduce(Aabb::empty, |a, b| a.union(&b));
    let mut bvh = Bvh2::zeroed(n);
    bvh.reset_for_reuse(n, Some((0..n as u32).collect()));
    if n == 0 {
        return bvh;
    }
    let mut builder = PlocBuilder::new();
    builder.current_nodes = leaves;
    let (precision, threshold) = (params.sort_precision, params.search_depth_threshold);
    let b = &mut builder;
    match params.ploc_search_distance {
        PlocSearchDistance::Minimum => {
            b.build_ploc_from_leaves::<1, false>(&mut bvh, total, precision, threshold)
        }
        PlocSearchDistance::VeryLow => {
            b.build_ploc_from_leaves::<2, false>(&mut bvh, total, precision, threshold)
        }
        PlocSearchDistance::Low => {
            b.build_ploc_from_leaves::<6, false>(&mut bvh, total, precision, threshold)
        }
        PlocSearchDistance::Medium => {
            b.build_ploc_from_leaves::<14, false>(&mut bvh, total, precision, threshold)
        }
        PlocSearchDistance::High => {
            b.build_ploc_from_leaves::<24, false>(&mut bvh, total, precision, threshold)
        }
        PlocSearchDistance::VeryHigh => {
            b.build_ploc_from_leaves::<32, false>(&mut bvh, total, precision, threshold)
        }
    }
    bvh
}

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
    let ids: Vec<u32> = Vec::new();
    preorder_into(bvh2, &ids, &mut flat, 1)?;
    Some(flat)
}

/// Appends `bvh2` (not empty) in pre-order to `flat`, its root at depth `depth`; a leaf's
/// primitive `p` becomes `ids[p]` (`p` itself when `ids` is empty). `None` when deeper than
/// [`MAX_BVH2_DEPTH`].
fn preorder_into(bvh2: &Bvh2, ids: &[u32], flat: &mut Vec<FlatNode>, depth: usize) -> Option<()> {
    // (binary node, pre-order index of the parent whose right child it is, depth)
    let mut todo = vec![(0u32, u32::MAX, depth)];
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
            let p = bvh2.primitive_indices[node.first_index as usize];
            let p = if ids.is_empty() { p } else { ids[p as usize] };
            flat.push(FlatNode {
                min,
                max,
                link: FLAT_LEAF | p,
            });
        }
    }
    Some(())
}

/// The wide tree of a binary BVH whose leaves hold one primitive each (PLOC's and
/// [`median_bvh2`]'s do); `None` for an empty tree or one deeper than [`MAX_BVH2_DEPTH`].
fn collapse<P: Prims + ?Sized>(bvh2: Bvh2, prims: &P) -> Option<Bvh> {
    let flat = preorder(&bvh2)?;
    // The copy is all that is needed from here on.
    drop(bvh2);
    collapse_flat(flat, prims)
}

/// The wide tree of a binary tree in pre-order ([`preorder`]).
fn collapse_flat<P: Prims + ?Sized>(flat: Vec<FlatNode>, prims: &P) -> Option<Bvh> {
    let n = flat.len();
    let right = |i: usize| flat[i].link as usize;
    // Bottom up (reverse pre-order): primitives under each node and the surface-area cost of
    // its best subtree; `leaf[i]` when the node's subtree is cheaper as one leaf.
    // `Accel` lists the spheres first: an index tells the kind without reading the primitive
    // (reading them in tree order misses the cache on every one).
    let sphere_count = prims.spheres();
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

    // The children of binary node `b` in the wide tree: its two children, then, while there
    // are fewer than `WIDTH`, the largest inner child opened into its two. As (binary node,
    // how many times opened); a tie in area opens the shallower child, so equal boxes (a
    // median-split tree of duplicates) collapse evenly.
    let open = |b: usize| -> ([(usize, u32); WIDTH], usize) {
        let mut slots = [(0usize, 0u32); WIDTH];
        let mut len = if leaf[b] {
            slots[0] = (b, 0);
            1
        } else {
            slots[0] = (b + 1, 0);
            slots[1] = (right(b), 0);
            2
        };
        while len < WIDTH {
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
        (slots, len)
    };

    let mut nodes: Vec<Node> = vec![Node::empty()];
    let mut narrow: Vec<Node<NARROW_WIDTH>> = Vec::new();
    let mut sphere_leaves: Vec<Prim> = Vec::new();
    // Each triangle leaf's primitive indices, four per leaf (the first repeated); gathered into
    // packets afterwards in one tight loop, whose independent loads overlap their cache misses.
    let mut leaf_prims: Vec<[u32; 4]> = Vec::new();
    let mut depth = 0;
    // (binary node, word of the wide node to fill, its depth); the root (always a full node)
    // has the root's children as its slots, or the root itself when it is a leaf.
    let mut todo = vec![(0usize, 0u32, 1usize)];
    while let Some((b, w, d)) = todo.pop() {
        depth = depth.max(d);
        let (slots, len) = open(b);
        // The slot's child word: a leaf's, or a new node's (full or narrow by its children).
        let mut word = |s: usize| -> u32 {
            if leaf[s] && spheres[s] == 1 {
                sphere_leaves.push(prims.get(flat[s].prim() as usize));
                LEAF | SPHERE | (sphere_leaves.len() - 1) as u32
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
                leaf_prims.push(ids);
                LEAF | ((leaf_prims.len() as u32 - 1) << 2) | (c as u32 - 1)
            } else {
                let child = if open(s).1 <= NARROW_WIDTH {
                    narrow.push(Node::empty());
                    NARROW | (narrow.len() - 1) as u32
                } else {
                    nodes.push(Node::empty());
                    (nodes.len() - 1) as u32
                };
                todo.push((s, child, d + 1));
                child
            }
        };
        if w & NARROW != 0 {
            let mut node = Node::<NARROW_WIDTH>::empty();
            for (slot, &(s, _)) in slots[..len].iter().enumerate() {
                node.set(slot, &flat[s].aabb(), word(s));
            }
            narrow[(w & !NARROW) as usize] = node;
        } else {
            let mut node = Node::<WIDTH>::empty();
            for (slot, &(s, _)) in slots[..len].iter().enumerate() {
                node.set(slot, &flat[s].aabb(), word(s));
            }
            nodes[w as usize] = node;
        }
    }
    drop(flat);
    nodes.shrink_to_fit();
    narrow.shrink_to_fit();
    let triangle = |i: u32| match prims.get(i as usize) {
        Prim {
            shape: Shape::Triangle(v),
            id,
        } => (v, id),
        // Leaves hold no spheres (`spheres[s] == 0`).
        Prim {
            shape: Shape::Sphere { .. },
            ..
        } => unreachable!("a sphere in a triangle leaf"),
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
        narrow,
        packets,
        spheres: sphere_leaves,
        depth,
    })
}

impl<const W: usize> Node<W> {
    /// Fills slot `slot` with child word `word` and its box `aabb`, padded.
    fn set(&mut self, slot: usize, aabb: &Aabb, word: u32) {
        let (lo, hi) = padded(aabb);
        for (axis, (l, h)) in [(lo.x, hi.x), (lo.y, hi.y), (lo.z, hi.z)]
            .into_iter()
            .enumerate()
        {
            self.planes[2 * axis][slot] = l;
            self.planes[2 * axis + 1][slot] = h;
        }
        self.valid |= 1 << slot;
        self.child[slot] = word;
    }
}

/// The most stack entries a traversal of `nodes` can need: on the worst root-to-leaf path,
/// each node pushes all its children but one.
pub(super) fn stack_need(bvh: &Bvh) -> usize {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut worst = 0;
    let mut todo = vec![(0u32, 0usize)];
    while let Some((word, above)) = todo.pop() {
        let children = bvh.children(word, 0);
        let here = above + children.clone().count().saturating_sub(1);
        worst = worst.max(here);
        for (child, _) in children {
            if child & LEAF == 0 {
                todo.push((child, here));
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

/// The largest number of the `n` boxes `bounds(i)` sharing exactly the same centre.
fn max_stacked(n: usize, bounds: &(impl Fn(usize) -> Aabb + Sync)) -> usize {
    let mut keys: Vec<[u32; 3]> = (0..n)
        .into_par_iter()
        .map(|i| {
            let c = bounds(i).center();
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
    use crate::accel::{Closest, Visitor};
    use crate::geometry::{Methods, Ray};

    /// The surface-area cost of a wide tree, relative to its root's box: every child box's
    /// area times the cost of visiting it (node, triangle leaf, sphere).
    fn sah_cost(bvh: &Bvh) -> f64 {
        let area = |lo: Vec3, hi: Vec3| {
            let d = (hi - lo).max(Vec3::ZERO);
            f64::from((d.x + d.y) * d.z + d.x * d.y)
        };
        let cost = |child: u32| {
            if child & LEAF == 0 {
                NODE_COST
            } else if child & SPHERE != 0 {
                SPHERE_COST
            } else {
                PACKET_COST
            }
        };
        let (lo, hi) = bvh.root_box();
        let words =
            (0..bvh.nodes.len() as u32).chain((0..bvh.narrow.len() as u32).map(|i| i | NARROW));
        let mut total = 0.0;
        for word in words {
            for (child, b) in bvh.children(word, 0) {
                total += f64::from(cost(child)) * area(b.lo, b.hi);
            }
        }
        total / area(lo, hi)
    }

    /// A bumpy torus of about `n` triangles (a surface like the benchmark's), as primitives.
    fn torus(n: usize) -> Vec<Prim> {
        let (nu, nv) = (
            (n as f32 / 8.0).sqrt() as usize * 4,
            (n as f32 / 8.0).sqrt() as usize,
        );
        let p = |i: usize, j: usize| {
            let (u, v) = (
                std::f32::consts::TAU * (i % nu) as f32 / nu as f32,
                std::f32::consts::TAU * (j % nv) as f32 / nv as f32,
            );
            let r = 0.5 * (1.0 + 0.12 * (9.0 * u).sin() * (6.0 * v).sin());
            Vec3::new(
                (1.35 + r * v.cos()) * u.cos(),
                r * v.sin(),
                (1.35 + r * v.cos()) * u.sin(),
            )
        };
        let mut prims = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                for v in [
                    [p(i, j), p(i, j + 1), p(i + 1, j + 1)],
                    [p(i, j), p(i + 1, j + 1), p(i + 1, j)],
                ] {
                    prims.push(Prim {
                        shape: Shape::Triangle(v),
                        id: prims.len() as u32,
                    });
                }
            }
        }
        prims
    }

    /// The two-tree build (forced at a small size here) finds what brute force finds, and
    /// its tree costs about what one PLOC tree costs (surface-area cost within 3 %).
    /// `n` small triangles in clusters scattered in a box (uneven, unlike the torus).
    fn clusters(n: usize) -> Vec<Prim> {
        let mut rnd = crate::rng::uniform(99);
        let mut prims = Vec::new();
        while prims.len() < n {
            let c = Vec3::new(rnd() * 8.0 - 4.0, rnd() * 2.0, rnd() * 3.0);
            for _ in 0..1 + (rnd() * 200.0) as usize {
                let a = c + Vec3::new(rnd(), rnd(), rnd()) * 0.5;
                let v = [
                    a,
                    a + Vec3::new(rnd(), rnd(), 0.0) * 0.05,
                    a + Vec3::Z * 0.03,
                ];
                prims.push(Prim {
                    shape: Shape::Triangle(v),
                    id: prims.len() as u32,
                });
            }
        }
        prims
    }

    /// Inner nodes of two to four children are narrow (two cache lines), the others full (four
    /// lines), the root always full; on a surface like the benchmark's most nodes are narrow,
    /// and every triangle is reached through exactly one leaf.
    #[test]
    fn nodes_of_at_most_four_children_are_narrow() {
        assert_eq!(size_of::<Node<NARROW_WIDTH>>(), 128);
        assert_eq!(size_of::<Node>(), 256);
        let prims = torus(20_000);
        let bvh = Bvh::build(prims.clone());
        for node in &bvh.nodes[1..] {
            assert!(node.valid.count_ones() as usize > NARROW_WIDTH);
        }
        for node in &bvh.narrow {
            assert!((2..=NARROW_WIDTH).contains(&(node.valid.count_ones() as usize)));
        }
        assert!(
            bvh.narrow.len() > bvh.nodes.len(),
            "{} narrow, {} full",
            bvh.narrow.len(),
            bvh.nodes.len()
        );
        let mut reached = vec![0u32; prims.len()];
        bvh.for_each_box(|_, _, leaf| {
            for id in leaf.map(|w| bvh.leaf_prims(w)).unwrap_or_default() {
                reached[id as usize] += 1;
            }
        });
        assert!(reached.iter().all(|&r| r == 1));
    }

    /// On uneven input the split build (two parts, and eight) costs a little more than one
    /// PLOC tree, but not much.
    #[test]
    fn the_split_build_costs_about_the_same_on_uneven_input() {
        let prims = clusters(40_000);
        let whole = Bvh::build_split(&prims[..], usize::MAX, usize::MAX);
        let a = sah_cost(&whole);
        for parts in [2, 8] {
            let split = Bvh::build_split(&prims[..], 0, prims.len().div_ceil(parts));
            let b = sah_cost(&split);
            eprintln!("clusters, surface-area cost: {parts} trees {b:.3}, one tree {a:.3}");
            assert!(b < a * 1.05, "{parts} parts: {b:.2} against whole {a:.2}");
        }
    }

    #[test]
    fn the_split_build_finds_the_same_hits_at_about_the_same_cost() {
        for parts in [2, 8] {
            split_build_finds_the_same_hits(parts);
        }
    }

    /// The split build of `parts` parts on a torus with two spheres: its tree costs about what
    /// one PLOC tree costs, and finds what brute force finds.
    fn split_build_finds_the_same_hits(parts: usize) {
        let mut prims = torus(40_000);
        // Spheres first, as `Accel` lists them.
        for (k, c) in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.35, 0.0, 0.0)]
            .into_iter()
            .enumerate()
        {
            prims.insert(
                k,
                Prim {
                    shape: Shape::Sphere {
                        center: c,
                        radius: 0.3,
                    },
                    id: 0,
                },
            );
        }
        for (id, p) in prims.iter_mut().enumerate() {
            p.id = id as u32;
        }
        let n = prims.len();
        let bounds = |i: usize| {
            let (lo, hi) = prims[i].bounds();
            Aabb::new(lo.into(), hi.into())
        };
        assert!(
            max_stacked(n, &bounds) <= MAX_STACKED,
            "PLOC, not the median split"
        );
        let params = build_params(n);
        let leaves: Vec<Bvh2Node> = (0..n)
            .map(|i| Bvh2Node::new(jitter(&bounds(i), i), 1, i as u32))
            .collect();
        let mut bvh2 = ploc(leaves, &params);
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        let whole = collapse_flat(preorder(&bvh2).expect("shallow"), &prims[..]).expect("a tree");
        let split = collapse_flat(
            split_ploc(n, &bounds, &params, n.div_ceil(parts)).expect("shallow"),
            &prims[..],
        )
        .expect("a tree");
        assert!(stack_need(&split) + WIDTH - 1 <= STACK_SIZE);
        // `build_split` takes this path too.
        let built = Bvh::build_split(&prims[..], 0, n.div_ceil(parts));
        assert_eq!(built.nodes.len(), split.nodes.len());
        assert_eq!(built.narrow.len(), split.narrow.len());
        let (a, b) = (sah_cost(&whole), sah_cost(&split));
        eprintln!("surface-area cost: {parts} trees {b:.3}, one tree {a:.3}");
        assert!(b < a * 1.03, "{parts} parts: {b:.2} against whole {a:.2}");
        assert!(split.spheres.len() == 2 && split.packets.len() > 40_000 / 4);
        let m = Methods::default();
        let mut rnd = crate::rng::signed(7);
        let mut hits = 0;
        for _ in 0..3000 {
            let o = Vec3::new(rnd(), rnd(), rnd()) * 3.0;
            let ray = Ray::new(o, (Vec3::new(rnd(), rnd(), rnd()) * 0.5 - o).normalize());
            let mut brute = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            for p in &prims {
                brute.visit(p);
            }
            let mut found = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            split.walk(&ray, 0.0, &mut found);
            assert_eq!(found.hit(), brute.hit());
            hits += usize::from(brute.hit().is_some());
        }
        assert!(hits > 1000, "{hits}");
    }

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
}
