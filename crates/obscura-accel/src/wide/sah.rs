//! A top-down binned surface-area builder for the binary tree the collapse reads (after Wald
//! 2007, "On fast construction of SAH-based bounding volume hierarchies"), with each side of a
//! split charged by the four-triangle packets it will fill rather than by its triangles.
//!
//! The wide tree's leaves are packets of four triangles, so a subtree of five triangles costs
//! two packet tests where one of four costs one. Charging each side of a split
//! `area * ceil(n / 4)` (as Embree's builders do with their block size) puts the binary tree's
//! subtree sizes on multiples of four wherever the geometry allows, and the collapse then
//! finds full packets to make leaves of.
//!
//! Ranges of many boxes are split on one thread and their two sides built as rayon tasks;
//! the node array comes out the same as a one-thread build's, whatever the pool's size.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::node::Bvh2Node;
use rayon::prelude::*;

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

    /// Adds the boxes of `other`.
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

/// A node still to be filled on one thread: its slot in the node array, its range of box
/// indices (within the range that thread fills), and the bin of that range (its bounds and
/// centroid bounds).
struct Pending {
    slot: usize,
    begin: usize,
    end: usize,
    bin: Bin,
}

/// A range of at least this many boxes is split on the calling thread and its two sides
/// built as two rayon tasks; a smaller one is built whole on one thread. Either way the node
/// array is the same, so the tree does not depend on the number of threads.
const PARALLEL_MIN: usize = 1 << 14;
/// The most levels of tasks (a bound on the recursion however unbalanced the splits are).
const MAX_FORKS: u32 = 24;

/// What every part of a build reads.
struct Inputs<'a> {
    aabbs: &'a [Aabb],
    centers: &'a [Vec3A],
    bins: usize,
    parallel_min: usize,
}

/// Builds a binary tree over `aabbs`, where box `i` belongs to primitive `prims[i]` (a
/// primitive split into several boxes appears once per box), with `bins` centroid bins per
/// axis (at most [`MAX_BINS`]). Node 0 is the root; an inner node's children sit at
/// `first_index` and `first_index + 1`, followed by the first's subtree and then the
/// second's; a leaf names up to [`MAX_LEAF`] entries of `primitive_indices`. Large subtrees
/// are built in parallel on rayon's current pool.
pub(super) fn build(aabbs: &[Aabb], prims: &[u32], bins: usize) -> Bvh2 {
    build_with(aabbs, prims, bins, PARALLEL_MIN)
}

/// [`build`], forking for ranges of at least `parallel_min` boxes.
fn build_with(aabbs: &[Aabb], prims: &[u32], bins: usize, parallel_min: usize) -> Bvh2 {
    debug_assert_eq!(aabbs.len(), prims.len());
    let inputs = Inputs {
        aabbs,
        centers: &aabbs.par_iter().map(Aabb::center).collect::<Vec<_>>(),
        bins: bins.clamp(2, MAX_BINS),
        parallel_min: parallel_min.max(MAX_LEAF + 1),
    };
    let mut indices: Vec<u32> = (0..aabbs.len() as u32).collect();
    let bin = Bin::of(&indices, aabbs, inputs.centers);
    let mut nodes = vec![Bvh2Node::default()];
    nodes[0] = fill(&inputs, &mut indices, 0, bin, &mut nodes, MAX_FORKS);
    Bvh2 {
        nodes,
        primitive_indices: indices.iter().map(|&i| prims[i as usize]).collect(),
        ..Bvh2::default()
    }
}

