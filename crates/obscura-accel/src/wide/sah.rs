//! A top-down binned surface-area builder for the binary tree the collapse reads (after Wald
//! 2007, "On fast construction of SAH-based bounding volume hierarchies"), with each side of a
//! split charged by the four-triangle packets it will fill rather than by its triangles.
//!
//! The wide tree's leaves are packets of four triangles, so a subtree of five triangles costs
//! two packet tests where one of four costs one. Charging each side of a split
//! `area * ceil(n / 4)` (as Embree's builders do with their block size) puts the binary tree's
//! subtree sizes on multiples of four wherever the geometry allows, and the collapse then
//! finds full packets to make leaves of.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::node::Bvh2Node;

/// The most centroid bins a split may use per axis.
const MAX_BINS: usize = 64;
/// Triangles per packet: the unit each side of a split is charged in.
const BLOCK: u32 = 4;
/// A range of at most this many boxes becomes a leaf of the binary tree (the collapse may
/// still merge two such leaves into one two-packet leaf).
const MAX_LEAF: usize = 4;

/// A bin: the box of the boxes whose centroids fall in it, the box of those centroids, and
/// how many there are.
#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    centroids: Aabb,
    count: u32,
}

impl Bin {
    const EMPTY: Bin = Bin {
        bounds: Aabb::INVALID,
        centroids: Aabb::INVALID,
        count: 0,
    };

    fn add(&mut self, other: &Bin) {
        self.bounds = self.bounds.union(&other.bounds);
        self.centroids = self.centroids.union(&other.centroids);
        self.count += other.count;
    }

    /// Counts the box `bounds`, whose centroid is `center`, in this bin.
    fn insert(&mut self, bounds: &Aabb, center: Vec3A) {
        self.bounds = self.bounds.union(bounds);
        self.centroids.extend(center);
        self.count += 1;
    }

    /// The bin of the boxes in `range`.
    fn of(range: &[u32], aabbs: &[Aabb], centers: &[Vec3A]) -> Bin {
        range.iter().fold(Bin::EMPTY, |mut bin, &i| {
            bin.insert(&aabbs[i as usize], centers[i as usize]);
            bin
        })
    }
}

/// The surface-area cost of one side of a split: its box's area times the packets it fills.
fn side_cost(side: &Bin) -> f32 {
    side.bounds.half_area() * side.count.div_ceil(BLOCK) as f32
}

/// A node still to be filled: its slot in the node array, its range of box indices, and the
/// bin of that range (its bounds and centroid bounds).
struct Pending {
    slot: usize,
    begin: usize,
    end: usize,
    bin: Bin,
}

/// Builds a binary tree over `aabbs`, where box `i` belongs to primitive `prims[i]` (a
/// primitive split into several boxes appears once per box), with `bins` centroid bins per
/// axis (at most [`MAX_BINS`]). Node 0 is the root; an inner node's children sit at
/// `first_index` and `first_index + 1`, the first's subtree filled first; a leaf names up to
/// [`MAX_LEAF`] entries of `primitive_indices`.
pub(super) fn build(aabbs: &[Aabb], prims: &[u32], bins: usize) -> Bvh2 {
    debug_assert_eq!(aabbs.len(), prims.len());
    let bins = bins.clamp(2, MAX_BINS);
    let centers: Vec<Vec3A> = aabbs.iter().map(Aabb::center).collect();
    let mut indices: Vec<u32> = (0..aabbs.len() as u32).collect();
    let mut nodes = vec![Bvh2Node::default()];
    let mut pending = vec![Pending {
        slot: 0,
        begin: 0,
        end: aabbs.len(),
        bin: Bin::of(&indices, aabbs, &centers),
    }];
    while let Some(Pending {
        slot,
        begin,
        end,
        bin,
    }) = pending.pop()
    {
        if end - begin <= MAX_LEAF {
            nodes[slot] = Bvh2Node::new(bin.bounds, (end - begin) as u32, begin as u32);
            continue;
        }
        let range = &mut indices[begin..end];
        let (left, right) = split(range, aabbs, &centers, &bin, bins);
        let first = nodes.len();
        nodes[slot] = Bvh2Node::new(bin.bounds, 0, first as u32);
        nodes.extend([Bvh2Node::default(); 2]);
        let mid = begin + left.count as usize;
        // The right side is stacked first, so the left one is filled next.
        pending.push(Pending {
            slot: first + 1,
            begin: mid,
            end,
            bin: right,
        });
        pending.push(Pending {
            slot: first,
            begin,
            end: mid,
            bin: left,
        });
    }
    Bvh2 {
        nodes,
        primitive_indices: indices.iter().map(|&i| prims[i as usize]).collect(),
        ..Bvh2::default()
    }
}

