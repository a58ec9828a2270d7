//! The triangle BVH: obvhs builds the tree, this module lays it out for SIMD and traverses it.
//!
//! obvhs builds a binary BVH (PLOC, then reinsertion, with the [`BvhBuildParams`] preset); it is
//! collapsed here into nodes of up to eight children whose boxes sit in structure-of-arrays
//! form, one lane per child, so one ray tests eight boxes in two registers' worth of SSE
//! instructions (the test is written over plain eight-lane arrays, which the compiler
//! vectorises; a build for an AVX CPU gets one register, and measured no faster). Leaves are
//! *packets* of up to four triangles (their first vertices and edges, again one lane per
//! triangle) tested together by a four-wide Möller–Trumbore. Which binary
//! nodes become a wide node's children and which subtrees become packets is chosen by a
//! surface-area dynamic programme over the whole binary tree (`Collapse::plan`).
//!
//! Why not obvhs's own traversal: its compressed wide BVH (CWBVH) unpacks eight quantised child
//! boxes per node and tests leaf triangles one at a time, which profiling put at 40% of a query
//! (docs/performance.md). A traversal over a 1M-triangle mesh is bound by memory latency, one
//! cache miss per node visited, so the wide nodes (half the depth of a four-wide tree) matter
//! most; nodes and packets are aligned to cache lines so none straddles one line more than it
//! must, and the children a ray will visit later are touched when stacked so their lines load
//! in the meantime. On the 1.31M-triangle icosphere: 84,627 nodes of 7.0 children on average,
//! 505,096 packets of 2.6 triangles, 90.5 bytes per triangle. Arrays that large live on
//! transparent huge pages ([`Pages`]), so the visits are not also TLB misses.
//!
//! Everything is safe Rust: the lanes are glam's `Vec4` (an SSE register on x86-64) or arrays
//! the compiler vectorises.

use crate::geom::{TriangleHit, gamma};
use crate::pages::Pages;
use glam::{BVec4A, Vec3, Vec3A, Vec4};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::PlocBuilder;
use obvhs::splits::split_aabbs_preset;
use obvhs::triangle::Triangle;
use std::cell::Cell;

thread_local! {
    /// Each thread's traversal stacks, kept between queries so a query neither allocates nor
    /// clears a fixed array.
    static CLOSEST_STACK: Cell<Vec<(u32, f32)>> = const { Cell::new(Vec::new()) };
    static ANY_STACK: Cell<Vec<u32>> = const { Cell::new(Vec::new()) };
}

/// The lanes set in `mask`, each named by `name(lane)` with its entry distance from `t_near`,
/// into `out` sorted nearest first (insertion sort: at most eight); returns how many.
#[inline(always)]
fn by_entry<T: Copy>(
    mask: u32,
    t_near: &[f32; ARITY],
    name: impl Fn(usize) -> T,
    out: &mut [(T, f32); ARITY],
) -> usize {
    let mut n = 0;
    let mut m = mask;
    while m != 0 {
        let lane = m.trailing_zeros() as usize & 7;
        m &= m - 1;
        let entry = (name(lane), t_near[lane]);
        let mut k = n;
        while k > 0 && out[k - 1].1 > entry.1 {
            out[k] = out[k - 1];
            k -= 1;
        }
        out[k] = entry;
        n += 1;
    }
    n
}

/// Runs `query` with this thread's (emptied) stack from `key`. The stack is taken, not
/// borrowed, so a nested query (none today) would simply get a fresh one.
#[inline(always)]
fn with_stack<T, R>(
    key: &'static std::thread::LocalKey<Cell<Vec<T>>>,
    query: impl FnOnce(&mut Vec<T>) -> R,
) -> R {
    key.with(|cell| {
        let mut stack = cell.take();
        stack.clear();
        let result = query(&mut stack);
        cell.set(stack);
        result
    })
}

/// Set in a child reference that names a leaf packet rather than a node.
const LEAF: u32 = 1 << 31;
/// The child reference of an unused lane (its box is empty, so it is never entered).
const EMPTY: u32 = u32::MAX;
/// Children per node: two SIMD registers' worth.
const ARITY: usize = 8;
/// Triangles per leaf packet (the SIMD width).
const WIDTH: usize = 4;
/// pbrt's `gamma(3)`: the relative error of a slab distance `(b - o) * (1 / d)`; the far
/// distance is pushed out by twice this so rounding never culls a box the ray touches.
const SLAB_SLACK: f32 = 2.0 * gamma(3);
/// The same push folded into the far planes' reciprocals, `(b - o) * ((1 / d) * FAR_SCALE)`,
/// for queries with `t_min >= 0`: the and, multiply and add of `t + |t| * SLAB_SLACK` leave
/// every node's dependent chain, and unused lanes no longer make a NaN. Four
/// roundings then separate a computed far distance from the true one (`gamma(4)` below it)
/// and three the near distance (`gamma(3)` above it), so a box the ray touches is kept when
/// `FAR_SCALE * (1 - gamma(4)) >= 1 + gamma(3)`; `1 + 2 gamma(4)` is four ulps above one
/// and clears it (`far_scale_covers_the_rounding` checks this in f64). A negative far
/// distance would be pulled in, not pushed out, so a query that may start behind its origin
/// keeps [`SLAB_SLACK`] instead.
const FAR_SCALE: f32 = 1.0 + 2.0 * gamma(4);

/// Eight children's boxes, one lane per child (children 0-3 in the first register, 4-7 in
/// the second), and what each child is: 224 bytes, padded to the four cache lines it would
/// take anyway, and aligned to start a line so it never takes five.
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(64))]
struct Node {
    /// `[min_x, max_x, min_y, max_y, min_z, max_z]`; an unused lane has min +inf, max -inf.
    bounds: [[Vec4; 2]; 6],
    /// A node index, `LEAF | packet index`, or `EMPTY`.
    child: [u32; ARITY],
    /// Explicit padding to 256 bytes, so a node is plain bytes ([`Pages`] maps it).
    _pad: [u32; 8],
}

