//! BVH (the lecture's "Bounding Volume Hierarchy"): an 8-wide BVH with `f32` child boxes over
//! spheres and triangles in one tree, built from a binary BVH made with `obvhs`. This module owns
//! the tree's data (nodes, leaf words, triangle packets) and its API; [`build`] makes the tree and
//! [`traverse`] walks it.
//!
//! Why not `obvhs`' compressed wide BVH (CWBVH, Ylitie et al. 2017), which this module used
//! first: its child boxes are quantised to 8 bits, so every node visit decodes 48 bytes to
//! floats before the slab test (a third of the render's instructions went there), its stock
//! traversal has the pitfalls listed in [`traverse`], and its build converts with an `O(n·k²)`
//! cost table. Eight `f32` boxes are one AVX2 slab test of six loads, six subtractions and six
//! multiplications (two SSE tests without AVX2); the node is 256 bytes (four cache lines)
//! against CWBVH's 80.
//!
//! Why eight children and not four: a ray's walk is a chain of dependent loads, one per level,
//! and the 8-wide tree has about half the levels. Against a 4-wide tree, on the 1.28M-triangle
//! bench scene the camera- and shadow-ray frame takes 0.033 s instead of 0.038 s and the whole
//! Whitted frame 0.068 s instead of 0.072 s; on the glass scene and the kitchen model, where
//! single reflected and refracted rays dominate, 4 % and 6 % less; at 80k triangles the same
//! (the method and the figures: docs/performance.md).
//!
//! Why some nodes are narrow: the collapse fills a node with the two
//! children of its binary node and opens the largest inner child until there are eight, so
//! near the leaves, where a small subtree's children are leaves, most nodes hold two to four
//! children (on the 1.28M-triangle bench mesh 71 % of nodes, 42 % with just two). Such a node
//! is stored narrow: four slots, two cache lines, one four-lane slab test (VEX-encoded SSE in
//! the AVX2 walks). The trees' nodes take 35 % less memory (the accelerator 98.6 → 86.7 MB at
//! 1.28M triangles), and the camera- and shadow-ray frame at 80k triangles is 4 % faster
//! (1.28M: within the spread); the images are the same bit for bit.
mod build;
mod traverse;

use glam::Vec3;

use super::{Prim, VisitedBox};
use crate::geometry::Triangles4;

/// Padding of child boxes in every axis, relative to the largest coordinate magnitude of the
/// box: a primitive's computed hit point is off by a few ulp of its largest coordinate in
/// *every* axis, even along an axis where the box is flat (a plane at z = 0).
pub const NODE_PAD_REL: f32 = 8.0 * f32::EPSILON;

/// Children per node: the width of the tree.
pub const WIDTH: usize = 8;

/// Traversal stack capacity in entries. The build checks the worst case of the tree (on any
/// root-to-leaf path, the sum of each node's children but one, plus `WIDTH − 1` for the
/// fixed-length push) against it; the median-split tree of up to 2²⁸ primitives needs at most
/// 7 per level for about 10 levels.
pub const STACK_SIZE: usize = 96;

/// Most triangles in one leaf: one four-lane test. A leaf holds triangles or one sphere.
pub const MAX_LEAF: usize = 4;

/// A child word with this bit is a leaf, otherwise a node index. A triangle leaf is
/// `LEAF | packet << 2 | (count − 1)`, a sphere leaf `LEAF | SPHERE | index`.
const LEAF: u32 = 0x8000_0000;
const SPHERE: u32 = 0x4000_0000;

/// Most primitives the leaf words can address (2²⁸ packets of up to four triangles).
pub const MAX_PRIMS: usize = 1 << 28;

/// Which node test the traversals use: with AVX2 where the CPU has it (the default, `Auto`), a
/// ray against a node's eight boxes at once; with SSE, four boxes against one ray (single
/// walks) or one box against four rays (packets). All give the same answers bit for bit; the
/// environment variable `RAYTREE_SIMD=sse` (or `avx2`, `auto`) sets it at start, and
/// [`set_packet_simd`] at run time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PacketSimd {
    Auto,
    Sse,
    Avx2,
}

