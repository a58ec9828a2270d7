//! The queries: front-to-back closest hit and any hit, each over a per-thread stack.

use super::batch::{BatchRay, One};
use super::layout::{ARITY, EMPTY, INDEX, LEAF, Node, PAIR, Packet};
use super::ray::{Level, Prepared, by_entry, dispatch};
use super::stack::Stack;
use super::{WideBvh, WideHit};
use crate::geom::TriangleHit;
use crate::simd::{prefetch, prefetch_items};
use glam::{Vec3, Vec3A, Vec4};
use std::cell::Cell;

/// A thread's kept stack: taken for a query and put back after it.
type Kept<T> = Cell<Option<Box<Stack<T>>>>;

thread_local! {
    /// Each thread's traversal stacks, kept between queries so a query neither allocates nor
    /// fills a fixed array.
    static CLOSEST_STACK: Kept<(u32, f32)> = const { Cell::new(None) };
    static ANY_STACK: Kept<u32> = const { Cell::new(None) };
}

/// This thread's stack from `key`, emptied. It is taken, not borrowed, so a nested query (none
/// today) would simply get a fresh one; [`keep`] hands it back. The queries run between the
/// two rather than in a closure given to the thread-local's `with`: code that
/// [`Avx2::run`] compiles for AVX2 must be inlined into it, and a large closure called from
/// more than one place may not be.
#[inline(always)]
fn take<T: Copy + Default>(key: &'static std::thread::LocalKey<Kept<T>>) -> Box<Stack<T>> {
    let mut stack = key.with(Cell::take).unwrap_or_default();
    stack.clear();
    stack
}

/// Hands a stack from [`take`] back to this thread's `key` for the next query.
#[inline(always)]
fn keep<T>(key: &'static std::thread::LocalKey<Kept<T>>, stack: Box<Stack<T>>) {
    key.with(|cell| cell.set(Some(stack)));
}