/// The node over `range` (the boxes at `begin..` of the whole index array, `bin` their
/// bin), with its descendants appended to `out`: its two children first, then the first
/// child's subtree, then the second's. Child indices count from the start of `out`.
fn fill(
    inputs: &Inputs,
    range: &mut [u32],
    begin: usize,
    bin: Bin,
    out: &mut Vec<Bvh2Node>,
    forks: u32,
) -> Bvh2Node {
    // A leaf is below `parallel_min` (at least MAX_LEAF + 1), so `fill_here` makes it.
    if range.len() < inputs.parallel_min || forks == 0 {
        return fill_here(inputs, range, begin, bin, out);
    }
    let (left, right) = split(range, inputs, &bin, &mut empty_scratch());
    let first = out.len();
    out.extend([Bvh2Node::default(); 2]);
    let mid = left.count as usize;
    let (left_range, right_range) = range.split_at_mut(mid);
    // The first side is appended to `out` in place; the second into a block of its own,
    // moved in after the first side's subtree with its child indices shifted to match.
    let (left_node, (right_node, right_block)) = rayon::join(
        || fill(inputs, left_range, begin, left, out, forks - 1),
        || {
            let mut block = Vec::new();
            let node = fill(
                inputs,
                right_range,
                begin + mid,
                right,
                &mut block,
                forks - 1,
            );
            (node, block)
        },
    );
    let offset = out.len();
    out.extend(right_block.into_iter().map(|n| shifted(n, offset)));
    out[first] = left_node;
    out[first + 1] = shifted(right_node, offset);
    Bvh2Node::new(bin.bounds, 0, first as u32)
}

/// `node` with its children's index moved on by `offset` (a leaf's primitive range is
/// absolute already).
fn shifted(mut node: Bvh2Node, offset: usize) -> Bvh2Node {
    if node.prim_count == 0 {
        node.first_index += offset as u32;
    }
    node
}

/// [`fill`] on this thread alone: depth first from a stack, the first child's subtree
/// before the second's.
fn fill_here(
    inputs: &Inputs,
    range: &mut [u32],
    begin: usize,
    bin: Bin,
    out: &mut Vec<Bvh2Node>,
) -> Bvh2Node {
    let mut root = Bvh2Node::default();
    let mut scratch = empty_scratch();
    // Slot `usize::MAX` is the range's own node, returned rather than stored.
    let mut pending = vec![Pending {
        slot: usize::MAX,
        begin: 0,
        end: range.len(),
        bin,
    }];
    while let Some(Pending {
        slot,
        begin: lo,
        end: hi,
        bin,
    }) = pending.pop()
    {
        let node = if hi - lo <= MAX_LEAF {
            Bvh2Node::new(bin.bounds, (hi - lo) as u32, (begin + lo) as u32)
        } else {
            let (left, right) = split(&mut range[lo..hi], inputs, &bin, &mut scratch);
            let first = out.len();
            out.extend([Bvh2Node::default(); 2]);
            let mid = lo + left.count as usize;
            // The second child is stacked first, so the first one's subtree is filled next.
            pending.push(Pending {
                slot: first + 1,
                begin: mid,
                end: hi,
                bin: right,
            });
            pending.push(Pending {
                slot: first,
                begin: lo,
                end: mid,
                bin: left,
            });
            Bvh2Node::new(bin.bounds, 0, first as u32)
        };
        match out.get_mut(slot) {
            Some(stored) => *stored = node,
            None => root = node,
        }
    }
    root
}

/// Each axis's bins, kept between splits so that a split resets only the bins it uses.
type Scratch = [[Bin; MAX_BINS]; 3];

/// Bins for [`split`] to fill, on the heap (15 KB).
fn empty_scratch() -> Box<Scratch> {
    Box::new([[Bin::EMPTY; MAX_BINS]; 3])
}

/// The bounds and count of a run of bins: all that a side's cost reads.
#[derive(Clone, Copy)]
struct Side {
    bounds: Aabb,
    count: u32,
}

impl Side {
    const EMPTY: Side = Side {
        bounds: Aabb::INVALID,
        count: 0,
    };

    fn add(&mut self, bin: &Bin) {
        self.bounds = self.bounds.union(&bin.bounds);
        self.count += bin.count;
    }

    /// The surface-area cost of the side: its box's area times the packets it fills.
    fn cost(&self) -> f32 {
        self.bounds.half_area() * self.count.div_ceil(BLOCK) as f32
    }
}