impl Node {
    /// A node with every lane unused (empty boxes, so no ray enters them).
    const EMPTY: Node = Node {
        bounds: [
            [Vec4::INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
            [Vec4::INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
            [Vec4::INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
        ],
        child: [EMPTY; ARITY],
        _pad: [0; 8],
    };

    /// Puts `aabb` in lane `lane`.
    fn set_box(&mut self, lane: usize, aabb: &Aabb) {
        for axis in 0..3 {
            self.bounds[2 * axis][lane >> 2][lane & 3] = aabb.min[axis];
            self.bounds[2 * axis + 1][lane >> 2][lane & 3] = aabb.max[axis];
        }
    }
}

/// Up to four triangles, one lane each: the first vertex and the two edges from it; 176
/// bytes padded to three cache lines.
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(64))]
struct Packet {
    v0: [Vec4; 3],
    e1: [Vec4; 3],
    e2: [Vec4; 3],
    /// The caller's two ids of the triangle in each lane (padding lanes are degenerate and
    /// never hit): a hit is reported without touching any other array.
    ids: [[u32; WIDTH]; 2],
    /// Explicit padding to 192 bytes, so a packet is plain bytes ([`Pages`] maps it).
    _pad: [u32; 4],
}

/// A hit found by [`WideBvh::closest`]: the triangle's ids and the triangle itself as the BVH
/// stores it (first vertex and the two edges from it), so the caller needs no further lookup.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WideHit {
    /// The two ids given for the triangle at build time.
    pub ids: [u32; 2],
    /// Distance and barycentrics.
    pub tri: TriangleHit,
    /// `v0`, `v1 - v0`, `v2 - v0`, exactly as the intersection test used them.
    pub v0: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
}

/// An eight-wide BVH with four-wide leaf packets over a list of triangles, its arrays on huge
/// pages where they are large enough ([`Pages`]).
#[derive(Clone, Debug)]
pub(crate) struct WideBvh {
    nodes: Pages<Node>,
    packets: Pages<Packet>,
    /// A node index, a leaf reference, or `EMPTY` for no triangles.
    root: u32,
}

/// A ray prepared for the box tests: splatted origin, reciprocal direction and near-plane lanes.
/// `SLACK`: far distances get [`SLAB_SLACK`] after the fact (a query with `t_min < 0`);
/// otherwise the far planes' reciprocals carry [`FAR_SCALE`]. Which one a query takes is
/// decided once, so the traversal of each has no test for it per node.
struct Prepared<const SLACK: bool> {
    o: [Vec4; 3],
    d: [Vec4; 3],
    inv: [f32; 3],
    /// The far planes' reciprocals: `inv` times [`FAR_SCALE`], or `inv` itself with `SLACK`.
    inv_far: [f32; 3],
    /// 1 where the direction is negative (the box's max plane is met first), else 0.
    near: [usize; 3],
}

impl<const SLACK: bool> Prepared<SLACK> {
    /// The ray from `o` along `d`.
    #[inline(always)]
    fn new(o: Vec3A, d: Vec3A) -> Self {
        // A zero component would give 0 * inf = NaN on a slab through the origin; a tiny
        // stand-in of the same sign gives the same slab answer with finite arithmetic.
        // (Three lanes at once: one division instruction instead of three.)
        let tiny = Vec3A::splat(1e-30);
        let safe = Vec3A::select(d.abs().cmplt(tiny), tiny.copysign(d), d);
        let inv = Vec3A::ONE / safe;
        let inv_far = if SLACK { inv } else { inv * FAR_SCALE };
        let inv = inv.to_array();
        Prepared {
            o: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
            d: [Vec4::splat(d.x), Vec4::splat(d.y), Vec4::splat(d.z)],
            inv,
            inv_far: inv_far.to_array(),
            near: inv.map(|i| usize::from(i < 0.0)),
        }
    }

    /// The entry distance of each of the node's first `N` children's boxes and the mask of
    /// those the ray enters within `[t_min, t_max]` (`N` a multiple of four: eight for a BVH
    /// node, four for a top level of few boxes). Written over plain arrays, which the compiler
    /// vectorises: one SSE register per four lanes on baseline x86-64 (one AVX register for
    /// eight when built for a CPU that has it, measured no faster). The `if`s are
    /// `maxps`/`minps` exactly, NaN operands included.
    #[inline(always)]
    fn slabs<const N: usize>(&self, node: &Node, t_min: f32, t_max: f32) -> ([f32; N], u32) {
        const { assert!(N.is_multiple_of(WIDTH) && N <= ARITY) };
        #[inline(always)]
        fn max(a: f32, b: f32) -> f32 {
            if a > b { a } else { b }
        }
        #[inline(always)]
        fn min(a: f32, b: f32) -> f32 {
            if a < b { a } else { b }
        }
        let plane = |i: usize| -> &[f32; N] {
            let lanes: &[f32; ARITY] = bytemuck::cast_ref(&node.bounds[i]);
            lanes.first_chunk().expect("N <= ARITY")
        };
        let (nx, ny, nz) = (self.near[0] & 1, self.near[1] & 1, self.near[2] & 1);
        let (near_x, far_x) = (plane(nx), plane(nx ^ 1));
        let (near_y, far_y) = (plane(2 + ny), plane(2 + (ny ^ 1)));
        let (near_z, far_z) = (plane(4 + nz), plane(4 + (nz ^ 1)));
        let (o, inv, inv_far) = (self.o.map(|v| v.x), self.inv, self.inv_far);
        let mut t_near = [0.0; N];
        let mut t_far = [0.0; N];
        for lane in 0..N {
            let tnx = (near_x[lane] - o[0]) * inv[0];
            let tfx = (far_x[lane] - o[0]) * inv_far[0];
            let tny = (near_y[lane] - o[1]) * inv[1];
            let tfy = (far_y[lane] - o[1]) * inv_far[1];
            let tnz = (near_z[lane] - o[2]) * inv[2];
            let tfz = (far_z[lane] - o[2]) * inv_far[2];
            t_near[lane] = max(max(tnx, tny), max(tnz, t_min));
            let t = min(min(tfx, tfy), tfz);
            // An unused lane's near distance is +inf and its far distance -inf, so it is
            // never entered. The slack makes -inf NaN; `t_max` goes first so that `minps`
            // returns its second operand, NaN, which no entry distance is below.
            t_far[lane] = min(t_max, if SLACK { t + t.abs() * SLAB_SLACK } else { t });
        }
        // The mask four lanes at a time: the compiler does not find `movmskps` in the loop.
        let mut mask = 0;
        for h in 0..N / WIDTH {
            let near = Vec4::from_slice(&t_near[WIDTH * h..]);
            mask |= near.cmple(Vec4::from_slice(&t_far[WIDTH * h..])).bitmask() << (WIDTH * h);
        }
        (t_near, mask)
    }