/// 0: not yet read from the environment; else `PacketSimd as u8 + 1`.
static PACKET_SIMD: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(0);

/// Sets the packet traversal's node test for the whole process. `Avx2` on a CPU without it
/// falls back to SSE.
pub fn set_packet_simd(simd: PacketSimd) {
    PACKET_SIMD.store(simd as u8 + 1, std::sync::atomic::Ordering::Relaxed);
}

/// The node test asked for: [`set_packet_simd`], else `RAYTREE_SIMD`, else `Auto`.
pub fn packet_simd() -> PacketSimd {
    let from = |v: u8| match v {
        2 => PacketSimd::Sse,
        3 => PacketSimd::Avx2,
        _ => PacketSimd::Auto,
    };
    match PACKET_SIMD.load(std::sync::atomic::Ordering::Relaxed) {
        0 => {
            let asked = match std::env::var("RAYTREE_SIMD").as_deref() {
                Ok("sse") => PacketSimd::Sse,
                Ok("avx2") => PacketSimd::Avx2,
                _ => PacketSimd::Auto,
            };
            set_packet_simd(asked);
            asked
        }
        v => from(v),
    }
}

/// Whether the traversals use the AVX2 node test: AVX2 (and the rest of x86-64-v3) present
/// and not turned off.
pub fn packet_uses_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        avx2().is_some()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The AVX2 token when the traversals (and the packet tiles' shading, see
/// `render::accumulate_tile`) are to use AVX2: present and not turned off.
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn avx2() -> Option<pulp::x86::V3> {
    match packet_simd() {
        PacketSimd::Sse => None,
        PacketSimd::Auto | PacketSimd::Avx2 => pulp::x86::V3::try_new(),
    }
}

/// Up to four triangles of a leaf, one per lane, and their primitive ids.
#[derive(Clone, Copy, Debug)]
struct Packet {
    tris: Triangles4,
    ids: [u32; 4],
}

/// One node of the tree, with `W` child slots: a full node ([`WIDTH`], four cache lines) or a
/// narrow one ([`NARROW_WIDTH`], two), so that the many nodes near the leaves that hold two to
/// four children cost half the memory and half the lines per visit.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node<const W: usize = WIDTH> {
    /// Child boxes by plane, one lane per child: min x, max x, min y, max y, min z, max z.
    /// Padded by [`NODE_PAD_REL`]; empty slots hold zeros and are masked by `valid`.
    planes: [[f32; W]; 6],
    /// Child words (see [`LEAF`] and [`NARROW`]).
    child: [u32; W],
    /// Bit `i` set when slot `i` holds a child.
    valid: u32,
}

/// Children of a narrow node.
pub const NARROW_WIDTH: usize = 4;

/// An inner node's child word with this bit (and not [`LEAF`]) is the index of a narrow node
/// (in [`Bvh::narrow`]), otherwise of a full one (in [`Bvh::nodes`]; the root is full node 0).
const NARROW: u32 = 0x4000_0000;

impl<const W: usize> Node<W> {
    fn empty() -> Self {
        Node {
            planes: [[0.0; W]; 6],
            child: [0; W],
            valid: 0,
        }
    }

    /// The padded box of child slot `slot`, at `level`.
    fn slot_box(&self, slot: usize, level: u32) -> VisitedBox {
        let p = &self.planes;
        VisitedBox {
            lo: Vec3::new(p[0][slot], p[2][slot], p[4][slot]),
            hi: Vec3::new(p[1][slot], p[3][slot], p[5][slot]),
            level,
        }
    }

    /// The child words and boxes (at `level`) of the filled slots, in slot order.
    fn children(&self, level: u32) -> [Option<(u32, VisitedBox)>; WIDTH] {
        std::array::from_fn(|slot| {
            (slot < W && self.valid & (1 << slot) != 0)
                .then(|| (self.child[slot], self.slot_box(slot, level)))
        })
    }
}

pub(in crate::accel) struct Bvh {
    /// Full nodes; the root is the first.
    nodes: Vec<Node>,
    /// Narrow nodes.
    narrow: Vec<Node<NARROW_WIDTH>>,
    /// Triangle leaves, in tree order.
    packets: Vec<Packet>,
    /// Sphere leaves.
    spheres: Vec<Prim>,
    depth: usize,
}

