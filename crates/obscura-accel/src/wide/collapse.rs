//! Building a [`WideBvh`]: obvhs's binary BVH, collapsed into wide nodes and leaf packets by a
//! surface-area dynamic programme.

use super::WideBvh;
use super::layout::{ARITY, EMPTY, LEAF, Node, PAIR, Packet, WIDTH};
use crate::pages::Pages;
use glam::{Vec3A, Vec4};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::PlocBuilder;
use obvhs::splits::split_aabbs_preset;
use obvhs::triangle::Triangle;

impl WideBvh {
    /// Builds the tree over `tris`, with two caller ids per triangle reported by its hits,
    /// collapsing the binary tree `binary` names.
    pub(crate) fn build(tris: &[[Vec3A; 3]], ids: &[[u32; 2]], binary: Binary) -> WideBvh {
        debug_assert_eq!(tris.len(), ids.len());
        if tris.is_empty() {
            return WideBvh {
                nodes: Pages::new(Vec::new()),
                packets: Pages::new(Vec::new()),
                root: EMPTY,
            };
        }
        let bvh2 = build_bvh2(tris, binary);
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
}

/// How the binary tree that the collapse reads is built.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Binary {
    /// obvhs's PLOC and reinsertion with the preset's settings (one triangle per leaf; large
    /// triangles split into several boxes first when the preset says so).
    Ploc(BvhBuildParams),
    /// The binned surface-area builder of `sah.rs` with `bins` bins per axis, over boxes of
    /// large triangles split as obvhs's preset splits them when `pre_split`.
    Sah { bins: usize, pre_split: bool },
}

/// The binary BVH over `tris` that `binary` names.
fn build_bvh2(tris: &[[Vec3A; 3]], binary: Binary) -> Bvh2 {
    let input = tris
        .iter()
        .map(|&[v0, v1, v2]| Triangle { v0, v1, v2 })
        .collect::<Vec<_>>();
    let mut indices = (0..tris.len() as u32).collect::<Vec<_>>();
    let pre_split = match binary {
        Binary::Ploc(params) => params.pre_split,
        Binary::Sah { pre_split, .. } => pre_split,
    };
    let mut aabbs = input.iter().map(Triangle::aabb).collect::<Vec<Aabb>>();
    if pre_split {
        let largest = aabbs.iter().map(Aabb::half_area).fold(0.0, f32::max);
        let average = aabbs.iter().map(Aabb::half_area).sum::<f32>() / aabbs.len() as f32;
        split_aabbs_preset(&mut aabbs, &mut indices, &input, average, largest);
    }
    match binary {
        Binary::Sah { bins, .. } => super::sah::build(&aabbs, &indices, bins),
        Binary::Ploc(params) => {
            let mut bvh2 = PlocBuilder::with_capacity(aabbs.len()).build(
                params.ploc_search_distance,
                &aabbs,
                indices,
                params.sort_precision,
                params.search_depth_threshold,
            );
            bvh2.uses_spatial_splits = pre_split;
            ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
            bvh2
        }
    }
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
    /// Per binary node `n`, the collapse's decisions. `choice[n][0]`: 0 makes `n` a leaf,
    /// `j > 0` makes it a wide node whose eight slots take `j` from its left subtree and
    /// `8 - j` from its right. `choice[n][k - 1]` for `k >= 2`: 0 puts `n` in one slot, `j > 0`
    /// spreads `n` over `k` slots, `j` from the left subtree and `k - j` from the right.
    choice: Vec<[u8; ARITY]>,
}

/// Surface-area cost of visiting a wide node and of testing a packet, per unit of area
/// (both cost about one memory round trip of three or four cache lines plus a little SIMD).
const COST_NODE: f32 = 1.0;
const COST_PACKET: f32 = 1.0;
/// The extra cost of a leaf's second packet: its lines follow the first's, so they come with
/// it rather than one round trip later, and what is left is its test.
const COST_SECOND_PACKET: f32 = 0.5;

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
    /// binary tree (after Ylitie et al. 2017, with leaves of one or two four-triangle packets):
    /// `cost[n][k - 1]` is the least cost of covering `n`'s subtree with at most `k` slots of
    /// its parent, each slot a leaf (a subtree of at most eight triangles) or a wide node.
    fn plan(bvh2: &Bvh2, preorder: &[u32], count: &[u32]) -> Vec<[u8; ARITY]> {
        let mut cost = vec![[0f32; ARITY]; bvh2.nodes.len()];
        let mut choice = vec![[0u8; ARITY]; bvh2.nodes.len()];
        for &i in preorder.iter().rev() {
            let i = i as usize;
            let node = &bvh2.nodes[i];
            let area = node.aabb.half_area();
            let as_packet = if count[i] as usize <= WIDTH {
                area * COST_PACKET
            } else if count[i] as usize <= 2 * WIDTH {
                area * (COST_PACKET + COST_SECOND_PACKET)
            } else {
                f32::INFINITY
            };
            if node.prim_count != 0 {
                // A binary leaf is never opened: PLOC makes one per triangle and the
                // surface-area build at most four, so it always fits a packet.
                assert!(
                    node.prim_count as usize <= WIDTH,
                    "binary leaves hold at most a packet"
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
            // Children are numbered before any grandchild, so siblings sit side by side: the
            // node's leaf packets are one run of the packet array, its child nodes one run of
            // the node array.
            let first_new = work.len();
            let (first_packet, first_node) = (out.packets.len() as u32, out.nodes.len() as u32);
            for (lane, &kid) in kids.iter().enumerate() {
                node.child[lane] = self.reference(kid, out, &mut work);
            }
            node.leaves = [first_packet, out.packets.len() as u32 - first_packet];
            node.nodes = [first_node, out.nodes.len() as u32 - first_node];
            // Visit the first child's subtree next (depth first, for locality).
            work[first_new..].reverse();
            out.nodes[wide as usize] = node;
        }
        root
    }

    /// The reference a wide node stores for binary node `b2`: a leaf of one or two packets
    /// for a small subtree, else a fresh wide node queued for filling.
    fn reference(&self, b2: u32, out: &mut Arrays, work: &mut Vec<(u32, u32)>) -> u32 {
        if self.choice[b2 as usize][0] == 0 {
            let first = out.packets.len() as u32;
            self.packets(b2, &mut out.packets);
            let pair = if out.packets.len() as u32 - first == 2 {
                PAIR
            } else {
                0
            };
            LEAF | pair | first
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

    /// Appends to `out` the packets of the (at most eight) triangles under binary node `b2`:
    /// the first four in tree order, then the rest.
    fn packets(&self, b2: u32, out: &mut Vec<Packet>) {
        const EMPTY_PACKET: Packet = Packet {
            v0: [Vec4::ZERO; 3],
            e1: [Vec4::ZERO; 3],
            e2: [Vec4::ZERO; 3],
            ids: [[EMPTY; WIDTH]; 2],
            _pad: [0; 4],
        };
        let mut packet = EMPTY_PACKET;
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
                if lane == WIDTH {
                    out.push(packet);
                    packet = EMPTY_PACKET;
                    lane = 0;
                }
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
        out.push(packet);
    }
}
