//! Traversal of the 8-wide [`Bvh`]: the closest-hit and any-hit walks over one stack and the
//! SIMD test of a node's eight child boxes (one AVX2 test, or two SSE ones; a narrow node's
//! four boxes in one SSE test). With AVX2, a packet's rays that reach a leaf are tested
//! against its triangles two at a time ([`NodeTest::visit_pair`]).
//!
//! Traversal, and what it must guarantee (the accelerators agree bit for bit with brute force):
//! child boxes are padded by a few ulp of their magnitude in every axis
//! ([`NODE_PAD_REL`](super::NODE_PAD_REL)), slab `t` values use `1/d` clamped to `±2⁶⁰` (no NaN),
//! both ends of the interval are widened by `2γ(3)` of their magnitude (pbrt-v4 widens the far end;
//! the near end too so that a primitive whose computed `t` is an ulp before its box's computed
//! entry is not culled), and the interval is clipped to the caller's `(t_min, best t]`, inclusive
//! so an equal `t` with a lower id is still found. Closest-hit queries visit the hit children
//! nearest first and keep each pushed child's entry `t`, so a child is skipped when it is popped
//! behind the best hit found since; occlusion queries push in any order and stop at the first hit.
//! The stack is a plain array that the build guarantees is deep enough.
//!
//! Pitfalls of `obvhs`' stock traversals that this avoids (found while this module used them):
//! `CwBvhNode::intersect_ray` clamps every box's entry `t` to an absolute `1e-4` and ignores
//! `ray.tmin` (misses at scene scales of `1e-3` and below); `Ray::new` replaces small direction
//! components by `±1/EPSILON` (not conservative); `ray_traverse` accepts only `t < tmax` (no
//! tie-break by id); `ray_traverse_anyhit` never stops early; the fixed traversal stack
//! (`StackStack<_, 32>`) silently overwrites its top entry when full.
use glam::{Vec3, Vec3A, Vec4};

use super::{Bvh, LEAF, NARROW, NARROW_WIDTH, Node, SPHERE, STACK_SIZE, WIDTH};
#[cfg(target_arch = "x86_64")]
use crate::accel::pair_triangles4;
use crate::accel::{Visitor, box_t_scales, prefetch};
use crate::geometry::{Ray, Triangles4};

/// Entries of the stack a query starts with; deeper queries continue on a [`STACK_SIZE`] one.
const SHORT_STACK: usize = 32;

/// Entries of the stack a packet walk starts with (each entry carries a ray mask and a `t`);
/// deeper walks continue on a [`STACK_SIZE`] one.
const SHORT_PACKET_STACK: usize = 24;