/// Splits `range` (more than [`MAX_LEAF`] boxes, `all` their bin) by the cheapest of the
/// planes between `inputs.bins` centroid bins on each axis, reordering it so the left side
/// comes first; returns the two sides' bins. Where no plane separates the centroids (they all
/// coincide), the range is halved at a multiple of [`BLOCK`].
///
/// Only planes between two occupied bins are costed, one per run of empty bins: every plane
/// of such a run leaves the same boxes on each side, so it has the same cost, and the first
/// cheapest plane found is the same. Most splits are of a few boxes in mostly empty bins.
fn split(range: &mut [u32], inputs: &Inputs, all: &Bin, scratch: &mut Scratch) -> (Bin, Bin) {
    let Inputs {
        aabbs,
        centers,
        bins,
        ..
    } = *inputs;
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
    for axis_bins in scratch.iter_mut() {
        axis_bins[..bins].fill(Bin::EMPTY);
    }
    for &i in range.iter() {
        let c = centers[i as usize];
        let b = bin_of(c);
        for (axis, axis_bins) in scratch.iter_mut().enumerate() {
            axis_bins[b[axis] as usize].insert(&aabbs[i as usize], c);
        }
    }
    // The cheapest plane: below it bins [0, plane), above it [plane, bins).
    let mut best: Option<(f32, usize, usize)> = None;
    for (axis, axis_bins) in scratch.iter().enumerate() {
        if extent[axis] <= 0.0 {
            continue;
        }
        let mut occupied = [0usize; MAX_BINS];
        let mut m = 0;
        for (b, bin) in axis_bins[..bins].iter().enumerate() {
            if bin.count > 0 {
                occupied[m] = b;
                m += 1;
            }
        }
        // above[k]: the side from occupied bin k up.
        let mut above = [0f32; MAX_BINS];
        let mut acc = Side::EMPTY;
        for k in (1..m).rev() {
            acc.add(&axis_bins[occupied[k]]);
            above[k] = acc.cost();
        }
        let mut acc = Side::EMPTY;
        for k in 1..m {
            acc.add(&axis_bins[occupied[k - 1]]);
            let cost = acc.cost() + above[k];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, occupied[k]));
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
    for (b, bin) in scratch[axis][..bins].iter().enumerate() {
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
    use proptest::prelude::Just;

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

    /// `n` boxes from `seed`: scattered, clustered and repeated, of many sizes (a small
    /// linear congruential generator, so the cases are the same everywhere).
    fn scattered(n: usize, seed: u64) -> Vec<Aabb> {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|k| {
                let p = match k % 5 {
                    // A tight cluster, and a run of boxes at one point.
                    0 => Vec3A::new(next(), next(), next()) * 0.01,
                    1 => Vec3A::splat(3.0),
                    _ => Vec3A::new(next(), next(), next()) * 100.0,
                };
                cube(p, 0.01 + next() * 4.0)
            })
            .collect()
    }

    /// The node array and leaf order, as bytes, for comparing two builds exactly.
    fn bytes(bvh: &Bvh2) -> (Vec<u8>, Vec<u32>) {
        (
            bytemuck::cast_slice(&bvh.nodes).to_vec(),
            bvh.primitive_indices.clone(),
        )
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(32))]

        /// Built in parallel, on one thread or three, the tree is the one-thread build's
        /// node for node, and a valid tree.
        #[test]
        fn parallel_build_is_the_sequential_one(
            n in 0usize..1500,
            seed in proptest::prelude::any::<u64>(),
            parallel_min in 5usize..200,
        ) {
            let aabbs = scattered(n, seed);
            let prims: Vec<u32> = (0..n as u32).collect();
            let alone = build_with(&aabbs, &prims, 32, usize::MAX);
            for threads in [1, 3] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                let forked = pool.install(|| build_with(&aabbs, &prims, 32, parallel_min));
                proptest::prop_assert_eq!(bytes(&forked), bytes(&alone));
            }
            if n > 0 {
                let leaves = check(&alone, &aabbs, &prims);
                proptest::prop_assert_eq!(leaves.iter().sum::<u32>() as usize, n);
            }
        }


        /// The plane `split` chooses from its bins, costing one plane per run of empty bins,
        /// is the one costing every plane from the boxes themselves chooses: the same boxes
        /// below it, and the two sides' bins are those of their boxes, bit for bit.
        #[test]
        fn split_matches_every_plane_costed(
            n in 5usize..300,
            seed in proptest::prelude::any::<u64>(),
            bins in proptest::prelude::prop_oneof![Just(2usize), Just(7), Just(32), Just(64)],
        ) {
            let aabbs = scattered(n, seed);
            let centers: Vec<Vec3A> = aabbs.iter().map(Aabb::center).collect();
            let mut range: Vec<u32> = (0..n as u32).collect();
            let all = Bin::of(&range, &aabbs, &centers);
            let expected = left_by_brute_force(&range, &aabbs, &centers, &all, bins);
            let mut scratch = empty_scratch();
            let inputs = Inputs {
                aabbs: &aabbs,
                centers: &centers,
                bins,
                parallel_min: usize::MAX,
            };
            let (left, right) = split(&mut range, &inputs, &all, &mut scratch);
            let (below, above) = range.split_at(left.count as usize);
            if let Some(mut expected) = expected {
                let mut below = below.to_vec();
                below.sort_unstable();
                expected.sort_unstable();
                proptest::prop_assert_eq!(below, expected);
            }
            let of = |side: &[u32]| bin_bits(&Bin::of(side, &aabbs, &centers));
            proptest::prop_assert_eq!(bin_bits(&left), of(below));
            proptest::prop_assert_eq!(bin_bits(&right), of(above));
        }
    }

    /// Splits that peel a few boxes off at a time (each box 1.2 times the last one's distance
    /// away) go deeper than `MAX_FORKS` levels of tasks, past which the rest is built on one
    /// thread: still the same tree.
    #[test]
    fn unbalanced_splits_past_the_last_fork_build_the_same_tree() {
        let aabbs: Vec<Aabb> = (0..120)
            .map(|k| cube(Vec3A::new(1.2f32.powi(k), 0.0, 0.0), 0.5))
            .collect();
        let prims: Vec<u32> = (0..120).collect();
        let alone = build_with(&aabbs, &prims, 32, usize::MAX);
        let forked = build_with(&aabbs, &prims, 32, 5);
        assert_eq!(bytes(&forked), bytes(&alone));
        check(&forked, &aabbs, &prims);
    }

    /// The boxes of `range` the cheapest plane puts below it, by brute force: on every axis
    /// with extent, every plane between two of `bins` centroid bins that leaves boxes on both
    /// sides, each side's box and count found from its boxes; the first cheapest, in the
    /// order `split` goes. `None` where no plane separates the centroids.
    fn left_by_brute_force(
        range: &[u32],
        aabbs: &[Aabb],
        centers: &[Vec3A],
        all: &Bin,
        bins: usize,
    ) -> Option<Vec<u32>> {
        let extent = all.centroids.diagonal();
        let mut best: Option<(f32, Vec<u32>)> = None;
        for axis in 0..3 {
            if extent[axis] <= 0.0 {
                continue;
            }
            // The same centroid-to-bin map as `split`'s.
            let scale = bins as f32 * (1.0 - f32::EPSILON) / extent[axis];
            let bin = |i: u32| {
                (((centers[i as usize] - all.centroids.min)[axis] * scale) as usize).min(bins - 1)
            };
            for plane in 1..bins {
                let (below, above): (Vec<u32>, Vec<u32>) =
                    range.iter().partition(|&&i| bin(i) < plane);
                if below.is_empty() || above.is_empty() {
                    continue;
                }
                let cost = |side: &[u32]| {
                    let bounds = side
                        .iter()
                        .fold(Aabb::INVALID, |b, &i| b.union(&aabbs[i as usize]));
                    bounds.half_area() * (side.len() as u32).div_ceil(BLOCK) as f32
                };
                let total = cost(&below) + cost(&above);
                if best.as_ref().is_none_or(|(c, _)| total < *c) {
                    best = Some((total, below));
                }
            }
        }
        best.map(|(_, below)| below)
    }

    /// The bits of a bin, for comparing two exactly.
    fn bin_bits(bin: &Bin) -> ([u32; 12], u32) {
        let (b, c) = (bin.bounds, bin.centroids);
        let mut f = [0.0; 12];
        f[..3].copy_from_slice(&b.min.to_array());
        f[3..6].copy_from_slice(&b.max.to_array());
        f[6..9].copy_from_slice(&c.min.to_array());
        f[9..].copy_from_slice(&c.max.to_array());
        (f.map(f32::to_bits), bin.count)
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
