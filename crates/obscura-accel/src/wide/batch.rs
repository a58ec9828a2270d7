//! Batch queries: several rays traversed in turns, so that their cache misses overlap.
//!
//! A query on a large mesh waits on memory at nearly every node it visits, one dependent miss
//! after another, and one query's out-of-order window is too short to overlap them. A batch
//! keeps [`LANES`] rays in flight: each takes one step (a node's box test or a packet's
//! triangle test), asks for the lines of the node or packet it will visit next ([`ask`], a
//! prefetch), and yields to the next ray, so by the time a ray's turn comes round again its
//! lines have had the other rays' steps to arrive. A ray that finishes hands its lane to
//! the next ray of the batch.
//!
//! Each ray takes exactly the steps of the one-ray query ([`Closest::step`], [`Any::step`],
//! shared with it), so every answer equals what [`WideBvh::closest`] or [`WideBvh::any`]
//! gives for that ray.

use super::layout::{Node, Packet};
use super::ray::{Level, OnLevel, dispatch};
use super::stack::Stack;
use super::traverse::{Any, Closest, Step, ask};
use super::{WideBvh, WideHit};
use glam::Vec3A;

/// Rays in flight at once.
pub(crate) const LANES: usize = 8;

/// The smallest tree whose batches take turns between rays: above a core's L2 (512 KiB to
/// 2 MiB on current x86-64) with room to spare. On the terrain of the mesh comparison scene,
/// turns cost time at 0.7 MB of tree and paid from about 3 MB (docs/performance.md).
pub(crate) const INTERLEAVE_MIN_BYTES: usize = 4 << 20;

/// One ray of a batch query: origin, direction and its range.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BatchRay {
    pub o: Vec3A,
    pub d: Vec3A,
    pub t_min: f32,
    pub t_max: f32,
}

/// A query that can take turns with others ([`WideBvh::run`]). Its implementations are
/// `#[inline(always)]`, so that inside [`Avx2::run`] they are compiled for AVX2 too.
pub(super) trait InTurns: Sized {
    /// What the query answers for a ray.
    type Answer;
    /// An entry of its traversal stack.
    type Entry: Copy + Default;
    /// The query of a ray with `t_min >= 0` from the tree's root.
    fn new(root: u32, r: &BatchRay) -> Self;
    /// The one-ray query's answer, with the box test of `level`.
    fn one<L: Level>(bvh: &WideBvh, level: L, r: &BatchRay) -> Self::Answer;
    /// One step with the box test of `level`; the answer once the query has one.
    fn advance<L: Level>(
        &mut self,
        level: L,
        nodes: &[Node],
        packets: &[Packet],
        stack: &mut Stack<Self::Entry>,
    ) -> Option<Self::Answer>;
    /// The node or packet the query visits next.
    fn at(&self) -> u32;
}

impl InTurns for Closest<false> {
    type Answer = Option<WideHit>;
    type Entry = (u32, f32);
    #[inline(always)]
    fn new(root: u32, r: &BatchRay) -> Self {
        Closest::new(root, r.o, r.d, r.t_min, r.t_max)
    }
    #[inline(always)]
    fn one<L: Level>(bvh: &WideBvh, level: L, r: &BatchRay) -> Self::Answer {
        bvh.closest_in(level, r.o, r.d, r.t_min, r.t_max, bvh.asks_below())
    }
    #[inline(always)]
    fn advance<L: Level>(
        &mut self,
        level: L,
        nodes: &[Node],
        packets: &[Packet],
        stack: &mut Stack<Self::Entry>,
    ) -> Option<Self::Answer> {
        (!self.step::<false, false, L>(level, nodes, packets, stack)).then(|| self.hit(packets))
    }
    #[inline(always)]
    fn at(&self) -> u32 {
        self.current
    }
}

impl InTurns for Any<false> {
    type Answer = bool;
    type Entry = u32;
    #[inline(always)]
    fn new(root: u32, r: &BatchRay) -> Self {
        Any::new(root, r.o, r.d, r.t_min, r.t_max)
    }
    #[inline(always)]
    fn one<L: Level>(bvh: &WideBvh, level: L, r: &BatchRay) -> Self::Answer {
        bvh.any_in(level, r.o, r.d, r.t_min, r.t_max, bvh.asks_below())
    }
    #[inline(always)]
    fn advance<L: Level>(
        &mut self,
        level: L,
        nodes: &[Node],
        packets: &[Packet],
        stack: &mut Stack<Self::Entry>,
    ) -> Option<Self::Answer> {
        match self.step::<false, false, L>(level, nodes, packets, stack) {
            Step::Next => None,
            Step::Hit => Some(true),
            Step::Done => Some(false),
        }
    }
    #[inline(always)]
    fn at(&self) -> u32 {
        self.current
    }
}

impl WideBvh {
    /// The closest hit of each ray, `out[i]` for `rays[i]`, each exactly as
    /// [`closest`](WideBvh::closest) finds it. `out` is as long as `rays`.
    pub(crate) fn closest_batch(&self, rays: &[BatchRay], out: &mut [Option<WideHit>]) {
        self.batch::<Closest<false>>(rays, out);
    }

    /// Whether each ray hits anything, `out[i]` for `rays[i]`, each exactly as
    /// [`any`](WideBvh::any) answers it. `out` is as long as `rays`.
    pub(crate) fn any_batch(&self, rays: &[BatchRay], out: &mut [bool]) {
        self.batch::<Any<false>>(rays, out);
    }