impl Bvh {
    /// Visits every primitive whose padded box the ray's `(t_min, v.limit()]` interval meets;
    /// nearest child first when [`Visitor::ORDERED`].
    #[inline]
    pub(in crate::accel) fn walk<V: Visitor>(&self, ray: &Ray, t_min: f32, v: &mut V) {
        // The node tests' widening needs it (`box_t_scales`).
        debug_assert!(t_min >= 0.0, "BVH walk from t_min {t_min} < 0");
        if self.nodes.is_empty() {
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(v3) = super::avx2() {
            // The same walk compiled for x86-64-v3 (VEX-encoded SSE, no fused multiply-add is
            // formed): the same numbers, in fewer instructions.
            return v3.vectorize(Avx2Walk {
                bvh: self,
                ray,
                t_min,
                v,
                v3,
            });
        }
        let r = TravRay::new(ray, t_min);
        self.walk_from::<V, SHORT_STACK, _>(&r, v, &[], 0, Sse4);
    }

    /// The traversal loop from child word `word` with `seed` on a stack of `N` entries. A
    /// query starts on a short stack (clearing it is part of every query's cost) and, in the
    /// rare case it would overflow, continues on a [`STACK_SIZE`] one.
    #[inline(always)]
    fn walk_from<V: Visitor, const N: usize, T: NodeTest>(
        &self,
        r: &TravRay,
        v: &mut V,
        seed: &[(u32, f32)],
        mut word: u32,
        test: T,
    ) {
        let mut stack = [(0u32, 0f32); N];
        // Element by element: these copies are short, and `copy_from_slice` of a variable
        // length calls `memcpy`.
        for (to, from) in stack.iter_mut().zip(seed) {
            *to = *from;
        }
        let mut sp = seed.len();
        loop {
            v.enter(word);
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
                let (mut mask, t, child) = if word & NARROW != 0 {
                    let node = &self.narrow[(word & !NARROW) as usize];
                    let (mask, t) = Sse4.enter_one_of(r, node, v.limit());
                    (mask, t, node.child_words())
                } else {
                    let node = &self.nodes[word as usize];
                    let (mask, t) = test.enter_one(r, node, v.limit());
                    (mask, t, node.child)
                };
                if mask != 0 {
                    if mask & (mask - 1) == 0 {
                        word = child[mask.trailing_zeros() as usize];
                        continue;
                    }
                    // Up to `WIDTH` hits; all but the one taken next are pushed with their
                    // entry t (sorted farthest first when ordered, so the nearest is next).
                    let mut hits = [(0u32, 0f32); WIDTH];
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
                        hits[j] = (child[i], t[i]);
                        k += 1;
                    }
                    word = hits[k - 1].0;
                    // `WIDTH − 1` entries are always written (only `k − 1` are kept): a
                    // fixed-length copy, where a loop of 1 to 7 would mispredict.
                    if N < STACK_SIZE && sp + WIDTH - 1 > N {
                        let mut deeper = [(0u32, 0f32); STACK_SIZE];
                        deeper[..sp].copy_from_slice(&stack[..sp]);
                        deeper[sp..sp + k - 1].copy_from_slice(&hits[..k - 1]);
                        let seed = &deeper[..sp + k - 1];
                        return self.walk_from::<V, STACK_SIZE, T>(r, v, seed, word, test);
                    }
                    // The pushed children's lines load while the nearest is walked.
                    for h in &hits[..k - 1] {
                        self.prefetch_child(h.0);
                    }
                    let top: &mut [(u32, f32); WIDTH - 1] = (&mut stack[sp..sp + WIDTH - 1])
                        .try_into()
                        .expect("checked above");
                    *top = hits[..WIDTH - 1].try_into().expect("WIDTH − 1 entries");
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

impl Bvh {
    /// The traversal of a packet of up to 32 coherent rays (camera rays of neighbouring
    /// pixels, shadow rays of neighbouring hits towards one light): one walk of the tree with
    /// one shared stack, each node fetched once for the packet and tested by every ray still
    /// in it (the same widened slab test as [`Bvh::walk`], against that ray's own
    /// `(t_min, limit]`). A stack entry carries the rays that entered the child (a mask) and
    /// the nearest of their entry `t`s, so a child is skipped when it is popped behind every
    /// one of its rays' best hits (closest hit) and a ray leaves the packet at its first hit
    /// (occlusion). Each ray visits every primitive its single walk would visit that can still
    /// matter, so with the id tie-break its answer is the single walk's, bit for bit.
    /// `active` selects the rays of `rays` (bit `i` for ray `i`).
    pub(in crate::accel) fn walk_packet<V: Visitor, const K: usize>(
        &self,
        rays: &[Ray; K],
        t_min: f32,
        vs: &mut [V; K],
        active: u32,
    ) {
        const { assert!(K <= 32) };
        debug_assert!(t_min >= 0.0, "BVH packet walk from t_min {t_min} < 0");
        if self.nodes.is_empty() || active == 0 {
            return;
        }
        // The rays' lanes in arrays of the next multiple of 8 (the AVX2 test loads eight), so
        // that a small packet does not fill 32 lanes.
        if K <= 8 {
            self.walk_packet_lanes::<V, K, 8>(rays, t_min, vs, active);
        } else if K <= 16 {
            self.walk_packet_lanes::<V, K, 16>(rays, t_min, vs, active);
        } else {
            self.walk_packet_lanes::<V, K, 32>(rays, t_min, vs, active);
        }
    }

    /// [`Bvh::walk_packet`] with the rays' lanes in arrays of `L ≥ K`.
    #[inline(always)]
    fn walk_packet_lanes<V: Visitor, const K: usize, const L: usize>(
        &self,
        rays: &[Ray; K],
        t_min: f32,
        vs: &mut [V; K],
        active: u32,
    ) {
        #[cfg(target_arch = "x86_64")]
        if let Some(v3) = super::avx2() {
            // The whole walk compiled for AVX2 (the node test eight rays wide; the rest the
            // same SSE arithmetic, VEX-encoded: no fused multiply-add is formed, so every
            // number is the SSE path's).
            return v3.vectorize(Avx8Walk::<V, K, L> {
                bvh: self,
                rays,
                t_min,
                vs,
                active,
                v3,
            });
        }
        self.walk_packet_with::<V, K, L, _>(rays, t_min, vs, active, Sse4);
    }

    /// [`Bvh::walk_packet`] with the node test `T`.
    #[inline(always)]
    fn walk_packet_with<V: Visitor, const K: usize, const L: usize, T: NodeTest>(
        &self,
        rays: &[Ray; K],
        t_min: f32,
        vs: &mut [V; K],
        active: u32,
        test: T,
    ) {
        let mut rays4 = Rays4::<L>::new(rays, active, t_min);
        for (i, v) in vs.iter().enumerate() {
            rays4.set_limit(i, v.limit());
        }
        let root = (0, active);
        self.packet_from::<V, K, L, T, SHORT_PACKET_STACK>(&mut rays4, vs, active, &[], root, test);
    }

    /// The packet walk's loop from child word `next.0` with its rays `next.1`, with `seed` on
    /// a stack of `N` entries: a walk starts on a short stack (clearing it is part of every
    /// walk's cost) and, in the rare case it would overflow, continues on a [`STACK_SIZE`] one.
    #[inline(always)]
    fn packet_from<V: Visitor, const K: usize, const L: usize, T: NodeTest, const N: usize>(
        &self,
        rays4: &mut Rays4<L>,
        vs: &mut [V; K],
        mut active: u32,
        seed: &[(u32, u32, f32)],
        next: (u32, u32),
        test: T,
    ) {
        let mut stack = [(0u32, 0u32, 0f32); N];
        for (to, from) in stack.iter_mut().zip(seed) {
            *to = *from;
        }
        let mut sp = seed.len();
        let (mut word, mut mask) = next;
        loop {
            if word & LEAF != 0 {
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    if T::PAIRS && m != 0 && word & SPHERE == 0 {
                        // Two rays against the leaf's triangles in one test.
                        let j = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let packet = &self.packets[((word & !LEAF) >> 2) as usize];
                        let count = (word & 3) as usize + 1;
                        let [a, b] = vs.get_disjoint_mut([i, j]).expect("two rays of the packet");
                        let stops = test.visit_pair(a, b, &packet.tris, &packet.ids, count);
                        for (k, stop) in [(i, stops.0), (j, stops.1)] {
                            if stop {
                                active &= !(1 << k);
                            } else if V::ORDERED {
                                rays4.set_limit(k, vs[k].limit());
                            }
                        }
                        continue;
                    }
                    let v = &mut vs[i];
                    let stop = if word & SPHERE != 0 {
                        v.visit(&self.spheres[(word & !(LEAF | SPHERE)) as usize])
                    } else {
                        let packet = &self.packets[((word & !LEAF) >> 2) as usize];
                        v.visit_triangles(&packet.tris, &packet.ids, (word & 3) as usize + 1)
                    };
                    if stop {
                        active &= !(1 << i);
                    } else if V::ORDERED {
                        rays4.set_limit(i, v.limit());
                    }
                }
                if active == 0 {
                    return;
                }
            } else {
                // The children entered, nearest first when ordered: (child word, its rays, a
                // `t` no later than any of their entry ts).
                let mut hits = [(0u32, 0u32, 0f32); WIDTH];
                let mut k = 0;
                // A macro, not a closure: see `rays_by_slot`.
                macro_rules! add {
                    ($child:expr, $rays:expr, $t:expr) => {{
                        let t = $t;
                        let mut j = k;
                        if V::ORDERED {
                            while j > 0 && hits[j - 1].2 < t {
                                hits[j] = hits[j - 1];
                                j -= 1;
                            }
                        }
                        hits[j] = ($child, $rays, t);
                        k += 1;
                    }};
                }
                let rest = mask & (mask - 1);
                if rest & rest.wrapping_sub(1) == 0 {
                    // One or two rays left (deep in the tree, where a packet's rays have
                    // parted): each ray's own test, the slots taken straight from their hit
                    // masks (no transpose), in slot order as below: the same children, order
                    // and keys (the keys folded over the rays in the same order).
                    let a = mask.trailing_zeros() as usize;
                    // Ray `b` only when `rest` holds it; its slots are none otherwise.
                    let b = (rest.trailing_zeros() & 31) as usize;
                    // Ray `a`, then ray `b` when there is one, by the node test `$t`, its keys
                    // folded as `rays_by_slot` folds them.
                    macro_rules! one_or_two {
                        ($t:expr, |$ray:ident, $keys:ident| $one:expr) => {{
                            let mut $keys = $t.no_keys();
                            let sa = {
                                let $ray = a;
                                $one
                            };
                            let sb = if rest != 0 {
                                let $ray = b;
                                $one
                            } else {
                                0
                            };
                            (sa, sb, $t.key_array($keys))
                        }};
                    }
                    let ((sa, sb, key), child) = if word & NARROW != 0 {
                        let node = &self.narrow[(word & !NARROW) as usize];
                        let found = one_or_two!(Sse4, |ray, keys| {
                            Sse4::one_of_w(rays4, node, ray, &mut keys) & node.valid
                        });
                        (found, node.child_words())
                    } else {
                        let node = &self.nodes[word as usize];
                        let found = one_or_two!(test, |ray, keys| {
                            test.one_of(rays4, node, ray, &mut keys) & node.valid
                        });
                        (found, node.child)
                    };
                    let mut slots = sa | sb;
                    while slots != 0 {
                        let slot = slots.trailing_zeros() as usize;
                        slots &= slots - 1;
                        let rays = ((sa >> slot) & 1) << a | ((sb >> slot) & 1) << b;
                        add!(child[slot], rays, key[slot]);
                    }
                } else {
                    // Per child slot, the rays that enter it, and a `t` no later than any of
                    // their entry ts.
                    let (entered, key, mut slots, child) = if word & NARROW != 0 {
                        let node = &self.narrow[(word & !NARROW) as usize];
                        let (entered, key, any) =
                            Sse4.enter_of::<K, L, NARROW_WIDTH>(rays4, node, mask);
                        (entered, key, any, node.child_words())
                    } else {
                        let node = &self.nodes[word as usize];
                        let (entered, key, any) = test.enter::<K, L>(rays4, node, mask);
                        (entered, key, any, node.child)
                    };
                    // Slot by slot, one step per slot entered.
                    while slots != 0 {
                        let slot = slots.trailing_zeros() as usize;
                        slots &= slots - 1;
                        add!(child[slot], entered[slot], key[slot]);
                    }
                }
                if k > 0 {
                    let next = (hits[k - 1].0, hits[k - 1].1);
                    if N < STACK_SIZE && sp + k - 1 > N {
                        // The pushed children on the long stack, the nearest walked next.
                        let mut deeper = [(0u32, 0u32, 0f32); STACK_SIZE];
                        deeper[..sp].copy_from_slice(&stack[..sp]);
                        deeper[sp..sp + k - 1].copy_from_slice(&hits[..k - 1]);
                        let seed = &deeper[..sp + k - 1];
                        return self.packet_from::<V, K, L, T, STACK_SIZE>(
                            rays4, vs, active, seed, next, test,
                        );
                    }
                    (word, mask) = next;
                    for h in &hits[..k - 1] {
                        self.prefetch_child(h.0);
                        stack[sp] = *h;
                        sp += 1;
                    }
                    continue;
                }
            }
            // Pop the next child with a ray still looking whose best hit is not before it.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (w, m, t) = stack[sp];
                let m = m & active;
                if m == 0 {
                    continue;
                }
                if V::ORDERED {
                    let mut any = false;
                    let mut r = m;
                    while r != 0 {
                        let i = r.trailing_zeros() as usize;
                        r &= r - 1;
                        any |= t <= vs[i].limit();
                    }
                    if !any {
                        continue;
                    }
                }
                (word, mask) = (w, m);
                break;
            }
        }
    }
}

impl Bvh {
    /// Prefetches the node or triangle packet of child word `word` (a pushed child, visited
    /// later: its lines load while the nearer children are walked).
    #[inline(always)]
    fn prefetch_child(&self, word: u32) {
        if word & (LEAF | NARROW) == 0 {
            prefetch(&self.nodes[word as usize]);
        } else if word & LEAF == 0 {
            prefetch(&self.narrow[(word & !NARROW) as usize]);
        } else if word & SPHERE == 0 {
            prefetch(&self.packets[((word & !LEAF) >> 2) as usize]);
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

/// The rays of a packet for the node test, lane `i` for ray `i`, so one SIMD test checks four
/// (SSE) or eight (AVX2) rays against one child box: the same slab arithmetic as [`TravRay`],
/// each ray's own numbers, with the near and far planes per axis taken as the smaller and
/// larger of the two planes' `t` (for `1/d` of either sign, the plane [`TravRay::near`] picks
/// gives the smaller: `(plane − o)·(1/d)` rounds monotonically in the plane, so the values are
/// the same, bar the sign of a zero, which no comparison sees).
struct Rays4<const L: usize> {
    o: [[f32; L]; 3],
    inv: [[f32; L]; 3],
    /// Each ray's [`TravRay::near`].
    near: [[u32; 3]; L],
    t_min: f32,
    /// Each ray's [`Visitor::limit`], as of its last leaf.
    limit: [f32; L],
}

impl<const L: usize> Rays4<L> {
    /// The lanes of the rays of `active` (bit `i` for `rays[i]`); the others are never
    /// tested, and keep placeholder values (a shadow packet leaves out the lanes without a
    /// shadow ray: their rays are last packet's).
    #[inline(always)]
    fn new<const K: usize>(rays: &[Ray; K], active: u32, t_min: f32) -> Self {
        // `walk_packet` picks `L ≥ K`; its other branches, where `L < K`, are never taken.
        const { assert!(L.is_multiple_of(8)) };
        assert!(K <= L);
        // Formed in place, field by field: arrays built apart and moved in are copied.
        let mut r = Rays4 {
            o: [[0.0f32; L]; 3],
            inv: [[1.0f32; L]; 3],
            near: [[0u32; 3]; L],
            t_min,
            limit: [f32::NEG_INFINITY; L],
        };
        let mut rest = active;
        while rest != 0 {
            let i = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let Some(ray) = rays.get(i) else { break };
            let d = trav_inv(ray.dir);
            for axis in 0..3 {
                r.o[axis][i] = ray.origin[axis];
                r.inv[axis][i] = d[axis];
                r.near[i][axis] = 2 * axis as u32 + u32::from(d[axis] < 0.0);
            }
        }
        r
    }

    #[inline(always)]
    fn set_limit(&mut self, i: usize, limit: f32) {
        self.limit[i] = limit;
    }
}

/// The packet test's transpose: `$one` gives the slots ray `$ray` (of `$mask`, a packet of
/// `$k` rays) meets, and the rays' slot masks (masked by `$valid`), eight rays at a time, form
/// an 8×8 bit matrix, transposed into each slot's rays (bit `i` of `entered[c]`: ray `i`
/// enters slot `c`); with them, the slots any ray enters (bit `c`). A macro, not a function
/// taking a closure: a closure is compiled without the AVX2 features of the walk around it,
/// and the node test in it would not be inlined.
macro_rules! rays_by_slot {
    ($k:expr, $mask:expr, $valid:expr, |$ray:ident| $one:expr) => {{
        const { assert!(WIDTH == 8) };
        let mut entered = [0u32; WIDTH];
        // The slots any ray enters.
        let mut any = 0u32;
        for g in 0..$k.div_ceil(8) {
            let group = ($mask >> (8 * g)) & 0xff;
            if group == 0 {
                continue;
            }
            let mut rows = 0u64;
            let mut m = group;
            while m != 0 {
                let i = m.trailing_zeros() as usize;
                m &= m - 1;
                let $ray = 8 * g + i;
                let slots = $one & $valid;
                any |= slots;
                rows |= u64::from(slots) << (8 * i);
            }
            let columns = transpose8(rows);
            for (c, e) in entered.iter_mut().enumerate() {
                *e |= (((columns >> (8 * c)) & 0xff) as u32) << (8 * g);
            }
        }
        (entered, any)
    }};
}

/// The node test of a packet: for the rays of `mask` (a subset of the packet's), per child
/// slot, the rays whose widened `(t_min, limit]` interval meets its box (as [`Bvh::walk_from`]
/// tests each), and the smallest entry `t` of the rays of their lane groups that meet it (no
/// later than any of theirs, so a child popped behind it is behind every one of them).
trait NodeTest: Copy {
    /// Whether [`NodeTest::visit_pair`] tests two rays at once (the packet walk then hands it
    /// a leaf's rays two by two).
    const PAIRS: bool = false;

    /// Rays `a` and `b` against lanes `0..count` of `tris` (ids `ids`), each as its
    /// [`Visitor::visit_triangles`]: whether each stops.
    #[inline(always)]
    fn visit_pair<V: Visitor>(
        &self,
        a: &mut V,
        b: &mut V,
        tris: &Triangles4,
        ids: &[u32; 4],
        count: usize,
    ) -> (bool, bool) {
        visit_each(a, b, tris, ids, count)
    }

    /// The single-ray test: the slots of `node` whose widened `(t_min, limit]` interval the
    /// ray `r` meets (bit `i` for slot `i`), and each slot's widened entry `t`.
    fn enter_one(&self, r: &TravRay, node: &Node, limit: f32) -> (u32, [f32; WIDTH]);

    /// Each slot's nearest entry so far, as the test keeps it.
    type Keys: Copy;

    /// No entry yet (every key infinite).
    fn no_keys(&self) -> Self::Keys;

    /// Ray `ray` of `r` against `node`'s boxes, as [`NodeTest::enter_one`] tests them: the
    /// slots it meets (not yet masked by `valid`), with its entry `t` of each slot it meets
    /// folded into `keys` (an empty slot's key, from its zero box, is never read: no ray
    /// enters it).
    fn one_of<const L: usize>(
        &self,
        r: &Rays4<L>,
        node: &Node,
        ray: usize,
        keys: &mut Self::Keys,
    ) -> u32;

    /// The keys as one `t` per slot.
    fn key_array(&self, keys: Self::Keys) -> [f32; WIDTH];

    /// The packet's test, ray by ray, each ray against the node's boxes as the single walk
    /// tests them: deep in the tree a packet's rays have parted, and a box tested against all
    /// its lanes pays for rays no longer in the packet. The rays' slot masks, eight rays at a
    /// time, form an 8×8 bit matrix, transposed into each slot's rays (bit `i` of
    /// `entered[c]`: ray `i` enters slot `c`). Returns those, each slot's key, and the slots
    /// any ray enters (bit `c`), so the caller steps through those alone.
    #[inline(always)]
    fn enter<const K: usize, const L: usize>(
        &self,
        r: &Rays4<L>,
        node: &Node,
        mask: u32,
    ) -> ([u32; WIDTH], [f32; WIDTH], u32) {
        let mut keys = self.no_keys();
        let (entered, any) = rays_by_slot!(K, mask, node.valid, |ray| self
            .one_of(r, node, ray, &mut keys));
        (entered, self.key_array(keys), any)
    }
}

/// [`NodeTest::visit_pair`] one ray after the other.
#[inline(always)]
fn visit_each<V: Visitor>(
    a: &mut V,
    b: &mut V,
    tris: &Triangles4,
    ids: &[u32; 4],
    count: usize,
) -> (bool, bool) {
    (
        a.visit_triangles(tris, ids, count),
        b.visit_triangles(tris, ids, count),
    )
}

impl<const W: usize> Node<W> {
    /// The child words, in `WIDTH` slots (the slots past `W` hold zero, and no test enters
    /// them).
    #[inline(always)]
    fn child_words(&self) -> [u32; WIDTH] {
        std::array::from_fn(|i| if i < W { self.child[i] } else { 0 })
    }
}

/// The node test four rays wide (SSE, glam).
#[derive(Clone, Copy)]
struct Sse4;

impl NodeTest for Sse4 {
    #[inline(always)]
    fn enter_one(&self, r: &TravRay, node: &Node, limit: f32) -> (u32, [f32; WIDTH]) {
        self.enter_one_of(r, node, limit)
    }

    type Keys = [Vec4; WIDTH / 4];

    #[inline(always)]
    fn no_keys(&self) -> Self::Keys {
        [Vec4::INFINITY; WIDTH / 4]
    }

    /// The eight boxes four at a time.
    #[inline(always)]
    fn one_of<const L: usize>(
        &self,
        r: &Rays4<L>,
        node: &Node,
        ray: usize,
        keys: &mut Self::Keys,
    ) -> u32 {
        Self::one_of_w(r, node, ray, keys)
    }

    #[inline(always)]
    fn key_array(&self, keys: Self::Keys) -> [f32; WIDTH] {
        let mut key = [f32::INFINITY; WIDTH];
        for (half, k) in keys.iter().enumerate() {
            key[4 * half..4 * half + 4].copy_from_slice(&k.to_array());
        }
        key
    }
}

impl Sse4 {
    /// [`NodeTest::enter_one`] for a node of either width (the slots past `W` are not met).
    /// Narrow nodes take this test in the AVX2 walks too: compiled there, it is the same
    /// arithmetic, VEX-encoded.
    #[inline(always)]
    fn enter_one_of<const W: usize>(
        &self,
        r: &TravRay,
        node: &Node<W>,
        limit: f32,
    ) -> (u32, [f32; WIDTH]) {
        let (o, inv) = ([r.ox, r.oy, r.oz], [r.ix, r.iy, r.iz]);
        let limit = Vec4::splat(limit);
        let mut mask = 0;
        let mut t = [f32::INFINITY; WIDTH];
        for half in 0..W / 4 {
            let (hit, t_near) = Self::slab(node, half, o, inv, r.near, r.t_min, limit);
            mask |= hit.bitmask() << (4 * half);
            t[4 * half..4 * half + 4].copy_from_slice(&t_near.to_array());
        }
        (mask & node.valid, t)
    }

    /// [`NodeTest::one_of`] for a node of either width.
    #[inline(always)]
    fn one_of_w<const L: usize, const W: usize>(
        r: &Rays4<L>,
        node: &Node<W>,
        ray: usize,
        keys: &mut [Vec4; WIDTH / 4],
    ) -> u32 {
        let o = [0, 1, 2].map(|axis| Vec4::splat(r.o[axis][ray]));
        let inv = [0, 1, 2].map(|axis| Vec4::splat(r.inv[axis][ray]));
        let near = r.near[ray].map(|n| n as usize);
        let (t_min, limit) = (Vec4::splat(r.t_min), Vec4::splat(r.limit[ray]));
        let mut bits = 0;
        for (half, key) in keys.iter_mut().enumerate().take(W / 4) {
            let (hit, t_near) = Self::slab(node, half, o, inv, near, t_min, limit);
            bits |= hit.bitmask() << (4 * half);
            *key = key.min(Vec4::select(hit, t_near, Vec4::INFINITY));
        }
        bits
    }

    /// [`NodeTest::enter`] for a node of either width.
    #[inline(always)]
    fn enter_of<const K: usize, const L: usize, const W: usize>(
        &self,
        r: &Rays4<L>,
        node: &Node<W>,
        mask: u32,
    ) -> ([u32; WIDTH], [f32; WIDTH], u32) {
        let mut keys = self.no_keys();
        let (entered, any) = rays_by_slot!(K, mask, node.valid, |ray| Self::one_of_w(
            r, node, ray, &mut keys
        ));
        (entered, self.key_array(keys), any)
    }

    /// The widened slab test of one ray (origin `o`, clamped `1/d` `inv`, near planes `near`,
    /// each splat over four lanes) against slots `4·half..4·half + 4` of `node`: the slots met
    /// (not yet masked by `valid`) and each slot's widened entry `t`.
    #[inline(always)]
    fn slab<const W: usize>(
        node: &Node<W>,
        half: usize,
        o: [Vec4; 3],
        inv: [Vec4; 3],
        near: [usize; 3],
        t_min: Vec4,
        limit: Vec4,
    ) -> (glam::BVec4A, Vec4) {
        let [nx, ny, nz] = near;
        let (fx, fy, fz) = (nx ^ 1, ny ^ 1, nz ^ 1);
        let lanes = 4 * half..4 * half + 4;
        let p = |k: usize| Vec4::from_slice(&node.planes[k][lanes.clone()]);
        let t_near = ((p(nx) - o[0]) * inv[0])
            .max((p(ny) - o[1]) * inv[1])
            .max((p(nz) - o[2]) * inv[2]);
        let t_far = ((p(fx) - o[0]) * inv[0])
            .min((p(fy) - o[1]) * inv[1])
            .min((p(fz) - o[2]) * inv[2]);
        // Widen both ends by the rounding of the slab arithmetic *and* of the primitives'
        // own t: a tie (equal t, lower id) in a flat box must not be culled by an ulp.
        let (shrink, grow) = box_t_scales();
        let t_near = (t_near * Vec4::splat(shrink)).max(t_min);
        let t_far = (t_far * Vec4::splat(grow)).min(limit);
        (t_near.cmple(t_far), t_near)
    }
}

/// [`Bvh::walk`] as the function `pulp` compiles with AVX2.
#[cfg(target_arch = "x86_64")]
struct Avx2Walk<'a, V> {
    bvh: &'a Bvh,
    ray: &'a Ray,
    t_min: f32,
    v: &'a mut V,
    v3: pulp::x86::V3,
}

#[cfg(target_arch = "x86_64")]
impl<V: Visitor> pulp::NullaryFnOnce for Avx2Walk<'_, V> {
    type Output = ();

    #[inline(always)]
    fn call(self) {
        let r = TravRay::new(self.ray, self.t_min);
        let test = Avx8(self.v3);
        self.bvh
            .walk_from::<V, SHORT_STACK, _>(&r, self.v, &[], 0, test);
    }
}

/// [`Bvh::walk_packet_with`] the [`Avx8`] test, as the function `pulp` compiles with AVX2:
/// its `call` must be inlined there, hence a type rather than a closure.
#[cfg(target_arch = "x86_64")]
struct Avx8Walk<'a, V, const K: usize, const L: usize> {
    bvh: &'a Bvh,
    rays: &'a [Ray; K],
    t_min: f32,
    vs: &'a mut [V; K],
    active: u32,
    v3: pulp::x86::V3,
}

#[cfg(target_arch = "x86_64")]
impl<V: Visitor, const K: usize, const L: usize> pulp::NullaryFnOnce for Avx8Walk<'_, V, K, L> {
    type Output = ();

    #[inline(always)]
    fn call(self) {
        let test = Avx8(self.v3);
        self.bvh
            .walk_packet_with::<V, K, L, _>(self.rays, self.t_min, self.vs, self.active, test);
    }
}

/// The node test eight rays wide (AVX2 through `pulp`'s safe intrinsics), the same operations
/// in the same order as [`Sse4`] (`min`/`max` return the second operand on NaN in both), so
/// the same numbers.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
struct Avx8(pulp::x86::V3);

#[cfg(target_arch = "x86_64")]
impl NodeTest for Avx8 {
    const PAIRS: bool = true;

