//! The wide BVH against testing every triangle, and the slab test's rounding bounds.

use super::layout::{ARITY, EMPTY, INDEX, LEAF, Node, PAIR, WIDTH};
use super::ray::{FAR_SCALE, Level, Portable, Prepared, slabs};
use super::{Binary, WideBvh};
use crate::BuildQuality;
use crate::geom::intersect_triangle;
use crate::simd::Avx2;
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;

/// A bumpy square of `n` by `n` quads, two triangles each, across [-3, 3]^2 near z = 0.
fn surface(n: usize) -> Vec<[Vec3A; 3]> {
    let at = |i: usize, j: usize| {
        let (x, y) = (
            6.0 * i as f32 / n as f32 - 3.0,
            6.0 * j as f32 / n as f32 - 3.0,
        );
        Vec3A::new(x, y, 0.3 * (1.7 * x).sin() * (1.3 * y).cos())
    };
    (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            [[a, b, c], [a, c, d]]
        })
        .collect()
}

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
/// box contains everything beneath it, a two-packet leaf's second packet holds a triangle,
/// the stack bound covers the real depth, and each node's `leaves` and `nodes` name exactly
/// the packets of its leaf children and its child nodes.
#[test]
fn the_collapse_keeps_every_triangle_once_inside_its_boxes() {
    let soups = [1, 2, 4, 5, 8, 9, 17, 300].map(|n| soup(n, n as u32));
    let binaries = [
        BuildQuality::Medium.binary(),
        Binary::Ploc(BvhBuildParams::medium_build()),
    ];
    for (tris, binary) in soups
        .into_iter()
        .chain([surface(24)])
        .flat_map(|tris| binaries.map(|b| (tris.clone(), b)))
    {
        let n = tris.len();
        let ids = (0..n as u32).map(|i| [i, i + 1000]).collect::<Vec<_>>();
        let bvh = WideBvh::build(&tris, &ids, binary);
        let mut seen = vec![0u32; n];
        let mut pending = vec![(bvh.root, None::<[f32; 6]>, 0usize)];
        let mut depth_max = 0;
        let mut pairs = 0;
        while let Some((r, bounds, depth)) = pending.pop() {
            depth_max = depth_max.max(depth);
            if r & LEAF == 0 {
                let node = &bvh.nodes[r as usize];
                let (mut packets, mut nodes) = (Vec::new(), Vec::new());
                for &c in node.child.iter().filter(|&&c| c != EMPTY) {
                    if c & LEAF == 0 {
                        nodes.push(c);
                    } else {
                        let first = c & INDEX;
                        packets.extend(first..=first + u32::from(c & PAIR != 0));
                    }
                }
                packets.sort_unstable();
                nodes.sort_unstable();
                let run = |[first, count]: [u32; 2]| (first..first + count).collect::<Vec<_>>();
                if !packets.is_empty() {
                    assert_eq!(packets, run(node.leaves), "n = {n}");
                }
                assert_eq!(node.leaves[1] as usize, packets.len());
                if !nodes.is_empty() {
                    assert_eq!(nodes, run(node.nodes), "n = {n}");
                }
                assert_eq!(node.nodes[1] as usize, nodes.len());
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
                let first = (r & INDEX) as usize;
                let count = 1 + usize::from(r & PAIR != 0);
                pairs += count - 1;
                assert!(count == 1 || bvh.packets[first + 1].ids[0][0] != EMPTY);
                for (p, lane) in bvh.packets[first..first + count]
                    .iter()
                    .flat_map(|p| (0..WIDTH).map(move |lane| (p, lane)))
                {
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
        if n > 2 * WIDTH {
            assert!(bvh.root & LEAF == 0, "more than two packets need a node");
        }
        // A dense surface's small subtrees of five to eight triangles become two-packet
        // leaves (scattered triangles' boxes are apart, and the heuristic splits them).
        if n == 2 * 24 * 24 {
            assert!(pairs > 20, "{pairs} two-packet leaves");
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
    for (binary, pre_split) in [
        (Binary::Ploc(BvhBuildParams::fast_build()), false),
        (Binary::Ploc(BvhBuildParams::medium_build()), false),
        (Binary::Ploc(BvhBuildParams::slow_build()), true),
        (BuildQuality::Fast.binary(), false),
        (BuildQuality::Medium.binary(), false),
        (BuildQuality::Slow.binary(), true),
    ] {
        let bvh = WideBvh::build(&tris, &ids, binary);
        let lanes: usize = bvh
            .packets
            .iter()
            .map(|p| p.ids[0].iter().filter(|&&i| i != EMPTY).count())
            .sum();
        // Every triangle once, or more than once where the preset splits.
        assert_eq!(lanes > tris.len(), pre_split, "{binary:?}: {lanes} lanes");
        check_against_every_triangle(&tris, &bvh);
    }
}

/// A dense surface, whose tree has two-packet leaves, answers as testing every triangle does.
#[test]
fn a_tree_with_two_packet_leaves_answers_the_same() {
    let tris = surface(24);
    let ids = (0..tris.len() as u32).map(|i| [i, 7]).collect::<Vec<_>>();
    check_against_every_triangle(
        &tris,
        &WideBvh::build(&tris, &ids, BuildQuality::Medium.binary()),
    );
}

/// A tree large enough for its arrays to move to huge pages answers exactly as testing
/// every triangle does, and so does its clone.
#[test]
fn a_tree_on_huge_pages_answers_the_same() {
    // 50,000 triangles fill about 12,600 packets of 192 bytes: over the 2 MiB threshold.
    let tris: Vec<[Vec3A; 3]> = soup(50_000, 11)
        .into_iter()
        .map(|[a, b, c]| [a, a + (b - a) * 0.1, a + (c - a) * 0.1])
        .collect();
    let ids = (0..tris.len() as u32).map(|i| [i, 7]).collect::<Vec<_>>();
    let bvh = WideBvh::build(&tris, &ids, BuildQuality::Medium.binary());
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
    // Both box tests, asking ahead for what lies below each node or not, give the same
    // answers as the query the CPU was given (AVX2 where it has it), bit for bit.
    let expected = (bits(got), brute.is_some());
    for below in [false, true] {
        let portable = (
            bits(bvh.closest_in(Portable, o, dir, t_min, f32::INFINITY, below)),
            bvh.any_in(Portable, o, dir, t_min, f32::INFINITY, below),
        );
        assert_eq!(portable, expected, "ray {k}, t_min {t_min}, below {below}");
        if let Some(avx2) = Avx2::detect() {
            let fast = (
                bits(bvh.closest_in(avx2, o, dir, t_min, f32::INFINITY, below)),
                bvh.any_in(avx2, o, dir, t_min, f32::INFINITY, below),
            );
            assert_eq!(
                fast, expected,
                "AVX2: ray {k}, t_min {t_min}, below {below}"
            );
        }
    }
}

/// `level`'s test of `node`'s eight boxes, the ray prepared as the sign of `t_min` requires
/// (as [`slabs`] does for the portable test).
fn slabs_with<L: Level>(
    level: L,
    o: Vec3A,
    d: Vec3A,
    node: &Node,
    t_min: f32,
    t_max: f32,
) -> ([f32; ARITY], u32) {
    if t_min >= 0.0 {
        level.slabs(&Prepared::<false>::new(o, d), node, t_min, t_max)
    } else {
        level.slabs(&Prepared::<true>::new(o, d), node, t_min, t_max)
    }
}

/// A hit's ids and its distance and barycentrics' bits.
type HitBits = Option<([u32; 2], [u32; 3])>;

fn bits(h: Option<super::WideHit>) -> HitBits {
    h.map(|h| (h.ids, [h.tri.t, h.tri.b1, h.tri.b2].map(f32::to_bits)))
}

#[test]
fn an_empty_tree_hits_nothing() {
    let bvh = WideBvh::build(&[], &[], BuildQuality::Medium.binary());
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
        // The eight-lane AVX2 test gives the two four-lane halves' bits in every lane,
        // entered or not, with either far-distance rounding.
        if let Some(avx2) = Avx2::detect() {
            let (fast, fast_mask) = slabs_with(avx2, o, d, &node, t_min, t_max);
            proptest::prop_assert_eq!(fast_mask, mask);
            proptest::prop_assert_eq!(fast.map(f32::to_bits), t_near.map(f32::to_bits));
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
                // The AVX2 test, where the CPU has it, enters what the portable one enters.
                let fast = Avx2::detect()
                    .map(|avx2| slabs_with(avx2, o.into(), d.into(), &node, t_min, t_max).1);

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
                    if let Some(fast) = fast {
                        proptest::prop_assert_eq!(fast & 1, 1, "AVX2: near {} far {}", near, far);
                    }
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

/// The interleaved batch (forced, whatever the tree's size) gives every ray exactly the
/// one-ray answer: hit for hit, bit for bit, in order, over trees of 0 to 40,000 triangles,
/// batches shorter and longer than the lanes in flight, rays that start behind their origin
/// (the one-ray query's other box test) and ranges that end before the geometry.
#[test]
fn interleaved_batches_answer_as_one_ray_queries() {
    use super::batch::{BatchRay, LANES};
    for n in [0, 1, 5, 300, 40_000] {
        let tris = soup(n, 5);
        let ids = (0..n as u32).map(|i| [i, 3]).collect::<Vec<_>>();
        let bvh = WideBvh::build(&tris, &ids, BuildQuality::Medium.binary());
        let dirs = soup(3 * LANES + 5, 17);
        let rays: Vec<BatchRay> = dirs
            .iter()
            .enumerate()
            .map(|(k, d)| {
                let o = d[0] * 3.0;
                BatchRay {
                    o,
                    d: d[1] - o,
                    t_min: if k % 7 == 3 { -0.5 } else { 0.0 },
                    t_max: if k % 5 == 1 { 0.4 } else { f32::INFINITY },
                }
            })
            .collect();
        for len in [0, 1, LANES - 1, LANES, rays.len()] {
            let rays = &rays[..len];
            let mut closest = vec![None; len];
            let mut any = vec![false; len];
            bvh.run::<super::traverse::Closest<false>, _>(Portable, rays, &mut closest);
            bvh.run::<super::traverse::Any<false>, _>(Portable, rays, &mut any);
            // The batch with the AVX2 box test answers as with the portable one.
            if let Some(avx2) = Avx2::detect() {
                let mut fast = vec![None; len];
                let mut any_fast = vec![false; len];
                bvh.run::<super::traverse::Closest<false>, _>(avx2, rays, &mut fast);
                bvh.run::<super::traverse::Any<false>, _>(avx2, rays, &mut any_fast);
                assert_eq!(
                    fast.iter().copied().map(bits).collect::<Vec<_>>(),
                    closest.iter().copied().map(bits).collect::<Vec<_>>(),
                    "{n} triangles, {len} rays"
                );
                assert_eq!(any_fast, any, "{n} triangles, {len} rays");
            }
            for (k, r) in rays.iter().enumerate() {
                let one = bvh.closest(r.o, r.d, r.t_min, r.t_max);
                let key = |h: &super::WideHit| {
                    (
                        h.ids,
                        h.tri.t.to_bits(),
                        h.tri.b1.to_bits(),
                        h.tri.b2.to_bits(),
                    )
                };
                assert_eq!(
                    closest[k].as_ref().map(key),
                    one.as_ref().map(key),
                    "{n} triangles, ray {k}"
                );
                assert_eq!(
                    any[k],
                    bvh.any(r.o, r.d, r.t_min, r.t_max),
                    "{n} triangles, ray {k}"
                );
            }
            if n == 40_000 && len == 3 * LANES + 5 {
                // The case is not vacuous: some rays hit, some miss.
                let hits = closest.iter().filter(|h| h.is_some()).count();
                assert!(0 < hits && hits < len, "{hits} of {len} rays hit");
            }
        }
    }
}
