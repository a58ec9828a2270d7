//! The top level of a scene with few instances: up to eight boxes tested together.

use super::layout::{ARITY, Node, WIDTH};
use super::ray::{by_entry, slabs};
use glam::Vec3A;
use obvhs::aabb::Aabb;

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