    /// Both rays in one eight-lane test when their queries allow it
    /// ([`crate::accel::pair_triangles4`]), each on its own otherwise.
    #[inline(always)]
    fn visit_pair<V: Visitor>(
        &self,
        a: &mut V,
        b: &mut V,
        tris: &Triangles4,
        ids: &[u32; 4],
        count: usize,
    ) -> (bool, bool) {
        let pair = match (a.pair_query(), b.pair_query()) {
            (Some(qa), Some(qb)) => pair_triangles4(self.0, qa, qb, tris, count),
            _ => None,
        };
        match pair {
            Some((ha, hb)) => (
                a.take_triangles(&ha, tris, ids, count),
                b.take_triangles(&hb, tris, ids, count),
            ),
            None => visit_each(a, b, tris, ids, count),
        }
    }

    /// [`Sse4::enter_one`] on all eight slots at once: the same operations lane by lane.
    #[inline(always)]
    fn enter_one(&self, r: &TravRay, node: &Node, limit: f32) -> (u32, [f32; WIDTH]) {
        let o = [r.ox.x, r.oy.x, r.oz.x];
        let inv = [r.ix.x, r.iy.x, r.iz.x];
        let (hit, t_near) = self.slab(node, o, inv, r.near, r.t_min.x, limit);
        let mask = self.0.avx._mm256_movemask_ps(hit) as u32;
        (mask & node.valid, pulp::cast(t_near))
    }