    /// The batch compiled for AVX2 when the CPU has it, as the one-ray queries are: the CPU
    /// is asked once per batch, not once per ray.
    fn batch<Q: InTurns>(&self, rays: &[BatchRay], out: &mut [Q::Answer]) {
        dispatch(Batch::<Q>(self, rays, out));
    }

    /// In turns on a large tree, one ray after another on a small one, with the box test of
    /// `level`.
    #[inline(always)]
    fn batch_on<Q: InTurns, L: Level>(&self, level: L, rays: &[BatchRay], out: &mut [Q::Answer]) {
        if self.interleaves() {
            self.run::<Q, L>(level, rays, out);
        } else {
            for (r, o) in rays.iter().zip(out) {
                *o = Q::one(self, level, r);
            }
        }
    }

    /// Whether a batch takes turns between rays: only for a tree too large for the caches
    /// nearest the core, where the turns hide misses. A smaller tree's lines are mostly at
    /// hand, and taking turns would only add the switching; its batch runs one ray after
    /// another ([`INTERLEAVE_MIN_BYTES`]).
    pub(crate) fn interleaves(&self) -> bool {
        self.heap_bytes() >= INTERLEAVE_MIN_BYTES
    }

    /// The batch loop, in turns whatever the tree's size, with the box test of `level`: each
    /// ray's query starts ([`InTurns::new`]), steps and asks for its next node's lines in
    /// turn with the others, and hands its lane to the next ray when it has its answer.
    #[inline(always)]
    pub(super) fn run<Q: InTurns, L: Level>(
        &self,
        level: L,
        rays: &[BatchRay],
        out: &mut [Q::Answer],
    ) {
        let (nodes, packets) = (&*self.nodes, &*self.packets);
        let mut flights: Vec<Flight<Q>> = Vec::with_capacity(LANES);
        let mut slots = 0..rays.len().min(out.len());
        while flights.len() < LANES {
            match self.next_in_turns::<Q, L>(level, rays, &mut slots, out) {
                Some(slot) => flights.push((Q::new(self.root, &rays[slot]), slot, Stack::new())),
                None => break,
            }
        }
        while !flights.is_empty() {
            let mut i = 0;
            while i < flights.len() {
                let (q, slot, stack) = &mut flights[i];
                let Some(answer) = q.advance(level, nodes, packets, stack) else {
                    ask(nodes, packets, q.at());
                    i += 1;
                    continue;
                };
                out[*slot] = answer;
                // The lane's next ray takes over its query and its (emptied) stack in place.
                match self.next_in_turns::<Q, L>(level, rays, &mut slots, out) {
                    Some(fresh) => {
                        *q = Q::new(self.root, &rays[fresh]);
                        *slot = fresh;
                        stack.clear();
                        i += 1;
                    }
                    None => {
                        flights.swap_remove(i);
                    }
                }
            }
        }
    }
}

impl WideBvh {
    /// The slot of the next ray of `slots` that takes turns, answering the others on the way:
    /// a ray that may start behind its origin has the other box test, so it takes the one-ray
    /// query. Only the slot is handed back, so that the lane's query is made in place rather
    /// than made elsewhere and copied in (it holds its prepared ray: hundreds of bytes). A
    /// function, not a closure, so that it is always inlined ([`crate::simd::WithAvx2`]).
    #[inline(always)]
    fn next_in_turns<Q: InTurns, L: Level>(
        &self,
        level: L,
        rays: &[BatchRay],
        slots: &mut std::ops::Range<usize>,
        out: &mut [Q::Answer],
    ) -> Option<usize> {
        for slot in slots.by_ref() {
            let r = &rays[slot];
            if r.t_min >= 0.0 {
                return Some(slot);
            }
            out[slot] = Q::one(self, level, r);
        }
        None
    }
}

/// One ray's query `Q` ([`InTurns::one`]), for [`dispatch`].
pub(super) struct One<'a, Q> {
    bvh: &'a WideBvh,
    ray: BatchRay,
    query: std::marker::PhantomData<Q>,
}

impl<'a, Q> One<'a, Q> {
    /// The query `Q` of `ray` in `bvh`.
    #[inline(always)]
    pub(super) fn new(bvh: &'a WideBvh, ray: BatchRay) -> Self {
        One {
            bvh,
            ray,
            query: std::marker::PhantomData,
        }
    }
}

impl<Q: InTurns> OnLevel for One<'_, Q> {
    type Output = Q::Answer;
    #[inline(always)]
    fn on<L: Level>(self, level: L) -> Q::Answer {
        Q::one(self.bvh, level, &self.ray)
    }
}

/// A batch of query `Q`, its rays and where their answers go, for [`dispatch`].
struct Batch<'a, Q: InTurns>(&'a WideBvh, &'a [BatchRay], &'a mut [Q::Answer]);

impl<Q: InTurns> OnLevel for Batch<'_, Q> {
    type Output = ();
    #[inline(always)]
    fn on<L: Level>(self, level: L) {
        let Batch(bvh, rays, out) = self;
        bvh.batch_on::<Q, L>(level, rays, out);
    }
}

/// A ray's query in flight: the query, the ray's slot, and its stack.
type Flight<Q> = (Q, usize, Stack<<Q as InTurns>::Entry>);
