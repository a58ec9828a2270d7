//! The triangle BVH: built, laid out for SIMD and traversed.
//!
//! A binary BVH is built top down by binned surface area, each side of a split charged by the
//! four-triangle packets it fills so that subtrees come in multiples of four (`sah.rs`), or by
//! obvhs's PLOC and reinsertion for the fast preset ([`Binary`]); it is collapsed here into nodes of up to eight children whose boxes sit in structure-of-arrays
//! form, one lane per child, so one ray tests eight boxes in two registers' worth of SSE
//! instructions (written on glam's `Vec4`, four lanes to a register, with the ray's values
//! kept splatted so a batch reloads them without shuffles). Leaves are one or two *packets* of
//! up to four triangles (their first vertices and edges, again one lane per triangle), each
//! tested by a four-wide Möller–Trumbore; a leaf's two packets sit side by side, so their lines
//! arrive together. Which binary nodes become a wide node's children and which subtrees become
//! leaves is chosen by a surface-area dynamic programme over the whole binary
//! tree (`Collapse::plan`).
//!
//! Why not obvhs's own traversal: its compressed wide BVH (CWBVH) unpacks eight quantised child
//! boxes per node and tests leaf triangles one at a time (docs/performance.md has the profile).
//! A traversal over a 1M-triangle mesh waits on memory at nearly every node it visits, one
//! miss after another, so the wide nodes (half the depth of a four-wide tree) matter most;
//! nodes and packets are aligned to cache lines so none straddles one line more than it must,
//! and the lines of the children a ray will visit later are prefetched when they are stacked,
//! so they load in the meantime. On a tree too large for the caches, a query also asks for a
//! node's leaf packets and first child node as soon as it reaches the node, before its box
//! test has chosen among them. Large arrays live on transparent huge pages ([`Pages`]), so
//! the visits are not also TLB misses.
//!
//! A batch of rays on a large tree is traversed in turns (`batch.rs`): eight rays in flight,
//! each taking one step and asking for the lines of its next node before the next ray's step,
//! so that the rays' cache misses overlap instead of following one another.
//!
//! The files: `layout.rs` (nodes and packets), `sah.rs` (the binary build), `collapse.rs` (the
//! collapse), `ray.rs` (the slab and triangle tests), `traverse.rs` (the queries, one step at a
//! time), `batch.rs` (batches in turns), `boxset.rs` (a top level of few boxes), `stack.rs`
//! (the traversal stack).
//!
//! Everything here is safe Rust: the lanes are glam's `Vec4` (an SSE register on x86-64); the
//! one prefetch instruction is in the crate's `simd` module.

mod batch;
mod boxset;
mod collapse;
mod layout;
mod ray;
mod sah;
mod stack;
mod traverse;

pub(crate) use batch::BatchRay;
pub(crate) use boxset::BoxSet;
pub(crate) use collapse::Binary;

use crate::geom::TriangleHit;
use crate::pages::Pages;
use glam::Vec3;
use layout::{Node, Packet};

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

impl WideBvh {
    /// Bytes held by the nodes and packets (for the memory figures).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.nodes.bytes() + self.packets.bytes()
    }
}

#[cfg(test)]
mod tests;
