//! The queries: front-to-back closest hit and any hit, each over a per-thread stack.

use super::layout::{ARITY, EMPTY, LEAF, Node, Packet};
use super::ray::{Prepared, by_entry};
use super::{WideBvh, WideHit};
use crate::geom::TriangleHit;
use glam::{Vec3, Vec3A, Vec4};
use std::cell::Cell;

thread_local! {
    /// Each thread's traversal stacks, kept between queries so a query neither allocates nor
    /// clears a fixed array.
    static CLOSEST_STACK: Cell<Vec<(u32, f32)>> = const { Cell::new(Vec::new()) };
    static ANY_STACK: Cell<Vec<u32>> = const { Cell::new(Vec::new()) };
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

impl WideBvh {
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
