//! The memory layout of the wide BVH: eight-child nodes and four-triangle leaf packets, each
//! in structure-of-arrays form (one SIMD lane per child or triangle) and aligned to cache lines.

use glam::Vec4;
use obvhs::aabb::Aabb;

/// Set in a child reference that names a leaf rather than a node.
pub(super) const LEAF: u32 = 1 << 31;
/// Set in a leaf's reference when the leaf is two packets, the one named and the next.
pub(super) const PAIR: u32 = 1 << 30;
/// The bits of a leaf's reference that name its (first) packet.
pub(super) const INDEX: u32 = !(LEAF | PAIR);
/// The child reference of an unused lane (its box is empty, so it is never entered).
pub(super) const EMPTY: u32 = u32::MAX;
/// Children per node: two SIMD registers' worth.
pub(super) const ARITY: usize = 8;
/// Triangles per leaf packet (the SIMD width).
pub(super) const WIDTH: usize = 4;
/// Eight children's boxes, one lane per child (children 0-3 in the first register, 4-7 in
/// the second), what each child is, and where its children's data sits: 240 bytes, padded to
/// the four cache lines it would take anyway, and aligned to start a line so it never takes
/// five.
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(64))]
pub(super) struct Node {
    /// `[min_x, max_x, min_y, max_y, min_z, max_z]`; an unused lane has min +inf, max -inf.
    pub(super) bounds: [[Vec4; 2]; 6],
    /// A node index, `LEAF | packet index` (with [`PAIR`] for a leaf of that packet and the
    /// next), or `EMPTY`.
    pub(super) child: [u32; ARITY],
    /// The first packet of the node's leaf children and how many packets they hold (they
    /// sit side by side), so a visit can ask for them before its box test has chosen.
    pub(super) leaves: [u32; 2],
    /// The first of the node's child nodes and how many there are (side by side as well).
    pub(super) nodes: [u32; 2],
    /// Explicit padding to 256 bytes, so a node is plain bytes ([`Pages`] maps it).
    pub(super) _pad: [u32; 4],
}

impl Node {
    /// A node with every lane unused (empty boxes, so no ray enters them).
    pub(super) const EMPTY: Node = Node {
        bounds: [
            [Vec4::INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
            [Vec4::INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
            [Vec4::INFINITY; 2],
            [Vec4::NEG_INFINITY; 2],
        ],
        child: [EMPTY; ARITY],
        leaves: [0; 2],
        nodes: [0; 2],
        _pad: [0; 4],
    };

    /// Puts `aabb` in lane `lane`.
    pub(super) fn set_box(&mut self, lane: usize, aabb: &Aabb) {
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
pub(super) struct Packet {
    pub(super) v0: [Vec4; 3],
    pub(super) e1: [Vec4; 3],
    pub(super) e2: [Vec4; 3],
    /// The caller's two ids of the triangle in each lane (padding lanes are degenerate and
    /// never hit): a hit is reported without touching any other array.
    pub(super) ids: [[u32; WIDTH]; 2],
    /// Explicit padding to 192 bytes, so a packet is plain bytes ([`Pages`] maps it).
    pub(super) _pad: [u32; 4],
}
