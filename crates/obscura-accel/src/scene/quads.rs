//! The static quads of a scene of a few items, in world space, tested four at a time.
//!
//! A Cornell box is six to a dozen quads and a few spheres. Finding its items through boxes
//! costs a box test per item and then the item's own test; the quads' own tests, four lanes
//! at once, cost less than their boxes' (docs/performance.md, "The quads of a small scene").

use crate::geom::{Parallelogram, QuadHit};
use glam::{Vec3A, Vec4};

/// Four quads, one per lane (structure of arrays): what [`Parallelogram::intersect`] reads.
/// An unused lane has a zero normal, which no ray meets.
#[derive(Clone, Debug)]
struct Group {
    origin: [Vec4; 3],
    n: [Vec4; 3],
    to_s: [Vec4; 3],
    to_v: [Vec4; 3],
}

/// What one group's test found: each lane's `t`, `s` and `v`, and the mask of the lanes hit.
struct Lanes {
    t: Vec4,
    s: Vec4,
    v: Vec4,
    mask: u32,
}

/// Up to [`QuadSet::CAPACITY`] quads in world space, each tagged with its item.
#[derive(Clone, Debug)]
pub(crate) struct QuadSet {
    groups: Vec<Group>,
    /// The item of each quad, in lane order.
    items: Vec<usize>,
}

impl QuadSet {
    /// The most quads a set holds: beyond this many, a tree over their boxes visits fewer.
    pub(crate) const CAPACITY: usize = 16;

    /// The set of `quads`, given as (item, quad); `None` when there are more than
    /// [`QuadSet::CAPACITY`].
    pub(crate) fn new(quads: &[(usize, Parallelogram)]) -> Option<QuadSet> {
        if quads.len() > Self::CAPACITY {
            return None;
        }
        let groups = quads
            .chunks(4)
            .map(|chunk| {
                let lane = |f: &dyn Fn(&Parallelogram) -> [f32; 3], axis: usize| {
                    Vec4::from_array(core::array::from_fn(|k| {
                        chunk.get(k).map_or(0.0, |(_, q)| f(q)[axis])
                    }))
                };
                let soa =
                    |f: &dyn Fn(&Parallelogram) -> [f32; 3]| [lane(f, 0), lane(f, 1), lane(f, 2)];
                Group {
                    origin: soa(&|q| q.origin.to_array()),
                    n: soa(&|q| q.n.to_array()),
                    to_s: soa(&|q| q.to_s.to_array()),
                    to_v: soa(&|q| q.to_v.to_array()),
                }
            })
            .collect();
        Some(QuadSet {
            groups,
            items: quads.iter().map(|&(item, _)| item).collect(),
        })
    }

    /// One group's lanes against the ray (`o` and `d` splatted, one coordinate per vector):
    /// lane for lane the arithmetic of [`Parallelogram::intersect`], in the same order, so the
    /// same `t`, `s` and `v` to the bit.
    #[inline(always)]
    fn test(group: &Group, o: &[Vec4; 3], d: &[Vec4; 3], t_min: f32, t_max: f32) -> Lanes {
        let ([ox, oy, oz], [dx, dy, dz]) = (*o, *d);
        let [px, py, pz] = group.origin;
        let [nx, ny, nz] = group.n;
        let denom = nx * dx + ny * dy + nz * dz;
        let t = (nx * (px - ox) + ny * (py - oy) + nz * (pz - oz)) / denom;
        let (wx, wy, wz) = (ox + dx * t - px, oy + dy * t - py, oz + dz * t - pz);
        let dot = |a: &[Vec4; 3]| wx * a[0] + wy * a[1] + wz * a[2];
        let (s, v) = (dot(&group.to_s), dot(&group.to_v));
        let (zero, one) = (Vec4::ZERO, Vec4::ONE);
        // Comparisons with NaN are false, so a NaN t, s or v is no hit, as in the scalar test.
        let hit = denom.cmpne(zero)
            & denom.abs().cmplt(Vec4::INFINITY)
            & t.cmpge(Vec4::splat(t_min))
            & t.cmple(Vec4::splat(t_max))
            & s.cmpge(zero)
            & s.cmple(one)
            & v.cmpge(zero)
            & v.cmple(one);
        Lanes {
            t,
            s,
            v,
            mask: hit.bitmask(),
        }
    }

    /// The ray's origin and direction splatted, one coordinate per vector.
    #[inline(always)]
    fn splat(o: Vec3A, d: Vec3A) -> ([Vec4; 3], [Vec4; 3]) {
        (o.to_array().map(Vec4::splat), d.to_array().map(Vec4::splat))
    }

    /// The closest quad hit with `t` in `[t_min, t_max]`, as (item, hit). Of quads hit at the
    /// same `t`, the later one: the answer of testing them one by one in order, each with the
    /// best distance so far as its `t_max`.
    #[inline]
    pub(crate) fn closest(
        &self,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<(usize, QuadHit)> {
        let (o, d) = Self::splat(o, d);
        let mut best = None;
        let mut t_best = t_max;
        for (g, group) in self.groups.iter().enumerate() {
            let lanes = Self::test(group, &o, &d, t_min, t_best);
            let mut mask = lanes.mask;
            if mask == 0 {
                continue;
            }
            let (t, s, v) = (lanes.t.to_array(), lanes.s.to_array(), lanes.v.to_array());
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if t[lane] <= t_best {
                    t_best = t[lane];
                    let hit = QuadHit {
                        t: t[lane],
                        s: s[lane],
                        v: v[lane],
                    };
                    best = Some((self.items[4 * g + lane], hit));
                }
            }
        }
        best
    }