impl Bvh {
    pub(in crate::accel) fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Node>()
            + self.narrow.capacity() * size_of::<Node<NARROW_WIDTH>>()
            + self.packets.capacity() * size_of::<Packet>()
            + self.spheres.capacity() * size_of::<Prim>()
    }

    pub(in crate::accel) fn depth(&self) -> usize {
        self.depth
    }

    /// The child words and boxes (at `level`) of inner node `word`, in slot order.
    fn children(&self, word: u32, level: u32) -> impl Iterator<Item = (u32, VisitedBox)> + Clone {
        debug_assert!(word & LEAF == 0);
        let slots = if word & NARROW != 0 {
            self.narrow[(word & !NARROW) as usize].children(level)
        } else {
            self.nodes[word as usize].children(level)
        };
        slots.into_iter().flatten()
    }
}

impl Bvh {
    /// The box of the root: the union of its children's (padded) boxes.
    fn root_box(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for (_, b) in self.children(0, 0) {
            lo = lo.min(b.lo);
            hi = hi.max(b.hi);
        }
        (lo, hi)
    }

    /// Calls `f(box, parent, leaf)` for every box of the tree, parents before children: the
    /// root (the union of its children), then each child slot's box (inner node or leaf), a
    /// node's children together. `parent` is the index (in call order) of the enclosing box,
    /// `None` for the root; `leaf` is the child word of a leaf (see [`LEAF`]), `None` for the
    /// root and inner nodes.
    pub(in crate::accel) fn for_each_box(
        &self,
        mut f: impl FnMut(VisitedBox, Option<usize>, Option<u32>),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let (lo, hi) = self.root_box();
        f(VisitedBox { lo, hi, level: 0 }, None, None);
        let mut count = 1;
        // (node, its index in report order, its level)
        let mut todo = vec![(0u32, 0usize, 0u32)];
        while let Some((node, index, level)) = todo.pop() {
            for (word, b) in self.children(node, level + 1) {
                let leaf = (word & LEAF != 0).then_some(word);
                f(b, Some(index), leaf);
                if word & LEAF == 0 {
                    todo.push((word, count, level + 1));
                }
                count += 1;
            }
        }
    }

    /// The primitive ids of a leaf word, in lane order.
    pub(in crate::accel) fn leaf_prims(&self, word: u32) -> Vec<u32> {
        if word & SPHERE != 0 {
            vec![self.spheres[(word & !(LEAF | SPHERE)) as usize].id]
        } else {
            let packet = &self.packets[((word & !LEAF) >> 2) as usize];
            packet.ids[..(word & 3) as usize + 1].to_vec()
        }
    }

    /// The boxes and levels of the child words a traversal entered, in the order given (the
    /// order of a traversal, so every word's parent comes before it). The root (word 0, which
    /// every traversal starts at) is kept when the ray's `(t_min, t_max)` meets its box or
    /// anything below it was entered, so a ray that misses the tree entered nothing.
    pub(in crate::accel) fn entered_boxes(
        &self,
        words: &[u32],
        ray: &crate::geometry::Ray,
        t_min: f32,
        t_max: f32,
    ) -> Vec<VisitedBox> {
        if self.nodes.is_empty() {
            return Vec::new();
        }
        let root = self.root_box();
        let (lo, hi) = root;
        let mut known = std::collections::HashMap::from([(0u32, VisitedBox { lo, hi, level: 0 })]);
        let mut out = Vec::with_capacity(words.len());
        for &word in words {
            // A word not yet known would have been entered without its parent, which the
            // traversal cannot do; skipping it keeps this total.
            let Some(&entered) = known.get(&word) else {
                continue;
            };
            out.push(entered);
            if word & LEAF == 0 {
                known.extend(self.children(word, entered.level + 1));
            }
        }
        if out.len() == 1 && words.first() == Some(&0) {
            let (t0, t1) = super::slab(ray.origin, super::safe_inv(ray.dir), root.0, root.1);
            let meets = t0.max(t_min) <= t1.min(t_max);
            if !meets {
                out.clear();
            }
        }
        out
    }
}
