//! A ray prepared for the SIMD tests: the slab test of up to eight child boxes, and the
//! four-wide triangle test of a leaf packet.

use super::layout::{ARITY, Node, Packet, WIDTH};
use crate::geom::gamma;
use crate::simd::{Avx2, WithAvx2};
use glam::{BVec4A, Vec3A, Vec4};

/// pbrt's `gamma(3)`: the relative error of a slab distance `(b - o) * (1 / d)`; the far
/// distance is pushed out by twice this so rounding never culls a box the ray touches.
pub(super) const SLAB_SLACK: f32 = 2.0 * gamma(3);
/// The same push folded into the far planes' reciprocals, `(b - o) * ((1 / d) * FAR_SCALE)`,
/// for queries with `t_min >= 0`: the and, multiply and add of `t + |t| * SLAB_SLACK` stay out
/// of every node's dependent chain, and unused lanes make no NaN. Four
/// roundings then separate a computed far distance from the true one (`gamma(4)` below it)
/// and three the near distance (`gamma(3)` above it), so a box the ray touches is kept when
/// `FAR_SCALE * (1 - gamma(4)) >= 1 + gamma(3)`; `1 + 2 gamma(4)` is four ulps above one
/// and clears it (`far_scale_covers_the_rounding` checks this in f64). A negative far
/// distance would be pulled in, not pushed out, so a query that may start behind its origin
/// keeps [`SLAB_SLACK`] instead.
pub(super) const FAR_SCALE: f32 = 1.0 + 2.0 * gamma(4);

/// A ray prepared for the box tests: splatted origin, reciprocal direction and near-plane lanes.
/// `SLACK`: far distances get [`SLAB_SLACK`] after the fact (a query with `t_min < 0`);
/// otherwise the far planes' reciprocals carry [`FAR_SCALE`]. Which one a query takes is
/// decided once, so the traversal of each has no test for it per node.
///
/// Everything a node's test reads is kept splatted, one value in every lane: a batch keeps
/// several queries and reloads a query's ray at each of its steps, and a splatted vector is
/// one load where a scalar is a load and a shuffle.
pub(super) struct Prepared<const SLACK: bool> {
    o: [Vec4; 3],
    d: [Vec4; 3],
    inv: [Vec4; 3],
    /// The far planes' reciprocals: `inv` times [`FAR_SCALE`], or `inv` itself with `SLACK`.
    inv_far: [Vec4; 3],
    /// 1 where the direction is negative (the box's max plane is met first), else 0.
    near: [usize; 3],
}

impl<const SLACK: bool> Prepared<SLACK> {
    /// The ray from `o` along `d`.
    #[inline(always)]
    pub(super) fn new(o: Vec3A, d: Vec3A) -> Self {
        // A zero component would give 0 * inf = NaN on a slab through the origin; a tiny
        // stand-in of the same sign gives the same slab answer with finite arithmetic.
        // (Three lanes at once: one division instruction instead of three.)
        let tiny = Vec3A::splat(1e-30);
        let safe = Vec3A::select(d.abs().cmplt(tiny), tiny.copysign(d), d);
        let inv = Vec3A::ONE / safe;
        let inv_far = if SLACK { inv } else { inv * FAR_SCALE };
        let inv = inv.to_array();
        Prepared {
            o: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
            d: [Vec4::splat(d.x), Vec4::splat(d.y), Vec4::splat(d.z)],
            inv: inv.map(Vec4::splat),
            inv_far: inv_far.to_array().map(Vec4::splat),
            near: inv.map(|i| usize::from(i < 0.0)),
        }
    }