    /// Whether any quad is hit with `t` in `[t_min, t_max]`.
    #[inline]
    pub(crate) fn any(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> bool {
        let (o, d) = Self::splat(o, d);
        self.groups
            .iter()
            .any(|group| Self::test(group, &o, &d, t_min, t_max).mask != 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use proptest::prelude::*;

    fn vec3() -> impl Strategy<Value = Vec3> {
        (-4.0f32..4.0, -4.0f32..4.0, -4.0f32..4.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    /// The scalar tests one by one, in order, each bounded by the best so far.
    fn one_by_one(
        quads: &[(usize, Parallelogram)],
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Option<(usize, QuadHit)> {
        let mut best = None;
        let mut t_best = t_max;
        for &(item, quad) in quads {
            if let Some(hit) = quad.intersect(o, d, t_min, t_best) {
                t_best = hit.t;
                best = Some((item, hit));
            }
        }
        best
    }

    fn bits(found: Option<(usize, QuadHit)>) -> Option<(usize, [u32; 3])> {
        found.map(|(item, h)| (item, [h.t, h.s, h.v].map(f32::to_bits)))
    }

    #[test]
    fn a_ray_through_a_box_of_quads_meets_the_far_wall() {
        // The unit cube's six faces; from its centre along +x the ray meets the face x = 1
        // at t = 0.5, at its middle.
        let faces = [
            (Vec3::ZERO, Vec3::Y, Vec3::Z),
            (Vec3::X, Vec3::Y, Vec3::Z),
            (Vec3::ZERO, Vec3::X, Vec3::Z),
            (Vec3::Y, Vec3::X, Vec3::Z),
            (Vec3::ZERO, Vec3::X, Vec3::Y),
            (Vec3::Z, Vec3::X, Vec3::Y),
        ]
        .map(|(o, u, v)| Parallelogram::new(o, u, v));
        let quads: Vec<_> = faces
            .into_iter()
            .enumerate()
            .map(|(i, q)| (10 + i, q))
            .collect();
        let set = QuadSet::new(&quads).unwrap();
        let (o, d) = (Vec3A::splat(0.5), Vec3A::X);
        let (item, hit) = set.closest(o, d, 0.0, f32::INFINITY).unwrap();
        assert_eq!((item, hit.t, hit.s, hit.v), (11, 0.5, 0.5, 0.5));
        assert!(set.any(o, d, 0.0, 0.5));
        assert!(!set.any(o, d, 0.0, 0.49));
        assert!(set.closest(o, d, 0.6, f32::INFINITY).is_none());
    }

    #[test]
    fn of_quads_hit_at_the_same_t_the_later_wins() {
        // Copies of one quad at slots 0 and 4 (the same lane of two groups) and at slots 1 and
        // 2 (two lanes of one group), the others elsewhere: the later copy of each pair wins.
        let near = Parallelogram::new(Vec3::new(-1.0, -1.0, 1.0), 2.0 * Vec3::X, 2.0 * Vec3::Y);
        let far = Parallelogram::new(Vec3::new(-1.0, -1.0, 5.0), 2.0 * Vec3::X, 2.0 * Vec3::Y);
        let (o, d) = (Vec3A::ZERO, Vec3A::Z);
        for (copies, want) in [([0, 4], 14), ([1, 2], 12), ([3, 7], 17)] {
            let quads: Vec<_> = (0..8)
                .map(|k| (10 + k, if copies.contains(&k) { near } else { far }))
                .collect();
            let set = QuadSet::new(&quads).unwrap();
            let (item, hit) = set.closest(o, d, 0.0, f32::INFINITY).unwrap();
            assert_eq!((item, hit.t), (want, 1.0), "copies at {copies:?}");
        }
    }

    #[test]
    fn more_quads_than_the_capacity_are_refused() {
        let quad = Parallelogram::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let quads: Vec<_> = (0..=QuadSet::CAPACITY).map(|i| (i, quad)).collect();
        assert!(QuadSet::new(&quads).is_none());
        assert!(QuadSet::new(&quads[..QuadSet::CAPACITY]).is_some());
    }

    proptest! {
        #[test]
        fn the_set_finds_what_the_quads_one_by_one_find(
            shapes in proptest::collection::vec((vec3(), vec3(), vec3()), 1..=16),
            o in vec3(),
            d in vec3(),
            t_min in 0.0f32..0.5,
            t_max in prop_oneof![Just(f32::INFINITY), 0.5f32..8.0],
            repeat in any::<bool>(),
        ) {
            // Random quads (degenerate ones too, when two random edges are parallel), the
            // first one repeated at the end when `repeat`: a tie at the same `t`.
            let mut quads: Vec<_> = shapes
                .iter()
                .enumerate()
                .map(|(i, &(p, u, v))| (i, Parallelogram::new(p, u, v)))
                .collect();
            if repeat && quads.len() < QuadSet::CAPACITY {
                quads.push((99, quads[0].1));
            }
            let set = QuadSet::new(&quads).unwrap();
            let (oa, da) = (Vec3A::from(o), Vec3A::from(d));
            let expected = one_by_one(&quads, o, d, t_min, t_max);
            prop_assert_eq!(bits(set.closest(oa, da, t_min, t_max)), bits(expected));
            prop_assert_eq!(set.any(oa, da, t_min, t_max), expected.is_some());
        }
    }
}
