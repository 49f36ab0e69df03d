//! BVH (the lecture's "Bounding Volume Hierarchy"): a 4-wide BVH with `f32` child boxes over
//! spheres and triangles in one tree, built from a binary BVH made with `obvhs`. This module owns
//! the tree's data (nodes, leaf words, triangle packets) and its API; [`build`] makes the tree and
//! [`traverse`] walks it.
//!
//! Why not `obvhs`' compressed wide BVH (CWBVH, Ylitie et al. 2017), which this module used
//! first: its child boxes are quantised to 8 bits, so every node visit decodes 48 bytes to
//! floats before the slab test (a third of the render's instructions went there), its stock
//! traversal has the pitfalls listed in [`traverse`], and its build converts with an `O(n·k²)`
//! cost table. Four `f32` boxes are one SSE slab test of six loads, six subtractions and six
//! multiplications; the node is 128 bytes (two cache lines) against CWBVH's 80, for
//! about a third as many nodes as leaves.
mod build;
mod traverse;

use glam::Vec4;

use super::Prim;
use crate::geometry::Triangles4;

/// Padding of child boxes in every axis, relative to the largest coordinate magnitude of the
/// box: a primitive's computed hit point is off by a few ulp of its largest coordinate in
/// *every* axis, even along an axis where the box is flat (a plane at z = 0).
pub const NODE_PAD_REL: f32 = 8.0 * f32::EPSILON;

/// Traversal stack capacity in entries. The build checks the worst case of the tree (on any
/// root-to-leaf path, the sum of each node's children but one, plus 3 for the fixed-length
/// push) against it; the median-split
/// tree of up to 2²⁸ primitives needs at most 3 per level for about 13 levels.
pub const STACK_SIZE: usize = 64;

/// Most triangles in one leaf: one four-lane test. A leaf holds triangles or one sphere.
pub const MAX_LEAF: usize = 4;

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

pub(in crate::accel) struct Bvh {
    nodes: Vec<Node>,
    /// Triangle leaves, in tree order.
    packets: Vec<Packet>,
    /// Sphere leaves.
    spheres: Vec<Prim>,
    depth: usize,
}

impl Bvh {
    pub(in crate::accel) fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Node>()
            + self.packets.capacity() * size_of::<Packet>()
            + self.spheres.capacity() * size_of::<Prim>()
    }

    pub(in crate::accel) fn depth(&self) -> usize {
        self.depth
    }
}