/// Splits `range` (more than [`MAX_LEAF`] boxes, `all` their bin) by the cheapest of the
/// planes between `bins` centroid bins on each axis, reordering it so the left side comes
/// first; returns the two sides' bins. Where no plane separates the centroids (they all
/// coincide), the range is halved at a multiple of [`BLOCK`].
fn split(
    range: &mut [u32],
    aabbs: &[Aabb],
    centers: &[Vec3A],
    all: &Bin,
    bins: usize,
) -> (Bin, Bin) {
    let extent = all.centroids.diagonal();
    // Centroid to bin: (c - min) * scale, below `bins` for every centroid in the range.
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(bins as f32 * (1.0 - f32::EPSILON)) / extent,
        Vec3A::ZERO,
    );
    let bin_of = |c: Vec3A| {
        ((c - all.centroids.min) * scale)
            .as_uvec3()
            .min(glam::UVec3::splat(bins as u32 - 1))
    };
    let mut binned = [[Bin::EMPTY; MAX_BINS]; 3];
    for &i in range.iter() {
        let c = centers[i as usize];
        let b = bin_of(c);
        for (axis, axis_bins) in binned.iter_mut().enumerate() {
            axis_bins[b[axis] as usize].insert(&aabbs[i as usize], c);
        }
    }
    // The cheapest plane: below it bins [0, plane), above it [plane, bins).
    let mut best: Option<(f32, usize, usize)> = None;
    for (axis, axis_bins) in binned.iter().enumerate() {
        if extent[axis] <= 0.0 {
            continue;
        }
        let mut above = [0f32; MAX_BINS];
        let mut acc = Bin::EMPTY;
        for plane in (1..bins).rev() {
            acc.add(&axis_bins[plane]);
            above[plane] = side_cost(&acc);
        }
        let mut acc = Bin::EMPTY;
        for plane in 1..bins {
            acc.add(&axis_bins[plane - 1]);
            if acc.count == 0 || acc.count == all.count {
                continue;
            }
            let cost = side_cost(&acc) + above[plane];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, plane));
            }
        }
    }
    let Some((_, axis, plane)) = best else {
        // Coinciding centroids: any order is as good as another.
        let mid = (range.len() / 2)
            .next_multiple_of(BLOCK as usize)
            .min(range.len() - 1);
        let (left, right) = range.split_at(mid);
        return (
            Bin::of(left, aabbs, centers),
            Bin::of(right, aabbs, centers),
        );
    };
    let (mut left, mut right) = (Bin::EMPTY, Bin::EMPTY);
    for (b, bin) in binned[axis][..bins].iter().enumerate() {
        if b < plane {
            left.add(bin);
        } else {
            right.add(bin);
        }
    }
    // In place: the boxes whose centroids fall below the plane go first.
    let (mut lo, mut hi) = (0, range.len());
    while lo < hi {
        if (bin_of(centers[range[lo] as usize])[axis] as usize) < plane {
            lo += 1;
        } else {
            hi -= 1;
            range.swap(lo, hi);
        }
    }
    debug_assert_eq!(lo, left.count as usize);
    (left, right)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box around the point `p`, `size` wide.
    fn cube(p: Vec3A, size: f32) -> Aabb {
        Aabb::new(p - Vec3A::splat(size / 2.0), p + Vec3A::splat(size / 2.0))
    }

    /// Walks the tree: every primitive once per box, each node's box the union of what is
    /// beneath it, leaves of at most four; returns the leaves' sizes.
    fn check(bvh: &Bvh2, aabbs: &[Aabb], prims: &[u32]) -> Vec<u32> {
        let mut seen = vec![0u32; aabbs.len()];
        let mut leaves = Vec::new();
        let mut pending = vec![0usize];
        while let Some(n) = pending.pop() {
            let node = &bvh.nodes[n];
            if node.prim_count == 0 {
                let (a, b) = (node.first_index as usize, node.first_index as usize + 1);
                let union = bvh.nodes[a].aabb.union(&bvh.nodes[b].aabb);
                assert_eq!((union.min, union.max), (node.aabb.min, node.aabb.max));
                pending.extend([a, b]);
            } else {
                assert!(node.prim_count as usize <= MAX_LEAF);
                leaves.push(node.prim_count);
                let first = node.first_index as usize;
                let mut union = Aabb::INVALID;
                for &p in &bvh.primitive_indices[first..first + node.prim_count as usize] {
                    // Which box of the primitive: one not yet seen inside the leaf's box.
                    let inside = |b: &Aabb| {
                        node.aabb.min.cmple(b.min).all() && b.max.cmple(node.aabb.max).all()
                    };
                    let i = (0..aabbs.len())
                        .find(|&i| prims[i] == p && seen[i] == 0 && inside(&aabbs[i]))
                        .expect("a primitive appears once per box");
                    seen[i] += 1;
                    union = union.union(&aabbs[i]);
                }
                assert_eq!((union.min, union.max), (node.aabb.min, node.aabb.max));
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "every box once");
        leaves
    }

    /// Twelve unit cubes side by side along x, worked by hand. A row of n cubes has half area
    /// n*1 + 1*1 + n*1 = 2n + 1. Charged by packets, halving it (6 | 6) costs 13*2 + 13*2 = 52
    /// and cutting off four (4 | 8) costs 9*1 + 17*2 = 43, so the row becomes three full
    /// packets; charged by triangles (13*6 + 13*6 = 156 against 9*4 + 17*8 = 172) it would be
    /// halved and then cut into four leaves of three.
    #[test]
    fn a_row_of_twelve_gives_full_packets() {
        let aabbs: Vec<Aabb> = (0..12)
            .map(|k| cube(Vec3A::new(k as f32, 0.0, 0.0), 1.0))
            .collect();
        let prims: Vec<u32> = (0..12).collect();
        let leaves = check(&build(&aabbs, &prims, 32), &aabbs, &prims);
        assert_eq!(leaves, [4, 4, 4]);
    }

    /// 37 boxes in a row, 13 of them one more time (a split primitive's boxes), with every
    /// bin count: all kept, and no leaf beyond four.
    #[test]
    fn uneven_counts_and_repeated_primitives_are_all_kept() {
        let mut aabbs: Vec<Aabb> = (0..37)
            .map(|k| cube(Vec3A::new(k as f32 * 1.5, 0.0, 0.0), 1.0))
            .collect();
        let mut prims: Vec<u32> = (0..37).collect();
        for k in (0..37).step_by(3) {
            aabbs.push(cube(Vec3A::new(k as f32 * 1.5 + 0.25, 0.5, 0.0), 0.5));
            prims.push(k);
        }
        for bins in [1, 2, 3, 16, 32, 64, 1000] {
            let leaves = check(&build(&aabbs, &prims, bins), &aabbs, &prims);
            assert_eq!(leaves.iter().sum::<u32>() as usize, aabbs.len());
        }
    }

    /// Boxes whose centroids all coincide cannot be told apart by any plane: they are halved
    /// at multiples of four, down to full leaves.
    #[test]
    fn coinciding_centroids_are_halved() {
        let aabbs: Vec<Aabb> = (0..40).map(|k| cube(Vec3A::ONE, 1.0 + k as f32)).collect();
        let prims: Vec<u32> = (0..40).collect();
        let bvh = build(&aabbs, &prims, 32);
        let leaves = check(&bvh, &aabbs, &prims);
        assert_eq!(leaves.len(), 10);
        assert!(leaves.iter().all(|&n| n == 4));
    }

    /// The split worked by hand: eight unit cubes in two columns of four along y, 100 apart
    /// along x. The plane between the columns leaves each side one full packet over a
    /// 1 x 4 x 1 box (half area 1*4 + 4*1 + 1*1 = 9), cost 9 + 9 = 18; any plane across a column
    /// leaves one side over both columns (half area above 100), so the root's children are the
    /// two columns.
    #[test]
    fn two_clusters_are_the_first_split() {
        let mut aabbs = Vec::new();
        for cluster in [0.0, 100.0] {
            for k in 0..4 {
                aabbs.push(cube(Vec3A::new(cluster, k as f32, 0.0), 1.0));
            }
        }
        let prims: Vec<u32> = (0..8).collect();
        let bvh = build(&aabbs, &prims, 32);
        let root = &bvh.nodes[0];
        assert_eq!(root.prim_count, 0);
        let (a, b) = (
            &bvh.nodes[root.first_index as usize],
            &bvh.nodes[root.first_index as usize + 1],
        );
        // Each child is one cluster: a 1 x 4 x 1 box, half area 1*4 + 4*1 + 1*1 = 9.
        assert_eq!((a.prim_count, b.prim_count), (4, 4));
        assert_eq!(a.aabb.half_area(), 9.0);
        assert_eq!(b.aabb.half_area(), 9.0);
        assert_eq!(a.aabb.max.x, 0.5);
        assert_eq!(b.aabb.min.x, 99.5);
    }
}