    /// The lanes of `p` the ray hits within `[t_min, t_max]`, with their distances and
    /// barycentrics (Möller–Trumbore, four triangles at once).
    #[inline(always)]
    fn triangles(&self, p: &Packet, t_min: f32, t_max: f32) -> (u32, Vec4, Vec4, Vec4) {
        let [dx, dy, dz] = self.d;
        let [e1x, e1y, e1z] = p.e1;
        let [e2x, e2y, e2z] = p.e2;
        // pvec = d x e2
        let px = dy * e2z - dz * e2y;
        let py = dz * e2x - dx * e2z;
        let pz = dx * e2y - dy * e2x;
        let det = e1x * px + e1y * py + e1z * pz;
        let inv_det = Vec4::ONE / det;
        // tvec = o - v0
        let tx = self.o[0] - p.v0[0];
        let ty = self.o[1] - p.v0[1];
        let tz = self.o[2] - p.v0[2];
        let b1 = (tx * px + ty * py + tz * pz) * inv_det;
        // qvec = tvec x e1
        let qx = ty * e1z - tz * e1y;
        let qy = tz * e1x - tx * e1z;
        let qz = tx * e1y - ty * e1x;
        let b2 = (dx * qx + dy * qy + dz * qz) * inv_det;
        let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
        // Comparisons with NaN are false, so a degenerate lane (det = 0) fails them.
        let ok: BVec4A = det.cmpne(Vec4::ZERO)
            & det.abs().cmplt(Vec4::INFINITY)
            & b1.cmpge(Vec4::ZERO)
            & b1.cmple(Vec4::ONE)
            & b2.cmpge(Vec4::ZERO)
            & (b1 + b2).cmple(Vec4::ONE)
            & t.cmpge(Vec4::splat(t_min))
            & t.cmple(Vec4::splat(t_max));
        (ok.bitmask(), t, b1, b2)
    }
}

/// One slab test of `node`'s first `N` lanes for a ray from `o` along `d` over
/// `[t_min, t_max]`, prepared as the sign of `t_min` requires ([`Prepared`]).
#[inline(always)]
fn slabs<const N: usize>(
    o: Vec3A,
    d: Vec3A,
    node: &Node,
    t_min: f32,
    t_max: f32,
) -> ([f32; N], u32) {
    if t_min >= 0.0 {
        Prepared::<false>::new(o, d).slabs::<N>(node, t_min, t_max)
    } else {
        Prepared::<true>::new(o, d).slabs::<N>(node, t_min, t_max)
    }
}

impl WideBvh {
    /// Builds the tree over `tris`, with two caller ids per triangle reported by its hits,
    /// using obvhs's binary builder and the given preset.
    pub(crate) fn build(tris: &[[Vec3A; 3]], ids: &[[u32; 2]], params: BvhBuildParams) -> WideBvh {
        debug_assert_eq!(tris.len(), ids.len());
        if tris.is_empty() {
            return WideBvh {
                nodes: Pages::new(Vec::new()),
                packets: Pages::new(Vec::new()),
                root: EMPTY,
            };
        }
        let bvh2 = build_bvh2(tris, params);
        let mut arrays = Arrays::default();
        let root = Collapse::new(&bvh2, tris, ids).run(&mut arrays);
        drop(bvh2);
        // Into their final home one at a time, each vector freed as soon as it is copied.
        let nodes = Pages::new(arrays.nodes);
        let packets = Pages::new(arrays.packets);
        WideBvh {
            nodes,
            packets,
            root,
        }
    }