impl WideBvh {
    /// The closest triangle hit with `t` in `[t_min, t_max]`, compiled for AVX2 when the CPU
    /// has it ([`Avx2`]).
    #[inline]
    pub(crate) fn closest(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<WideHit> {
        dispatch(One::<Closest<false>>::new(
            self,
            BatchRay { o, d, t_min, t_max },
        ))
    }

    /// True when any triangle is hit with `t` in `[t_min, t_max]`; stops at the first found.
    /// Compiled for AVX2 when the CPU has it, as [`closest`](WideBvh::closest) is.
    #[inline]
    pub(crate) fn any(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> bool {
        dispatch(One::<Any<false>>::new(
            self,
            BatchRay { o, d, t_min, t_max },
        ))
    }

    /// [`closest`](WideBvh::closest) with the box test of `level` on this thread's stack, its
    /// traversal chosen once: the box test the sign of `t_min` needs ([`Prepared`]), and
    /// whether each visit asks below ([`ask_below`]; tests ask on trees of any size, since
    /// asking ahead must never change an answer).
    #[inline(always)]
    pub(super) fn closest_in<L: Level>(
        &self,
        level: L,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
        below: bool,
    ) -> Option<WideHit> {
        let mut stack = take(&CLOSEST_STACK);
        let s = &mut stack;
        let hit = match (t_min >= 0.0, below) {
            (true, false) => self.closest_with::<false, false, L>(level, s, o, d, t_min, t_max),
            (true, true) => self.closest_with::<false, true, L>(level, s, o, d, t_min, t_max),
            (false, false) => self.closest_with::<true, false, L>(level, s, o, d, t_min, t_max),
            (false, true) => self.closest_with::<true, true, L>(level, s, o, d, t_min, t_max),
        };
        keep(&CLOSEST_STACK, stack);
        hit
    }

    /// [`any`](WideBvh::any) with the box test of `level`, chosen as
    /// [`closest_in`](WideBvh::closest_in) is.
    #[inline(always)]
    pub(super) fn any_in<L: Level>(
        &self,
        level: L,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
        below: bool,
    ) -> bool {
        let mut stack = take(&ANY_STACK);
        let s = &mut stack;
        let answer = match (t_min >= 0.0, below) {
            (true, false) => self.any_with::<false, false, L>(level, s, o, d, t_min, t_max),
            (true, true) => self.any_with::<false, true, L>(level, s, o, d, t_min, t_max),
            (false, false) => self.any_with::<true, false, L>(level, s, o, d, t_min, t_max),
            (false, true) => self.any_with::<true, true, L>(level, s, o, d, t_min, t_max),
        };
        keep(&ANY_STACK, stack);
        answer
    }

    /// Whether a one-ray query asks for a node's leaf packets and first child node at its
    /// visit ([`ask_below`]): only on a tree of [`ASK_BELOW_MIN_BYTES`] or more.
    #[inline(always)]
    pub(super) fn asks_below(&self) -> bool {
        self.heap_bytes() >= ASK_BELOW_MIN_BYTES
    }

    #[inline(always)]
    fn closest_with<const SLACK: bool, const BELOW: bool, L: Level>(
        &self,
        level: L,
        stack: &mut Stack<(u32, f32)>,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<WideHit> {
        let (nodes, packets) = (&*self.nodes, &*self.packets);
        let mut q = Closest::<SLACK>::new(self.root, o, d, t_min, t_max);
        while q.step::<true, BELOW, L>(level, nodes, packets, stack) {}
        q.hit(packets)
    }

    #[inline(always)]
    fn any_with<const SLACK: bool, const BELOW: bool, L: Level>(
        &self,
        level: L,
        stack: &mut Stack<u32>,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> bool {
        let (nodes, packets) = (&*self.nodes, &*self.packets);
        let mut q = Any::<SLACK>::new(self.root, o, d, t_min, t_max);
        loop {
            match q.step::<true, BELOW, L>(level, nodes, packets, stack) {
                Step::Next => {}
                Step::Hit => break true,
                Step::Done => break false,
            }
        }
    }
}

/// A closest-hit query under way: where it is, and the best hit so far.
pub(super) struct Closest<const SLACK: bool> {
    ray: Prepared<SLACK>,
    t_min: f32,
    t_best: f32,
    /// The node or packet the next step visits.
    pub(super) current: u32,
    /// The packet and lane of the best hit so far, with the hit.
    best: Option<(usize, usize, TriangleHit)>,
}

impl<const SLACK: bool> Closest<SLACK> {
    /// A query from `root` for the ray from `o` along `d` over `[t_min, t_max]`.
    #[inline(always)]
    pub(super) fn new(root: u32, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Self {
        Closest {
            ray: Prepared::<SLACK>::new(o, d),
            t_min,
            t_best: t_max,
            current: root,
            best: None,
        }
    }

    /// One step of front-to-back traversal: the box test of the node the query is at (of
    /// the children it enters, the nearest is visited next and the others are stacked with
    /// their entry distance, so a later hit can skip them) or the triangle test of the
    /// packet; then where to go next. False when there is nowhere left to go. `AHEAD`: ask
    /// for the lines of each stacked child ([`ask`]), so they load in the meantime (a batch
    /// asks for each ray's next visit instead). `BELOW`: ask for a node's leaf packets and
    /// first child node before its box test runs ([`ask_below`]).
    #[inline(always)]
    pub(super) fn step<const AHEAD: bool, const BELOW: bool, L: Level>(
        &mut self,
        level: L,
        nodes: &[Node],
        packets: &[Packet],
        stack: &mut Stack<(u32, f32)>,
    ) -> bool {
        let current = self.current;
        if current & LEAF == 0 {
            let node = &nodes[current as usize];
            if BELOW {
                ask_below(nodes, packets, node);
            }
            let (t_near, mask) = level.slabs(&self.ray, node, self.t_min, self.t_best);
            if mask != 0 {
                let rest = mask & (mask - 1);
                if rest == 0 {
                    self.current = node.child[mask.trailing_zeros() as usize & 7];
                    return true;
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
                    if AHEAD {
                        ask(nodes, packets, far_child);
                    }
                    stack.push((far_child, t_far));
                    self.current = node.child[near];
                    return true;
                }
                // Three to eight children: sort them by entry distance, nearest first.
                let mut hits = [(0u32, 0f32); ARITY];
                let n = by_entry(mask, &t_near, |lane| node.child[lane], &mut hits);
                for &entry in hits[1..n].iter().rev() {
                    if AHEAD {
                        ask(nodes, packets, entry.0);
                    }
                    stack.push(entry);
                }
                self.current = hits[0].0;
                return true;
            }
        } else if current != EMPTY {
            for index in leaf_packets(current) {
                let packet = &packets[index];
                let (mask, t, b1, b2) = self.ray.triangles(packet, self.t_min, self.t_best);
                if mask != 0 {
                    let (t, b1, b2) = (t.to_array(), b1.to_array(), b2.to_array());
                    let mut m = mask;
                    while m != 0 {
                        let lane = m.trailing_zeros() as usize & 3;
                        m &= m - 1;
                        if t[lane] <= self.t_best {
                            self.t_best = t[lane];
                            self.best = Some((
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
        }
        // Next: the nearest stacked child not already beyond the best hit.
        loop {
            let Some((next, t_entry)) = stack.pop() else {
                return false;
            };
            if t_entry <= self.t_best {
                self.current = next;
                return true;
            }
        }
    }

    /// The hit found, once [`step`](Closest::step) has returned false.
    #[inline(always)]
    pub(super) fn hit(&self, packets: &[Packet]) -> Option<WideHit> {
        self.best
            .map(|(index, lane, tri)| hit_record(&packets[index], lane, tri))
    }
}

/// What an any-hit step found.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Step {
    /// Go on: the query has somewhere left to go.
    Next,
    /// A triangle is hit: the query's answer is true.
    Hit,
    /// Nowhere left to go and nothing hit.
    Done,
}

/// An any-hit query under way.
pub(super) struct Any<const SLACK: bool> {
    ray: Prepared<SLACK>,
    t_min: f32,
    t_max: f32,
    /// The node or packet the next step visits.
    pub(super) current: u32,
}

impl<const SLACK: bool> Any<SLACK> {
    /// A query from `root` for the ray from `o` along `d` over `[t_min, t_max]`.
    #[inline(always)]
    pub(super) fn new(root: u32, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Self {
        Any {
            ray: Prepared::<SLACK>::new(o, d),
            t_min,
            t_max,
            current: root,
        }
    }

    /// One step: a node's entered children are stacked in lane order (any order will do),
    /// or a packet's triangles tested; then where to go next. `AHEAD` and `BELOW` as for
    /// [`Closest`].
    #[inline(always)]
    pub(super) fn step<const AHEAD: bool, const BELOW: bool, L: Level>(
        &mut self,
        level: L,
        nodes: &[Node],
        packets: &[Packet],
        stack: &mut Stack<u32>,
    ) -> Step {
        let current = self.current;
        if current & LEAF == 0 {
            let node = &nodes[current as usize];
            if BELOW {
                ask_below(nodes, packets, node);
            }
            let (_, mut mask) = level.slabs(&self.ray, node, self.t_min, self.t_max);
            if mask != 0 {
                self.current = node.child[mask.trailing_zeros() as usize & 7];
                mask &= mask - 1;
                while mask != 0 {
                    let child = node.child[mask.trailing_zeros() as usize & 7];
                    if AHEAD {
                        ask(nodes, packets, child);
                    }
                    stack.push(child);
                    mask &= mask - 1;
                }
                return Step::Next;
            }
        } else if current != EMPTY {
            for index in leaf_packets(current) {
                if self
                    .ray
                    .triangles(&packets[index], self.t_min, self.t_max)
                    .0
                    != 0
                {
                    return Step::Hit;
                }
            }
        }
        match stack.pop() {
            Some(next) => {
                self.current = next;
                Step::Next
            }
            None => Step::Done,
        }
    }
}

/// The packets of the leaf `r` names: one, or two side by side.
#[inline(always)]
fn leaf_packets(r: u32) -> std::ops::RangeInclusive<usize> {
    let first = (r & INDEX) as usize;
    first..=first + usize::from(r & PAIR != 0)
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

/// Packets of a node's leaf children asked for at its visit, at most (twelve lines).
const BELOW_PACKETS: u32 = 4;

/// The smallest tree whose one-ray queries ask for what lies below a node at its visit
/// ([`ask_below`]). On a tree that stays in the caches between rays the prefetches only
/// cost; measured on a host with 2 MB of L2 and a shared L3, trees of 7-19 MB lost 2-18% and
/// trees of 60-75 MB gained 5-20% (docs/performance.md).
const ASK_BELOW_MIN_BYTES: usize = 32 << 20;

/// Asks for the lines a visit to `node` is likely to need next, before its box test has
/// chosen: the packets of its leaf children (up to [`BELOW_PACKETS`]) and its first child
/// node. The box test and the branches on its outcome then overlap their arrival.
#[inline(always)]
fn ask_below(nodes: &[Node], packets: &[Packet], node: &Node) {
    let [first, count] = node.leaves;
    if count != 0
        && let Some(packet) = packets.get(first as usize)
    {
        prefetch_items::<_, { size_of::<Packet>() / 64 }, { BELOW_PACKETS as usize }>(
            packet,
            count as usize,
        );
    }
    let [first, count] = node.nodes;
    if count != 0
        && let Some(child) = nodes.get(first as usize)
    {
        prefetch(child, size_of::<Node>() / 64 - 1);
    }
}

/// Asks for the lines of the node or leaf (one packet or two) `r` names: a prefetch, which
/// never changes a result and, unlike a load, does not hold up the instructions behind it
/// while the lines come.
#[inline(always)]
pub(super) fn ask(nodes: &[Node], packets: &[Packet], r: u32) {
    if r & LEAF == 0 {
        if let Some(node) = nodes.get(r as usize) {
            prefetch(node, size_of::<Node>() / 64 - 1);
        }
    } else if let Some(packet) = packets.get((r & INDEX) as usize) {
        let count = 1 + usize::from(r & PAIR != 0);
        prefetch(packet, count * size_of::<Packet>() / 64 - 1);
    }
}