    type Keys = std::arch::x86_64::__m256;

    #[inline(always)]
    fn no_keys(&self) -> Self::Keys {
        self.0.avx._mm256_set1_ps(f32::INFINITY)
    }

    /// The eight boxes at once.
    #[inline(always)]
    fn one_of<const L: usize>(
        &self,
        r: &Rays4<L>,
        node: &Node,
        ray: usize,
        keys: &mut Self::Keys,
    ) -> u32 {
        let avx = self.0.avx;
        let o = [r.o[0][ray], r.o[1][ray], r.o[2][ray]];
        let inv = [r.inv[0][ray], r.inv[1][ray], r.inv[2][ray]];
        let near = r.near[ray].map(|n| n as usize);
        let (hit, t_near) = self.slab(node, o, inv, near, r.t_min, r.limit[ray]);
        let inf = avx._mm256_set1_ps(f32::INFINITY);
        *keys = avx._mm256_min_ps(*keys, avx._mm256_blendv_ps(inf, t_near, hit));
        avx._mm256_movemask_ps(hit) as u32
    }

    #[inline(always)]
    fn key_array(&self, keys: Self::Keys) -> [f32; WIDTH] {
        pulp::cast(keys)
    }
}

#[cfg(target_arch = "x86_64")]
impl Avx8 {
    /// The widened slab test of one ray (origin `o`, clamped `1/d` `inv`, near planes `near`)
    /// against a node's eight child boxes: the slots met (all bits of lane `c`, not yet
    /// masked by `valid`) and each slot's widened entry `t`.
    #[inline(always)]
    fn slab(
        &self,
        node: &Node,
        o: [f32; 3],
        inv: [f32; 3],
        near: [usize; 3],
        t_min: f32,
        limit: f32,
    ) -> (std::arch::x86_64::__m256, std::arch::x86_64::__m256) {
        use std::arch::x86_64::{__m256, _CMP_LE_OQ};
        const { assert!(WIDTH == 8) };
        let avx = self.0.avx;
        let [nx, ny, nz] = near;
        let (fx, fy, fz) = (nx ^ 1, ny ^ 1, nz ^ 1);
        let splat = |x: f32| avx._mm256_set1_ps(x);
        let (min, max) = (
            |a, b| avx._mm256_min_ps(a, b),
            |a, b| avx._mm256_max_ps(a, b),
        );
        let (sub, mul) = (
            |a, b| avx._mm256_sub_ps(a, b),
            |a, b| avx._mm256_mul_ps(a, b),
        );
        let p = |k: usize| -> __m256 { pulp::cast(node.planes[k]) };
        let (ox, oy, oz) = (splat(o[0]), splat(o[1]), splat(o[2]));
        let (ix, iy, iz) = (splat(inv[0]), splat(inv[1]), splat(inv[2]));
        let t_near = max(
            max(mul(sub(p(nx), ox), ix), mul(sub(p(ny), oy), iy)),
            mul(sub(p(nz), oz), iz),
        );
        let t_far = min(
            min(mul(sub(p(fx), ox), ix), mul(sub(p(fy), oy), iy)),
            mul(sub(p(fz), oz), iz),
        );
        let (shrink, grow) = box_t_scales();
        let t_near = max(mul(t_near, splat(shrink)), splat(t_min));
        let t_far = min(mul(t_far, splat(grow)), splat(limit));
        (avx._mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far), t_near)
    }
}