    /// The closest triangle hit with `t` in `[t_min, t_max]`.
    #[inline]
    pub(crate) fn closest(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<WideHit> {
        with_stack(&CLOSEST_STACK, |stack| {
            if t_min >= 0.0 {
                self.closest_with::<false>(stack, o, d, t_min, t_max)
            } else {
                self.closest_with::<true>(stack, o, d, t_min, t_max)
            }
        })
    }

    /// True when any triangle is hit with `t` in `[t_min, t_max]`; stops at the first found.
    #[inline]
    pub(crate) fn any(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> bool {
        with_stack(&ANY_STACK, |stack| {
            if t_min >= 0.0 {
                self.any_with::<false>(stack, o, d, t_min, t_max)
            } else {
                self.any_with::<true>(stack, o, d, t_min, t_max)
            }
        })
    }

    /// Front-to-back traversal: of the children a ray enters, the nearest is visited next and
    /// the others are stacked with their entry distance, so a later hit can skip them.
    #[inline(always)]
    fn closest_with<const SLACK: bool>(
        &self,
        stack: &mut Vec<(u32, f32)>,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<WideHit> {
        let ray = Prepared::<SLACK>::new(o, d);
        let (nodes, packets) = (&*self.nodes, &*self.packets);
        // The packet and lane of the best hit so far, with the hit.
        let mut best: Option<(usize, usize, TriangleHit)> = None;
        let mut warm = 0u32;
        let mut t_best = t_max;
        let mut current = self.root;
        loop {
            if current & LEAF == 0 {
                let node = &nodes[current as usize];
                let (t_near, mask) = ray.slabs::<ARITY>(node, t_min, t_best);
                if mask != 0 {
                    let rest = mask & (mask - 1);
                    if rest == 0 {
                        current = node.child[mask.trailing_zeros() as usize & 7];
                        continue;
                    }
                    if rest & (rest - 1) == 0 {
                        // Exactly two: no sort, the nearer goes next and the other is stacked
                        // (the order the sort below would give, ties to the lower lane).
                        let (a, b) = (
                            mask.trailing_zeros() as usize & 7,
                            rest.trailing_zeros() as usize & 7,
                        );
                        let (ta, tb) = (t_near[a], t_near[b]);
                        let (near, far, t_far) = if tb < ta { (b, a, ta) } else { (a, b, tb) };
                        let far_child = node.child[far];
                        warm ^= touch(nodes, packets, far_child);
                        stack.push((far_child, t_far));
                        current = node.child[near];
                        continue;
                    }
                    // Three to eight children: sort them by entry distance, nearest first.
                    let mut hits = [(0u32, 0f32); ARITY];
                    let n = by_entry(mask, &t_near, |lane| node.child[lane], &mut hits);
                    for &entry in hits[1..n].iter().rev() {
                        warm ^= touch(nodes, packets, entry.0);
                        stack.push(entry);
                    }
                    current = hits[0].0;
                    continue;
                }
            } else if current != EMPTY {
                let index = (current & !LEAF) as usize;
                let packet = &packets[index];
                let (mask, t, b1, b2) = ray.triangles(packet, t_min, t_best);
                if mask != 0 {
                    let (t, b1, b2) = (t.to_array(), b1.to_array(), b2.to_array());
                    let mut m = mask;
                    while m != 0 {
                        let lane = m.trailing_zeros() as usize & 3;
                        m &= m - 1;
                        if t[lane] <= t_best {
                            t_best = t[lane];
                            best = Some((
                                index,
                                lane,
                                TriangleHit {
                                    t: t[lane],
                                    b1: b1[lane],
                                    b2: b2[lane],
                                },
                            ));
                        }
                    }
                }
            }
            // Next: the nearest stacked child not already beyond the best hit.
            loop {
                let Some((next, t_entry)) = stack.pop() else {
                    std::hint::black_box(warm);
                    return best.map(|(index, lane, tri)| hit_record(&packets[index], lane, tri));
                };
                if t_entry <= t_best {
                    current = next;
                    break;
                }
            }
        }
    }

    #[inline(always)]
    fn any_with<const SLACK: bool>(
        &self,
        stack: &mut Vec<u32>,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> bool {
        let ray = Prepared::<SLACK>::new(o, d);
        let (nodes, packets) = (&*self.nodes, &*self.packets);
        let mut warm = 0u32;
        let mut current = self.root;
        loop {
            if current & LEAF == 0 {
                let node = &nodes[current as usize];
                let (_, mut mask) = ray.slabs::<ARITY>(node, t_min, t_max);
                if mask != 0 {
                    current = node.child[mask.trailing_zeros() as usize & 7];
                    mask &= mask - 1;
                    while mask != 0 {
                        let child = node.child[mask.trailing_zeros() as usize & 7];
                        warm ^= touch(nodes, packets, child);
                        stack.push(child);
                        mask &= mask - 1;
                    }
                    continue;
                }
            } else if current != EMPTY {
                let packet = &packets[(current & !LEAF) as usize];
                if ray.triangles(packet, t_min, t_max).0 != 0 {
                    std::hint::black_box(warm);
                    return true;
                }
            }
            let Some(next) = stack.pop() else {
                std::hint::black_box(warm);
                return false;
            };
            current = next;
        }
    }

    /// Bytes held by the nodes and packets (for the memory figures).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.nodes.bytes() + self.packets.bytes()
    }
}

/// The full record of a hit on lane `lane` of packet `p`.
fn hit_record(p: &Packet, lane: usize, tri: TriangleHit) -> WideHit {
    let at = |v: &[Vec4; 3]| Vec3::new(v[0][lane], v[1][lane], v[2][lane]);
    WideHit {
        ids: [p.ids[0][lane], p.ids[1][lane]],
        tri,
        v0: at(&p.v0),
        e1: at(&p.e1),
        e2: at(&p.e2),
    }
}

/// Reads one word of each cache line of a stacked child, so its lines are on their way
/// while the nearer child is traversed (safe Rust has no prefetch instruction; loads that
/// nothing waits on do the same).
#[inline(always)]
fn touch(nodes: &[Node], packets: &[Packet], r: u32) -> u32 {
    if r & LEAF == 0 {
        nodes.get(r as usize).map_or(0, |n| {
            let b = &n.bounds;
            b[0][0].x.to_bits() ^ b[2][0].y.to_bits() ^ b[4][0].z.to_bits() ^ n.child[0]
        })
    } else {
        packets.get((r & !LEAF) as usize).map_or(0, |p| {
            p.v0[0].x.to_bits() ^ p.e1[1].y.to_bits() ^ p.e2[2].z.to_bits()
        })
    }
}

/// Up to eight boxes tested together: the top level of a scene with few instances, where a
/// tree over them would cost more than one wide node test.
#[derive(Clone, Debug)]
pub(crate) struct BoxSet {
    node: Node,
    len: usize,
}

impl BoxSet {
    /// The most boxes a set holds.
    pub(crate) const CAPACITY: usize = ARITY;

    /// A set of `boxes` (at most [`BoxSet::CAPACITY`]); `None` when there are more.
    pub(crate) fn new(boxes: &[Aabb]) -> Option<BoxSet> {
        if boxes.len() > ARITY {
            return None;
        }
        let mut node = Node::EMPTY;
        for (lane, aabb) in boxes.iter().enumerate() {
            node.set_box(lane, aabb);
            node.child[lane] = lane as u32;
        }
        Some(BoxSet {
            node,
            len: boxes.len(),
        })
    }

    /// The mask of the boxes the ray enters within `[t_min, t_max]` (bit `i` for box `i`).
    #[inline]
    pub(crate) fn entered_mask(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> u32 {
        self.test(o, d, t_min, t_max).1
    }

    /// The entry distances and the mask of the boxes entered; four boxes or fewer take one
    /// register's worth of tests, not two.
    #[inline(always)]
    pub(crate) fn test(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> ([f32; ARITY], u32) {
        let (t_near, mask) = if self.len <= WIDTH {
            let (near, mask) = slabs::<WIDTH>(o, d, &self.node, t_min, t_max);
            let mut t_near = [f32::INFINITY; ARITY];
            t_near[..WIDTH].copy_from_slice(&near);
            (t_near, mask)
        } else {
            slabs::<ARITY>(o, d, &self.node, t_min, t_max)
        };
        (t_near, mask & ((1u32 << self.len) - 1))
    }

    /// The boxes the ray enters within `[t_min, t_max]`, as (index, entry distance), nearest
    /// first, in `out`.
    #[inline]
    pub(crate) fn entered(
        &self,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
        out: &mut [(usize, f32); ARITY],
    ) -> usize {
        let (t_near, mask) = self.test(o, d, t_min, t_max);
        by_entry(mask, &t_near, |lane| lane, out)
    }
}

/// obvhs's binary BVH over `tris`, as its CWBVH builder makes it before collapsing.
fn build_bvh2(tris: &[[Vec3A; 3]], params: BvhBuildParams) -> Bvh2 {
    let input = tris
        .iter()
        .map(|&[v0, v1, v2]| Triangle { v0, v1, v2 })
        .collect::<Vec<_>>();
    let indices = (0..tris.len() as u32).collect::<Vec<_>>();
    let mut bvh2 = if params.pre_split {
        let mut aabbs = input.iter().map(Triangle::aabb).collect::<Vec<Aabb>>();
        let largest = aabbs.iter().map(Aabb::half_area).fold(0.0, f32::max);
        let average = aabbs.iter().map(Aabb::half_area).sum::<f32>() / aabbs.len() as f32;
        let mut indices = indices;
        split_aabbs_preset(&mut aabbs, &mut indices, &input, average, largest);
        let mut bvh2 = PlocBuilder::with_capacity(aabbs.len()).build(
            params.ploc_search_distance,
            &aabbs,
            indices,
            params.sort_precision,
            params.search_depth_threshold,
        );
        bvh2.uses_spatial_splits = true;
        bvh2
    } else {
        PlocBuilder::with_capacity(input.len()).build(
            params.ploc_search_distance,
            &input,
            indices,
            params.sort_precision,
            params.search_depth_threshold,
        )
    };
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2
}

/// The nodes and packets of a [`WideBvh`] as the collapse makes them.
#[derive(Default)]
struct Arrays {
    nodes: Vec<Node>,
    packets: Vec<Packet>,
}

/// The collapse of a binary BVH into [`WideBvh`] nodes and packets.
struct Collapse<'a> {
    bvh2: &'a Bvh2,
    tris: &'a [[Vec3A; 3]],
    ids: &'a [[u32; 2]],
    /// Per binary node `n`, the collapse's decisions. `choice[n][0]`: 0 makes `n` a packet,
    /// `j > 0` makes it a wide node whose eight slots take `j` from its left subtree and
    /// `8 - j` from its right. `choice[n][k - 1]` for `k >= 2`: 0 puts `n` in one slot, `j > 0`
    /// spreads `n` over `k` slots, `j` from the left subtree and `k - j` from the right.
    choice: Vec<[u8; ARITY]>,
}

/// Surface-area cost of visiting a wide node and of testing a packet, per unit of area
/// (both cost about one memory round trip of three or four cache lines plus a little SIMD).
const COST_NODE: f32 = 1.0;
const COST_PACKET: f32 = 1.0;

impl<'a> Collapse<'a> {
    fn new(bvh2: &'a Bvh2, tris: &'a [[Vec3A; 3]], ids: &'a [[u32; 2]]) -> Self {
        // Children follow their parent in preorder, so a reverse preorder sweep sums leaves up.
        let mut preorder = Vec::with_capacity(bvh2.nodes.len());
        let mut pending = vec![0u32];
        while let Some(i) = pending.pop() {
            preorder.push(i);
            let node = &bvh2.nodes[i as usize];
            if node.prim_count == 0 {
                pending.push(node.first_index);
                pending.push(node.first_index + 1);
            }
        }
        let mut count = vec![0u32; bvh2.nodes.len()];
        for &i in preorder.iter().rev() {
            let node = &bvh2.nodes[i as usize];
            count[i as usize] = if node.prim_count == 0 {
                count[node.first_index as usize] + count[node.first_index as usize + 1]
            } else {
                node.prim_count
            };
        }
        let choice = Self::plan(bvh2, &preorder, &count);
        Collapse {
            bvh2,
            tris,
            ids,
            choice,
        }
    }

    /// The optimal collapse under the surface area heuristic, by dynamic programming over the
    /// binary tree (after Ylitie et al. 2017, with four-triangle packets as leaves):
    /// `cost[n][k - 1]` is the least cost of covering `n`'s subtree with at most `k` slots of
    /// its parent, each slot a packet (subtrees of at most four triangles) or a wide node.
    fn plan(bvh2: &Bvh2, preorder: &[u32], count: &[u32]) -> Vec<[u8; ARITY]> {
        let mut cost = vec![[0f32; ARITY]; bvh2.nodes.len()];
        let mut choice = vec![[0u8; ARITY]; bvh2.nodes.len()];
        for &i in preorder.iter().rev() {
            let i = i as usize;
            let node = &bvh2.nodes[i];
            let area = node.aabb.half_area();
            let as_packet = if count[i] as usize <= WIDTH {
                area * COST_PACKET
            } else {
                f32::INFINITY
            };
            if node.prim_count != 0 {
                // A binary leaf is never opened: PLOC makes one per triangle, so it always
                // fits a packet.
                assert!(
                    node.prim_count as usize <= WIDTH,
                    "obvhs's PLOC leaves hold one primitive"
                );
                cost[i] = [as_packet; ARITY];
                continue;
            }
            let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
            // The best way to spread the two subtrees over k slots, k = 2..=8.
            let mut split = [f32::INFINITY; ARITY];
            let mut at = [0u8; ARITY];
            for k in 2..=ARITY {
                for j in 1..k {
                    let c = cost[l][j - 1] + cost[r][k - j - 1];
                    if c < split[k - 1] {
                        split[k - 1] = c;
                        at[k - 1] = j as u8;
                    }
                }
            }
            let as_node = area * COST_NODE + split[ARITY - 1];
            let single = as_packet.min(as_node);
            cost[i][0] = single;
            choice[i][0] = if as_packet <= as_node {
                0
            } else {
                at[ARITY - 1]
            };
            for k in 2..=ARITY {
                if split[k - 1] < single {
                    cost[i][k - 1] = split[k - 1];
                    choice[i][k - 1] = at[k - 1];
                } else {
                    cost[i][k - 1] = single;
                }
            }
        }
        choice
    }

    /// The binary nodes that fill `k` slots for `n`'s subtree, in tree order.
    fn slots(&self, n: u32, k: usize, out: &mut Vec<u32>) {
        let j = if k >= 2 {
            self.choice[n as usize][k - 1]
        } else {
            0
        };
        if j == 0 {
            out.push(n);
        } else {
            let first = self.bvh2.nodes[n as usize].first_index;
            self.slots(first, usize::from(j), out);
            self.slots(first + 1, k - usize::from(j), out);
        }
    }

    /// Fills `out` and returns the root's reference.
    fn run(&self, out: &mut Arrays) -> u32 {
        // Work list of (binary node, its wide node).
        let mut work = Vec::new();
        let root = self.reference(0, out, &mut work);
        while let Some((b2, wide)) = work.pop() {
            let kids = self.open(b2);
            let mut node = Node::EMPTY;
            for (lane, &kid) in kids.iter().enumerate() {
                node.set_box(lane, &self.bvh2.nodes[kid as usize].aabb);
            }
            // Children are numbered before any grandchild, so siblings sit side by side.
            let first_new = work.len();
            for (lane, &kid) in kids.iter().enumerate() {
                node.child[lane] = self.reference(kid, out, &mut work);
            }
            // Visit the first child's subtree next (depth first, for locality).
            work[first_new..].reverse();
            out.nodes[wide as usize] = node;
        }
        root
    }

    /// The reference a wide node stores for binary node `b2`: a packet for a small subtree,
    /// else a fresh wide node queued for filling.
    fn reference(&self, b2: u32, out: &mut Arrays, work: &mut Vec<(u32, u32)>) -> u32 {
        if self.choice[b2 as usize][0] == 0 {
            let packet = self.packet(b2);
            out.packets.push(packet);
            LEAF | (out.packets.len() as u32 - 1)
        } else {
            let wide = out.nodes.len() as u32;
            out.nodes.push(Node::EMPTY);
            work.push((b2, wide));
            wide
        }
    }

    /// The binary nodes that become the children of `b2`'s wide node.
    fn open(&self, b2: u32) -> Vec<u32> {
        let j = usize::from(self.choice[b2 as usize][0]);
        let first = self.bvh2.nodes[b2 as usize].first_index;
        let mut kids = Vec::with_capacity(ARITY);
        self.slots(first, j, &mut kids);
        self.slots(first + 1, ARITY - j, &mut kids);
        kids
    }

    /// The packet of the (at most four) triangles under binary node `b2`.
    fn packet(&self, b2: u32) -> Packet {
        let mut packet = Packet {
            v0: [Vec4::ZERO; 3],
            e1: [Vec4::ZERO; 3],
            e2: [Vec4::ZERO; 3],
            ids: [[EMPTY; WIDTH]; 2],
            _pad: [0; 4],
        };
        let mut lane = 0;
        let mut pending = vec![b2];
        while let Some(i) = pending.pop() {
            let node = &self.bvh2.nodes[i as usize];
            if node.prim_count == 0 {
                pending.push(node.first_index + 1);
                pending.push(node.first_index);
                continue;
            }
            let first = node.first_index as usize;
            for &prim in &self.bvh2.primitive_indices[first..first + node.prim_count as usize] {
                let [v0, v1, v2] = self.tris[prim as usize];
                let (e1, e2) = (v1 - v0, v2 - v0);
                for axis in 0..3 {
                    packet.v0[axis][lane] = v0[axis];
                    packet.e1[axis][lane] = e1[axis];
                    packet.e2[axis][lane] = e2[axis];
                }
                packet.ids[0][lane] = self.ids[prim as usize][0];
                packet.ids[1][lane] = self.ids[prim as usize][1];
                lane += 1;
            }
        }
        packet
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::intersect_triangle;

    fn soup(n: usize, seed: u32) -> Vec<[Vec3A; 3]> {
        // A small deterministic generator: the tests need no statistical quality.
        let mut state = seed.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let mut next = move || {
            state = state.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
            ((state >> 8) as f32 / (1u32 << 24) as f32) * 2.0 - 1.0
        };
        (0..n)
            .map(|_| {
                let c = Vec3A::new(next(), next(), next()) * 4.0;
                [0, 1, 2].map(|_| c + Vec3A::new(next(), next(), next()) * 0.3)
            })
            .collect()
    }

    /// Every input triangle sits in exactly one packet lane (no pre-splits), every node's lane
    /// box contains everything beneath it, and the stack bound covers the real depth.
    #[test]
    fn the_collapse_keeps_every_triangle_once_inside_its_boxes() {
        for n in [1, 2, 4, 5, 17, 300] {
            let tris = soup(n, n as u32);
            let ids = (0..n as u32).map(|i| [i, i + 1000]).collect::<Vec<_>>();
            let bvh = WideBvh::build(&tris, &ids, BvhBuildParams::medium_build());
            let mut seen = vec![0u32; n];
            let mut pending = vec![(bvh.root, None::<[f32; 6]>, 0usize)];
            let mut depth_max = 0;
            while let Some((r, bounds, depth)) = pending.pop() {
                depth_max = depth_max.max(depth);
                if r & LEAF == 0 {
                    let node = &bvh.nodes[r as usize];
                    for lane in 0..ARITY {
                        if node.child[lane] == EMPTY {
                            continue;
                        }
                        let b = node.bounds.map(|v| v[lane >> 2][lane & 3]);
                        if let Some(outer) = bounds {
                            for axis in 0..3 {
                                assert!(outer[2 * axis] <= b[2 * axis]);
                                assert!(outer[2 * axis + 1] >= b[2 * axis + 1]);
                            }
                        }
                        pending.push((node.child[lane], Some(b), depth + 1));
                    }
                } else {
                    let p = &bvh.packets[(r & !LEAF) as usize];
                    for lane in 0..WIDTH {
                        if p.ids[0][lane] == EMPTY {
                            continue;
                        }
                        let prim = p.ids[0][lane] as usize;
                        assert_eq!(p.ids[1][lane], prim as u32 + 1000);
                        seen[prim] += 1;
                        // A packet at the root (four triangles or fewer) has no box.
                        let Some(b) = bounds else { continue };
                        for corner in tris[prim] {
                            for axis in 0..3 {
                                assert!(b[2 * axis] <= corner[axis]);
                                assert!(corner[axis] <= b[2 * axis + 1]);
                            }
                        }
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "n = {n}: {seen:?}");
            if n > WIDTH {
                assert!(bvh.root & LEAF == 0, "more than one packet needs a node");
            }
        }
    }

    /// Closest and any-hit queries agree with testing every triangle, for rays from every
    /// direction, including axis-aligned ones (zero direction components).
    #[test]
    fn queries_match_testing_every_triangle() {
        // Small triangles and a few large ones, which the slow preset splits (the same
        // triangle then sits in several leaves).
        let mut tris = soup(500, 7);
        // Long slivers across the box: huge boxes around little area, what splitting is for.
        for (k, c) in soup(12, 3).iter().enumerate() {
            let a = c[0].normalize() * 4.0;
            tris.push([-a, a, a + Vec3A::splat(0.05 * (k + 1) as f32)]);
        }
        let ids = (0..tris.len() as u32).map(|i| [i, 7]).collect::<Vec<_>>();
        for params in [
            BvhBuildParams::fast_build(),
            BvhBuildParams::medium_build(),
            BvhBuildParams::slow_build(),
        ] {
            let bvh = WideBvh::build(&tris, &ids, params);
            let lanes: usize = bvh
                .packets
                .iter()
                .map(|p| p.ids[0].iter().filter(|&&i| i != EMPTY).count())
                .sum();
            // Every triangle once, or more than once where the preset splits.
            assert_eq!(lanes > tris.len(), params.pre_split, "{lanes} lanes");
            check_against_every_triangle(&tris, &bvh);
        }
    }

    /// A tree large enough for its arrays to move to huge pages answers exactly as testing
    /// every triangle does, and so does its clone.
    #[test]
    fn a_tree_on_huge_pages_answers_the_same() {
        let tris: Vec<[Vec3A; 3]> = soup(40_000, 11)
            .into_iter()
            .map(|[a, b, c]| [a, a + (b - a) * 0.1, a + (c - a) * 0.1])
            .collect();
        let ids = (0..tris.len() as u32).map(|i| [i, 7]).collect::<Vec<_>>();
        let bvh = WideBvh::build(&tris, &ids, BvhBuildParams::fast_build());
        if cfg!(target_os = "linux") {
            assert!(
                bvh.packets.is_mapped(),
                "{} bytes of packets",
                bvh.packets.bytes()
            );
        }
        check_against_every_triangle(&tris, &bvh);
        check_against_every_triangle(&tris, &bvh.clone());
    }

    fn check_against_every_triangle(tris: &[[Vec3A; 3]], bvh: &WideBvh) {
        let dirs = soup(200, 99);
        for (k, d) in dirs.iter().enumerate() {
            let o = d[0] * 3.0;
            let mut dir = d[1] - o;
            if k % 10 == 0 {
                dir = Vec3A::new(0.0, 0.0, -o.z);
            }
            // Each ray twice: from its origin, and from halfway along it with a range that
            // starts half a direction behind (the traversal with `t_min < 0`).
            for (start, t_min) in [(0.0, 0.0), (0.5, -0.5)] {
                let o = o + dir * start;
                check_ray(tris, bvh, o, dir, t_min, k);
            }
        }
    }

    /// One ray's closest and any hit against testing every triangle.
    fn check_ray(tris: &[[Vec3A; 3]], bvh: &WideBvh, o: Vec3A, dir: Vec3A, t_min: f32, k: usize) {
        let brute = tris
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                intersect_triangle(o, dir, t_min, f32::INFINITY, t).map(|h| (i as u32, h.t))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let got = bvh.closest(o, dir, t_min, f32::INFINITY);
        match (brute, got) {
            (None, None) => {}
            (Some((_, t_ref)), Some(h)) => {
                assert!(
                    (t_ref - h.tri.t).abs() <= 1e-4 * t_ref.abs().max(1.0),
                    "ray {k}, t_min {t_min}"
                );
                // The record names the triangle hit and carries it as stored.
                let [v0, v1, v2] = tris[h.ids[0] as usize];
                assert_eq!(h.ids[1], 7);
                assert_eq!(Vec3A::from(h.v0), v0);
                assert_eq!(Vec3A::from(h.e1), v1 - v0);
                assert_eq!(Vec3A::from(h.e2), v2 - v0);
                // The point from the barycentrics lies on the triangle's plane to within
                // a few roundings of its terms; along the plane the barycentrics of a
                // sliver are ill-conditioned, so it only roughly equals o + t d.
                let p = h.v0 + h.e1 * h.tri.b1 + h.e2 * h.tri.b2;
                let n = h.e1.cross(h.e2).normalize();
                let scale = h.v0.abs() + (h.e1 * h.tri.b1).abs() + (h.e2 * h.tri.b2).abs();
                let off_plane = n.dot(p - h.v0).abs();
                assert!(
                    off_plane <= 8.0 * f32::EPSILON * scale.length(),
                    "ray {k}, t_min {t_min}"
                );
                let q = Vec3::from(o + dir * h.tri.t);
                assert!(
                    (p - q).length() <= 1e-3 * q.length().max(1.0),
                    "ray {k}, t_min {t_min}: {p} vs {q}"
                );
            }
            other => panic!("ray {k}, t_min {t_min}: brute force and BVH disagree: {other:?}"),
        }
        assert_eq!(
            bvh.any(o, dir, t_min, f32::INFINITY),
            brute.is_some(),
            "ray {k}, t_min {t_min}"
        );
    }

    #[test]
    fn an_empty_tree_hits_nothing() {
        let bvh = WideBvh::build(&[], &[], BvhBuildParams::fast_build());
        let (o, d) = (Vec3A::ZERO, Vec3A::X);
        assert!(bvh.closest(o, d, 0.0, f32::INFINITY).is_none());
        assert!(!bvh.any(o, d, 0.0, f32::INFINITY));
    }

    proptest::proptest! {
        /// The four-lane slab test (a few-box top level) gives, lane for lane and bit for bit,
        /// what the eight-lane one (a BVH node) gives its first four lanes, and an unused lane
        /// is never entered: for boxes of any shape and rays in any direction, axis-parallel
        /// too, with finite and infinite `t_max`.
        #[test]
        fn slab_tests_agree_and_skip_unused_lanes(
            corners in proptest::collection::vec(proptest::array::uniform6(-8.0f32..8.0), ARITY),
            empty in proptest::collection::vec(proptest::bool::weighted(0.2), ARITY),
            o in proptest::array::uniform3(-10.0f32..10.0),
            d in proptest::array::uniform3(proptest::prop_oneof![
                -1.0f32..1.0,
                proptest::strategy::Just(0.0f32),
                proptest::strategy::Just(-0.0f32),
            ]),
            t_min in proptest::prop_oneof![0.0f32..2.0, -2.0f32..0.0],
            t_max in proptest::prop_oneof![2.0f32..30.0, proptest::strategy::Just(f32::INFINITY)],
        ) {
            let mut node = Node::EMPTY;
            for (lane, c) in corners.iter().enumerate() {
                if !empty[lane] {
                    let (a, b) = (Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5]));
                    let aabb = Aabb::new(a.min(b).into(), a.max(b).into());
                    node.set_box(lane, &aabb);
                }
            }
            let (o, d) = (Vec3A::from_array(o), Vec3A::from_array(d));
            let (t_near, mask) = slabs::<ARITY>(o, d, &node, t_min, t_max);
            let (t_near4, mask4) = slabs::<WIDTH>(o, d, &node, t_min, t_max);
            proptest::prop_assert_eq!(mask4, mask & 0xf);
            for lane in 0..WIDTH {
                if mask4 & (1 << lane) != 0 {
                    proptest::prop_assert_eq!(t_near4[lane].to_bits(), t_near[lane].to_bits());
                }
            }
            for (lane, _) in empty.iter().enumerate().filter(|(_, e)| **e) {
                proptest::prop_assert_eq!(mask & (1 << lane), 0);
            }
        }

        /// The slab test never culls a box the ray enters: rays through points on the
        /// box's twelve edges, ahead of the origin or behind it (reached with `t_min` below
        /// zero, where far distances get the slack instead of `FAR_SCALE`), are entered
        /// whenever f64 arithmetic on the same f32 inputs says the ray's range overlaps the
        /// box by more than f64's own rounding.
        #[test]
        fn slab_test_keeps_every_box_the_ray_enters(
            corner in proptest::array::uniform3(-8.0f32..8.0),
            size in proptest::array::uniform3(0.01f32..8.0),
            along in 0.0f32..1.0,
            d in proptest::array::uniform3(proptest::prop_oneof![-1.0f32..-1e-3, 1e-3f32..1.0]),
            before in proptest::prop_oneof![0.1f32..20.0, -20.0f32..-0.1],
            t_min in proptest::prop_oneof![0.0f32..0.05, -30.0f32..0.0],
            t_max in proptest::prop_oneof![20.0f32..60.0, proptest::strategy::Just(f32::INFINITY)],
        ) {
            let lo = Vec3::from_array(corner);
            let hi = lo + Vec3::from_array(size);
            let d = Vec3::from_array(d);
            let mut node = Node::EMPTY;
            node.set_box(0, &Aabb::new(lo.into(), hi.into()));
            // Eight points along each edge: one axis runs along it, the other two sit at a
            // min or a max plane.
            for edge in 0..12 {
                for step in 0..8 {
                    let axis = edge % 3;
                    let mut target = [0.0f32; 3];
                    for a in 0..3 {
                        target[a] = if a == axis {
                            lo[a] + (hi[a] - lo[a]) * ((step as f32 + along) / 8.0)
                        } else {
                            let bit = if a == (axis + 1) % 3 { (edge / 3) & 1 } else { (edge / 6) & 1 };
                            if bit == 0 { lo[a] } else { hi[a] }
                        };
                    }
                    let o = Vec3::from_array(target) - d * before;
                    let (_, mask) = slabs::<ARITY>(o.into(), d.into(), &node, t_min, t_max);

                    // The same interval in f64 from the same f32 numbers.
                    let (mut near, mut far) = (f64::from(t_min), f64::from(t_max));
                    for a in 0..3 {
                        let inv = 1.0 / f64::from(d[a]);
                        let t0 = (f64::from(lo[a]) - f64::from(o[a])) * inv;
                        let t1 = (f64::from(hi[a]) - f64::from(o[a])) * inv;
                        near = near.max(t0.min(t1));
                        far = far.min(t0.max(t1));
                    }
                    if far - near > 1e-12 * far.abs().max(near.abs()).max(1.0) {
                        proptest::prop_assert_eq!(mask & 1, 1, "near {} far {}", near, far);
                    }
                }
            }
        }
    }

    /// [`FAR_SCALE`] outweighs the rounding it must cover, in f64: a far distance computed
    /// in four roundings, scaled, is not below a near distance computed in three.
    #[test]
    fn far_scale_covers_the_rounding() {
        let u = f64::from(f32::EPSILON) * 0.5;
        let gamma = |n: f64| n * u / (1.0 - n * u);
        assert!(f64::from(FAR_SCALE) * (1.0 - gamma(4.0)) >= 1.0 + gamma(3.0));
        // And it is no bigger than it must be: one ulp less would not do.
        let smaller = f64::from(f32::from_bits(FAR_SCALE.to_bits() - 1));
        assert!(smaller * (1.0 - gamma(4.0)) < 1.0 + gamma(3.0));
    }
}