    /// The entry distance of each of the node's first `N` children's boxes and the mask of
    /// those the ray enters within `[t_min, t_max]` (`N` a multiple of four: eight for a BVH
    /// node, four for a top level of few boxes), four lanes to a register. On x86-64
    /// `Vec4::max(a, b)` and `min` are `maxps`/`minps` (`a > b ? a : b`, the second operand
    /// when either is NaN), as were the scalar `if`s this replaced; the one NaN the test can
    /// make (an unused lane's far distance with the slack, below) stays NaN on every target.
    #[inline(always)]
    pub(super) fn slabs<const N: usize>(
        &self,
        node: &Node,
        t_min: f32,
        t_max: f32,
    ) -> ([f32; N], u32) {
        const { assert!(N.is_multiple_of(WIDTH) && N <= ARITY) };
        let (nx, ny, nz) = (self.near[0] & 1, self.near[1] & 1, self.near[2] & 1);
        let ([ox, oy, oz], [ix, iy, iz], [fx, fy, fz]) = (&self.o, &self.inv, &self.inv_far);
        let (t_min, t_max) = (Vec4::splat(t_min), Vec4::splat(t_max));
        let mut t_near = [0.0; N];
        let mut mask = 0;
        for h in 0..N / WIDTH {
            let plane = |i: usize| node.bounds[i][h];
            let tnx = (plane(nx) - *ox) * *ix;
            let tfx = (plane(nx ^ 1) - *ox) * *fx;
            let tny = (plane(2 + ny) - *oy) * *iy;
            let tfy = (plane(2 + (ny ^ 1)) - *oy) * *fy;
            let tnz = (plane(4 + nz) - *oz) * *iz;
            let tfz = (plane(4 + (nz ^ 1)) - *oz) * *fz;
            let near = tnx.max(tny).max(tnz.max(t_min));
            let t = tfx.min(tfy).min(tfz);
            // An unused lane's near distance is +inf and its far distance -inf, so it is
            // never entered. The slack makes -inf NaN; `t_max` goes first so that `minps`
            // returns its second operand, NaN, which no entry distance is below.
            let far = t_max.min(if SLACK { t + t.abs() * SLAB_SLACK } else { t });
            near.write_to_slice(&mut t_near[WIDTH * h..]);
            mask |= near.cmple(far).bitmask() << (WIDTH * h);
        }
        (t_near, mask)
    }

    /// The lanes of `p` the ray hits within `[t_min, t_max]`, with their distances and
    /// barycentrics (Möller–Trumbore, four triangles at once).
    #[inline(always)]
    pub(super) fn triangles(&self, p: &Packet, t_min: f32, t_max: f32) -> (u32, Vec4, Vec4, Vec4) {
        let [dx, dy, dz] = self.d;
        let [e1x, e1y, e1z] = p.e1;
        let [e2x, e2y, e2z] = p.e2;
        // pvec = d x e2
        let px = dy * e2z - dz * e2y;
        let py = dz * e2x - dx * e2z;
        let pz = dx * e2y - dy * e2x;
        let det = e1x * px + e1y * py + e1z * pz;
        let inv_det = Vec4::ONE / det;
        // tvec = o - v0
        let tx = self.o[0] - p.v0[0];
        let ty = self.o[1] - p.v0[1];
        let tz = self.o[2] - p.v0[2];
        let b1 = (tx * px + ty * py + tz * pz) * inv_det;
        // qvec = tvec x e1
        let qx = ty * e1z - tz * e1y;
        let qy = tz * e1x - tx * e1z;
        let qz = tx * e1y - ty * e1x;
        let b2 = (dx * qx + dy * qy + dz * qz) * inv_det;
        let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
        // Comparisons with NaN are false, so a degenerate lane (det = 0) fails them.
        let ok: BVec4A = det.cmpne(Vec4::ZERO)
            & det.abs().cmplt(Vec4::INFINITY)
            & b1.cmpge(Vec4::ZERO)
            & b1.cmple(Vec4::ONE)
            & b2.cmpge(Vec4::ZERO)
            & (b1 + b2).cmple(Vec4::ONE)
            & t.cmpge(Vec4::splat(t_min))
            & t.cmple(Vec4::splat(t_max));
        (ok.bitmask(), t, b1, b2)
    }
}