/// The transpose of an 8×8 bit matrix whose row `i` is byte `i` (bit `j` of the byte for
/// column `j`): row `j` of the result holds column `j`.
#[inline(always)]
fn transpose8(x: u64) -> u64 {
    let t = (x ^ (x >> 7)) & 0x00AA_00AA_00AA_00AA;
    let x = x ^ t ^ (t << 7);
    let t = (x ^ (x >> 14)) & 0x0000_CCCC_0000_CCCC;
    let x = x ^ t ^ (t << 14);
    let t = (x ^ (x >> 28)) & 0x0000_0000_F0F0_F0F0;
    x ^ t ^ (t << 28)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::build::stack_need;
    use crate::accel::{AnyHit, Closest, Prim, Shape};
    use crate::geometry::Methods;

    /// `transpose8` moves bit `(i, j)` to `(j, i)`.
    #[test]
    fn bit_matrix_transpose() {
        let mut rng = crate::rng::Pcg::new(0x9E37_79B9_7F4A_7C15);
        for _ in 0..200 {
            let x = u64::from(rng.next_u32()) << 32 | u64::from(rng.next_u32());
            let t = transpose8(x);
            for i in 0..8 {
                for j in 0..8 {
                    assert_eq!(t >> (8 * j + i) & 1, x >> (8 * i + j) & 1);
                }
            }
        }
    }

    /// 3000 small triangles scattered in a box of side 4, and the pseudo-random numbers in
    /// `[−1, 1]` (seeded by `seed`) that placed them, to go on with.
    fn scattered_triangles(seed: u32) -> (Vec<Prim>, impl FnMut() -> f32) {
        let mut rnd = crate::rng::signed(u64::from(seed));
        let prims = (0..3000u32)
            .map(|id| {
                let c = Vec3::new(rnd(), rnd(), rnd()) * 2.0;
                let v = [0, 1, 2].map(|_| c + Vec3::new(rnd(), rnd(), rnd()) * 0.3);
                Prim {
                    shape: Shape::Triangle(v),
                    id,
                }
            })
            .collect();
        (prims, rnd)
    }

    /// A query that overflows the short stack continues on the long one and finds what brute
    /// force finds: a one-entry short stack overflows on nearly every query.
    #[test]
    fn overflow_to_the_long_stack_finds_the_same_hits() {
        let (prims, mut rnd) = scattered_triangles(7);
        let bvh = Bvh::build(prims.clone());
        assert!(stack_need(&bvh) > 1);
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
            bvh.walk_from::<_, 8, _>(&TravRay::new(&ray, 0.0), &mut tiny, &[], 0, Sse4);
            let mut short = Closest::new(&m, &ray, 0.0, f32::INFINITY);
            bvh.walk(&ray, 0.0, &mut short);
            assert_eq!(tiny.hit(), brute.hit());
            assert_eq!(short.hit(), brute.hit());
            hits += usize::from(brute.hit().is_some());
        }
        assert!(hits > 1000, "{hits}");
    }

    /// A packet walk that overflows its short stack continues on the long one and finds, ray
    /// by ray, what brute force finds: an eight-entry short stack overflows on most packets.
    #[test]
    fn packet_overflow_to_the_long_stack_finds_the_same_hits() {
        let (prims, mut rnd) = scattered_triangles(11);
        let bvh = Bvh::build(prims.clone());
        let m = Methods::default();
        let (mut hits, mut blocked) = (0, 0);
        for _ in 0..300 {
            // Eight rays from one point in nearby directions, as a camera packet.
            let o = Vec3::new(rnd(), rnd(), rnd()) * 4.0;
            let aim = Vec3::new(rnd(), rnd(), rnd()) - o;
            let rays: [Ray; 8] = std::array::from_fn(|_| {
                let d = aim + Vec3::new(rnd(), rnd(), rnd()) * 0.2;
                Ray::new(o, d.normalize())
            });
            let mut closest = rays
                .each_ref()
                .map(|r| Closest::new(&m, r, 0.0, f32::INFINITY));
            let mut rays4 = Rays4::<8>::new(&rays, 0xff, 0.0);
            for (i, v) in closest.iter().enumerate() {
                rays4.set_limit(i, v.limit());
            }
            bvh.packet_from::<_, 8, 8, Sse4, 8>(
                &mut rays4,
                &mut closest,
                0xff,
                &[],
                (0, 0xff),
                Sse4,
            );
            let length = 3.0;
            let mut any = rays.each_ref().map(|r| AnyHit {
                q: crate::accel::Query::new(&m, r, 0.0),
                t_max: length,
                hit: false,
            });
            let mut rays4 = Rays4::<8>::new(&rays, 0xff, 0.0);
            for (i, v) in any.iter().enumerate() {
                rays4.set_limit(i, v.limit());
            }
            bvh.packet_from::<_, 8, 8, Sse4, 8>(&mut rays4, &mut any, 0xff, &[], (0, 0xff), Sse4);
            for (i, ray) in rays.iter().enumerate() {
                let mut brute = Closest::new(&m, ray, 0.0, f32::INFINITY);
                for p in &prims {
                    brute.visit(p);
                }
                assert_eq!(closest[i].hit(), brute.hit());
                let occluded = brute.hit().is_some_and(|h| h.t < length);
                assert_eq!(any[i].hit, occluded);
                hits += usize::from(brute.hit().is_some());
                blocked += usize::from(occluded);
            }
        }
        assert!(
            hits > 1000 && blocked > 500,
            "{hits} hits, {blocked} blocked"
        );
    }
}