/// How a query tests a node's eight boxes: the same steps on every lane, in two four-lane
/// halves ([`Portable`]) or in one eight-lane register ([`Avx2`], when the CPU has it). A
/// query is generic over it, so each is compiled once and chosen once per query or batch.
pub(super) trait Level: Copy {
    /// The AVX2 token, for the level that has one; a constant once the query is compiled.
    fn avx2(self) -> Option<Avx2>;

    /// [`Prepared::slabs`] of all [`ARITY`] lanes, with this level's instructions.
    #[inline(always)]
    fn slabs<const SLACK: bool>(
        self,
        ray: &Prepared<SLACK>,
        node: &Node,
        t_min: f32,
        t_max: f32,
    ) -> ([f32; ARITY], u32) {
        match self.avx2() {
            Some(avx2) => avx2.slabs8::<SLACK>(
                &node.bounds,
                &ray.o,
                &ray.inv,
                &ray.inv_far,
                ray.near,
                [t_min, t_max],
                SLAB_SLACK,
            ),
            None => ray.slabs::<ARITY>(node, t_min, t_max),
        }
    }
}

/// A query to run with the best box test this CPU has ([`dispatch`]); `on` is
/// `#[inline(always)]`, as [`WithAvx2`] requires.
pub(super) trait OnLevel {
    /// What the query returns.
    type Output;
    /// The query with the box test of `level`.
    fn on<L: Level>(self, level: L) -> Self::Output;
}

/// A query handed to [`Avx2::run`], which runs it with the AVX2 box test.
struct OnAvx2<Q>(Q);

impl<Q: OnLevel> WithAvx2 for OnAvx2<Q> {
    type Output = Q::Output;
    #[inline(always)]
    fn with_avx2(self, avx2: Avx2) -> Q::Output {
        self.0.on(avx2)
    }
}

/// Runs `query` compiled for AVX2 with the eight-lane box test when the CPU has AVX2, and with
/// the portable test otherwise.
#[inline(always)]
pub(super) fn dispatch<Q: OnLevel>(query: Q) -> Q::Output {
    match Avx2::detect() {
        Some(avx2) => avx2.run(OnAvx2(query)),
        None => query.on(Portable),
    }
}

/// The box test on any CPU: two four-lane halves.
#[derive(Clone, Copy, Debug)]
pub(super) struct Portable;

impl Level for Portable {
    #[inline(always)]
    fn avx2(self) -> Option<Avx2> {
        None
    }
}

impl Level for Avx2 {
    #[inline(always)]
    fn avx2(self) -> Option<Avx2> {
        Some(self)
    }
}

/// One slab test of `node`'s first `N` lanes for a ray from `o` along `d` over
/// `[t_min, t_max]`, prepared as the sign of `t_min` requires ([`Prepared`]).
#[inline(always)]
pub(super) fn slabs<const N: usize>(
    o: Vec3A,
    d: Vec3A,
    node: &Node,
    t_min: f32,
    t_max: f32,
) -> ([f32; N], u32) {
    if t_min >= 0.0 {
        Prepared::<false>::new(o, d).slabs::<N>(node, t_min, t_max)
    } else {
        Prepared::<true>::new(o, d).slabs::<N>(node, t_min, t_max)
    }
}

/// The lanes set in `mask`, each named by `name(lane)` with its entry distance from `t_near`,
/// into `out` sorted nearest first (insertion sort: at most eight); returns how many.
#[inline(always)]
pub(super) fn by_entry<T: Copy>(
    mask: u32,
    t_near: &[f32; ARITY],
    name: impl Fn(usize) -> T,
    out: &mut [(T, f32); ARITY],
) -> usize {
    let mut n = 0;
    let mut m = mask;
    while m != 0 {
        let lane = m.trailing_zeros() as usize & 7;
        m &= m - 1;
        let entry = (name(lane), t_near[lane]);
        let mut k = n;
        while k > 0 && out[k - 1].1 > entry.1 {
            out[k] = out[k - 1];
            k -= 1;
        }
        out[k] = entry;
        n += 1;
    }
    n
}
