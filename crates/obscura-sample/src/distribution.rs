//! Piecewise-constant distributions in one and two dimensions, for importance sampling
//! environment maps and choosing triangles by area.

use crate::hash::ONE_MINUS_EPSILON;
use glam::{Vec2, Vec3};
use std::ops::Deref;

/// A piecewise-constant density over `[0, 1)` with `n` equal bins of non-negative weights.
/// When every weight is zero it falls back to the uniform density (so sampling never fails).
///
/// Sampling inverts the CDF with a guide table (the cutpoint method, Chen and Asau 1974):
/// `n` buckets of `u`, each knowing which CDF entries can answer for it, so a search looks at
/// about two entries instead of binary-searching all `n + 1`. The answer is exactly the full
/// binary search's.
///
/// Each bin can carry a value `V`, kept in the same cell as the bin's CDF entry and weight:
/// finding a bin, its density and its value touches one place in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution1D<V = ()> {
    /// `n + 1` cells: cell `i` holds the CDF where bin `i` starts, the bin's weight (0 in the
    /// last), guide entry `i` and the bin's value (the default in the last).
    cells: Vec<Cell<V>>,
    integral: f32,
}

/// What a search reads of a bin: the CDF where it starts, its weight (0 in the last cell)
/// and its guide entry.
#[derive(Debug, Clone, Copy, PartialEq, Default, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
struct Bin {
    cdf: f32,
    func: f32,
    /// How many CDF entries fall in guide buckets below this cell's index (see [`bucket`]).
    guide: u32,
}

/// One bin of a [`Distribution1D`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cell<V> {
    bin: Bin,
    value: V,
}

/// One bin of a [`Distribution2D`]'s grid as stored: the bin's CDF entry within its row, its
/// weight, its guide entry and the RGB value it carries, 24 bytes in one place. Opaque; it is
/// public so that a caller can choose where a large grid lives
/// ([`Distribution2D::with_values_stored`]), and plain bytes (`bytemuck::Pod`) so that the
/// storage may be any memory.
#[derive(Debug, Clone, Copy, PartialEq, Default, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct GridCell {
    bin: Bin,
    value: [f32; 3],
}

/// A cell of either kind, as the searches see it.
trait HasBin: Copy {
    fn bin(&self) -> &Bin;
}

impl<V: Copy> HasBin for Cell<V> {
    #[inline(always)]
    fn bin(&self) -> &Bin {
        &self.bin
    }
}

impl HasBin for GridCell {
    #[inline(always)]
    fn bin(&self) -> &Bin {
        &self.bin
    }
}

/// A 1D distribution's `n + 1` cells as built: CDF entry, weight and guide entry of each,
/// and the weights' integral (see [`Distribution1D`]).
fn build_bins(weights: &[f32]) -> (Vec<Bin>, f32) {
    let mut func: Vec<f32> = weights
        .iter()
        .map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
        .collect();
    if func.is_empty() {
        func.push(1.0);
    }
    let n = func.len();
    // Running sums in f64 so long rows do not lose their small bins.
    let mut cdf = Vec::with_capacity(n + 1);
    let mut sum = 0.0f64;
    cdf.push(0.0f32);
    for &f in &func {
        sum += f64::from(f) / n as f64;
        cdf.push(sum as f32);
    }
    let integral = sum as f32;
    if integral > 0.0 {
        for c in cdf.iter_mut().skip(1) {
            *c /= integral;
        }
    } else {
        for (i, c) in cdf.iter_mut().enumerate() {
            *c = i as f32 / n as f32;
        }
    }
    cdf[n] = 1.0;
    // Guide entry k: the CDF entries in buckets below k (a histogram, then running sums).
    let mut guide = vec![0u32; n + 1];
    for &c in &cdf {
        guide[bucket(c, n) + 1] += 1;
    }
    for k in 1..=n {
        guide[k] += guide[k - 1];
    }
    let bins = (0..=n)
        .map(|i| Bin {
            cdf: cdf[i],
            func: func.get(i).copied().unwrap_or(0.0),
            guide: guide[i],
        })
        .collect();
    (bins, integral)
}

/// The guide bucket of `u` among `n`: `floor(u n)`, clamped to `0..n`. Monotone in `u`,
/// which is all the guide table relies on.
#[inline(always)]
fn bucket(u: f32, n: usize) -> usize {
    ((u * n as f32) as usize).min(n - 1)
}

/// A 1D distribution's cells and integral, wherever they are stored: the searches and
/// densities that [`Distribution1D`] and each row of a [`Distribution2D`] share.
#[derive(Clone, Copy)]
struct Row<'a, C> {
    /// `n + 1` cells, as in [`Distribution1D`].
    cells: &'a [C],
    integral: f32,
}

impl<C: HasBin> Row<'_, C> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.cells.len() - 1
    }

    /// The bin holding `x` in `[0, 1)` (clamped).
    #[inline(always)]
    fn bin(&self, x: f32) -> usize {
        ((x * self.len() as f32) as usize).min(self.len() - 1)
    }

    /// The density of bin `i` with respect to `x`.
    #[inline(always)]
    fn pdf_of_bin(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            self.cells[i].bin().func / self.integral
        } else {
            1.0
        }
    }

    fn discrete_pdf(&self, i: usize) -> f32 {
        if i >= self.len() {
            0.0
        } else if self.integral > 0.0 {
            self.cells[i].bin().func / (self.integral * self.len() as f32)
        } else {
            1.0 / self.len() as f32
        }
    }

    #[inline]
    fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        self.sample_continuous_in(u, self.find(u))
    }

    /// [`Row::sample_continuous`] in bin `i`, which must be `self.find(u)`.
    #[inline(always)]
    fn sample_continuous_in(&self, u: f32, i: usize) -> (f32, f32, usize) {
        let (c0, c1) = (self.cells[i].bin().cdf, self.cells[i + 1].bin().cdf);
        let du = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.5 };
        let x = ((i as f32 + du.clamp(0.0, 1.0)) / self.len() as f32).min(ONE_MINUS_EPSILON);
        (x, self.pdf_of_bin(self.bin(x)), i)
    }

    fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let i = self.find(u);
        let (c0, c1) = (self.cells[i].bin().cdf, self.cells[i + 1].bin().cdf);
        let u_remapped = if c1 > c0 {
            ((u - c0) / (c1 - c0)).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.5
        };
        (i, self.discrete_pdf(i), u_remapped)
    }

    /// The number of CDF entries `<= u`, i.e. `cdf.partition_point(|&c| c <= u)`, searched
    /// only among the entries of `u`'s bucket `k`. Every entry in a lower bucket is below `u`
    /// and every entry in a higher one above it (the bucket is monotone), so the count lies
    /// between guide entries `k` and `k + 1`.
    #[inline(always)]
    fn count_at_or_below(&self, u: f32) -> usize {
        let k = bucket(u, self.len());
        let (lo, hi) = (
            self.cells[k].bin().guide as usize,
            self.cells[k + 1].bin().guide as usize,
        );
        lo + self.cells[lo..hi].partition_point(|c| c.bin().cdf <= u)
    }

    /// The last bin `i` with `cdf[i] <= u`, skipping empty bins.
    #[inline(always)]
    fn find(&self, u: f32) -> usize {
        let n = self.len();
        // The first index with cdf > u; the bin is one before it.
        let first_above = self.count_at_or_below(u);
        let mut i = first_above.saturating_sub(1).min(n - 1);
        // Never land in a zero-weight bin through rounding at the CDF's flat parts.
        while i + 1 < n && self.cells[i + 1].bin().cdf <= self.cells[i].bin().cdf {
            i += 1;
        }
        i
    }
}

impl Distribution1D {
    /// A distribution over the given bin weights (non-negative and finite; others count as 0).
    /// An empty slice is treated as one bin.
    pub fn new(weights: &[f32]) -> Distribution1D {
        Distribution1D::build(weights, |_| ())
    }
}

impl<V: Copy + Default> Distribution1D<V> {
    /// A distribution over `weights` (as [`Distribution1D::new`]) whose bin `i` carries
    /// `values[i]` (the default where `values` is shorter).
    pub fn with_values(weights: &[f32], values: &[V]) -> Distribution1D<V> {
        Distribution1D::build(weights, |i| values.get(i).copied().unwrap_or_default())
    }

    fn build(weights: &[f32], value: impl Fn(usize) -> V) -> Distribution1D<V> {
        let (bins, integral) = build_bins(weights);
        let n = bins.len() - 1;
        let cells = bins
            .into_iter()
            .enumerate()
            .map(|(i, bin)| Cell {
                bin,
                value: if i < n { value(i) } else { V::default() },
            })
            .collect();
        Distribution1D { cells, integral }
    }

    #[inline(always)]
    fn row(&self) -> Row<'_, Cell<V>> {
        Row {
            cells: &self.cells,
            integral: self.integral,
        }
    }

    /// The number of bins.
    pub fn len(&self) -> usize {
        self.cells.len() - 1
    }

    /// Always false: there is at least one bin.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The integral of the weights over `[0, 1)` (their mean); 0 if they are all zero.
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The density at `x` in `[0, 1)` with respect to `x`.
    pub fn pdf(&self, x: f32) -> f32 {
        self.pdf_and_value(x).0
    }

    /// The value of the bin holding `x` in `[0, 1)` (clamped).
    pub fn value(&self, x: f32) -> V {
        self.cells[self.row().bin(x)].value
    }

    /// [`Distribution1D::pdf`] and [`Distribution1D::value`] at `x`, from one cell.
    pub fn pdf_and_value(&self, x: f32) -> (f32, V) {
        let row = self.row();
        let i = row.bin(x);
        (row.pdf_of_bin(i), self.cells[i].value)
    }

    /// The probability of bin `i` (its share of the total weight).
    pub fn discrete_pdf(&self, i: usize) -> f32 {
        self.row().discrete_pdf(i)
    }

    /// Inverts the CDF: returns `(x, pdf(x), bin)` for a canonical `u` in `[0, 1)`.
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        self.row().sample_continuous(u)
    }

    /// Picks a bin with probability [`Distribution1D::discrete_pdf`]; returns it, its
    /// probability and `u` re-stretched to `[0, 1)` within the bin (reusable as a fresh number).
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        self.row().sample_discrete(u)
    }

    #[cfg(test)]
    fn count_at_or_below(&self, u: f32) -> usize {
        self.row().count_at_or_below(u)
    }
}

/// A piecewise-constant density over `[0, 1)^2` on a `width x height` grid: a marginal
/// distribution over rows (`v`) and a conditional one over columns (`u`) in each row. Each
/// grid cell carries an RGB value (an environment map's texel), stored beside the cell's
/// weight so that a lookup reads one place in memory.
///
/// The rows' cells are one array of [`GridCell`]s, `height` rows of `width + 1`, held in `S`:
/// a `Vec` by default, or whatever [`Distribution2D::with_values_stored`] is given (a large
/// map's caller may keep it on huge pages, where a lookup does not also miss the TLB).
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution2D<S = Vec<GridCell>> {
    cells: S,
    /// Each row's integral (the conditional distribution's normaliser).
    integrals: Vec<f32>,
    width: usize,
    marginal: Distribution1D,
}

/// Where a sample of a [`Distribution2D`] starts its search within the row it picked, from
/// [`Distribution2D::search_start`]: two loads, one after the other, that a caller can ask
/// the cache for ahead of the sample, in turn.
#[derive(Debug, Clone, Copy)]
pub struct SearchStart<'a> {
    cells: &'a [GridCell],
    bucket: usize,
    row: usize,
}

impl<'a> SearchStart<'a> {
    /// The cell holding the guide entry the search reads first (not read here).
    #[inline]
    pub fn guide_cell(&self) -> &'a GridCell {
        &self.cells[self.bucket]
    }

    /// The row the sample picked (the marginal's bin), for
    /// [`Distribution2D::sample_with_value_in_row`].
    #[inline]
    pub fn row(&self) -> usize {
        self.row
    }

    /// The first cell the search then compares, found by reading the guide entry, and the
    /// cells either side of it, which the sample reads too when its bin is the one before the
    /// first compared (or after it): `[before, first, after]`, clamped to the row.
    #[inline]
    pub fn searched_cells(&self) -> [&'a GridCell; 3] {
        let lo = self.cells[self.bucket].bin().guide as usize;
        [
            &self.cells[lo.saturating_sub(1)],
            &self.cells[lo],
            &self.cells[(lo + 1).min(self.cells.len() - 1)],
        ]
    }
}

impl Distribution2D {
    /// From row-major weights (`weights[y * width + x]`); `weights.len()` must be `width * height`.
    /// Every cell's value is zero.
    pub fn new(weights: &[f32], width: usize, height: usize) -> Distribution2D {
        Distribution2D::with_values(weights, &[], width, height)
    }

    /// [`Distribution2D::new`] with grid cell `(x, y)` carrying `values[y * width + x]` (zero
    /// where `values` is shorter).
    pub fn with_values(
        weights: &[f32],
        values: &[Vec3],
        width: usize,
        height: usize,
    ) -> Distribution2D {
        Distribution2D::with_values_stored(weights, values, width, height, |cells| cells)
    }
}

impl<S: Deref<Target = [GridCell]>> Distribution2D<S> {
    /// [`Distribution2D::with_values`], its cells moved into the storage `store` makes of them
    /// (it must keep them as they are, in order).
    pub fn with_values_stored(
        weights: &[f32],
        values: &[Vec3],
        width: usize,
        height: usize,
        store: impl FnOnce(Vec<GridCell>) -> S,
    ) -> Distribution2D<S> {
        let width = width.max(1);
        let height = height.max(1);
        let mut cells = Vec::with_capacity(height * (width + 1));
        let mut integrals = Vec::with_capacity(height);
        // A row missing from `weights` has `width` empty bins, so every row has one stride.
        let empty = vec![0.0; width];
        for y in 0..height {
            let row = weights.get(y * width..(y + 1) * width).unwrap_or(&empty);
            let (bins, integral) = build_bins(row);
            cells.extend(bins.into_iter().enumerate().map(|(x, bin)| {
                let value = if x < width {
                    values.get(y * width + x).copied().unwrap_or(Vec3::ZERO)
                } else {
                    Vec3::ZERO
                };
                GridCell {
                    bin,
                    value: value.to_array(),
                }
            }));
            integrals.push(integral);
        }
        let marginal = Distribution1D::new(&integrals);
        Distribution2D {
            cells: store(cells),
            integrals,
            width,
            marginal,
        }
    }

    /// Row `y` of the grid (clamped to the last).
    #[inline(always)]
    fn row_at(&self, y: usize) -> Row<'_, GridCell> {
        let y = y.min(self.integrals.len() - 1);
        let stride = self.width + 1;
        Row {
            cells: &self.cells[y * stride..(y + 1) * stride],
            integral: self.integrals[y],
        }
    }

    /// The row holding `y` in `[0, 1)` (clamped).
    #[inline(always)]
    fn row(&self, y: f32) -> Row<'_, GridCell> {
        let n = self.integrals.len();
        self.row_at(((y * n as f32) as usize).min(n - 1))
    }

    /// Samples `(u, v)` in `[0, 1)^2` and returns it with its density.
    #[inline]
    pub fn sample(&self, u2: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, y) = self.marginal.sample_continuous(u2.y);
        let (u, pdf_u, _) = self.row_at(y).sample_continuous(u2.x);
        (Vec2::new(u, v), pdf_u * pdf_v)
    }

    /// Where [`Distribution2D::sample`]'s search for `u2` starts, without reading the grid:
    /// its first load, which nothing before it predicts, for a caller to prefetch.
    #[inline]
    pub fn search_start(&self, u2: Vec2) -> SearchStart<'_> {
        let y = self.marginal.row().find(u2.y);
        let row = self.row_at(y);
        SearchStart {
            row: y,
            cells: row.cells,
            bucket: bucket(u2.x, row.len()),
        }
    }

    /// The grid cell holding `p` in `[0, 1)^2` (clamped): the one that
    /// [`Distribution2D::pdf_and_value`] reads.
    #[inline]
    pub fn cell(&self, p: Vec2) -> &GridCell {
        let row = self.row(p.y);
        &row.cells[row.bin(p.x)]
    }

    /// [`Distribution2D::sample`] with the value of the grid cell holding the point.
    #[inline]
    pub fn sample_with_value(&self, u2: Vec2) -> (Vec2, f32, Vec3) {
        let (p, pdf) = self.sample(u2);
        (p, pdf, self.value(p))
    }

    /// [`Distribution2D::sample_with_value`] given the row the sample picks, which must be
    /// [`SearchStart::row`] of [`Distribution2D::search_start`] for the same `u2`: the
    /// marginal's search is not made again. The same result to the bit. A row past the last
    /// is taken as the last.
    #[inline]
    pub fn sample_with_value_in_row(&self, u2: Vec2, row: usize) -> (Vec2, f32, Vec3) {
        let row = row.min(self.marginal.len() - 1);
        let (v, pdf_v, y) = self.marginal.row().sample_continuous_in(u2.y, row);
        let (u, pdf_u, _) = self.row_at(y).sample_continuous(u2.x);
        let p = Vec2::new(u, v);
        (p, pdf_u * pdf_v, self.value(p))
    }

    /// The density at `(u, v)` in `[0, 1)^2`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        self.pdf_and_value(p).0
    }

    /// The value of the grid cell holding `p` in `[0, 1)^2` (clamped).
    #[inline]
    pub fn value(&self, p: Vec2) -> Vec3 {
        Vec3::from_array(self.cell(p).value)
    }

    /// [`Distribution2D::pdf`] and [`Distribution2D::value`] at `p`, from one cell of the grid.
    #[inline]
    pub fn pdf_and_value(&self, p: Vec2) -> (f32, Vec3) {
        let row = self.row(p.y);
        let i = row.bin(p.x);
        let value = Vec3::from_array(row.cells[i].value);
        (self.marginal.pdf(p.y) * row.pdf_of_bin(i), value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hand_computed_1d() {
        // Weights 1, 3, 0, 4 over four bins of width 1/4: integral = 8 / 4 = 2, so the pdf in
        // bin 1 is 3 / 2 and the CDF is 0, 1/8, 4/8, 4/8, 1.
        let d = Distribution1D::new(&[1.0, 3.0, 0.0, 4.0]);
        assert_eq!(d.integral(), 2.0);
        assert_eq!(d.pdf(0.3), 1.5);
        assert_eq!(d.discrete_pdf(3), 0.5);
        // u = 0.25 is a third of the way through bin 1's CDF span [1/8, 4/8): x = (1 + 1/3) / 4.
        let (x, pdf, i) = d.sample_continuous(0.25);
        assert_eq!(i, 1);
        assert!((x - (1.0 + 1.0 / 3.0) / 4.0).abs() < 1e-6);
        assert_eq!(pdf, 1.5);
        // u = 0.5 sits on the flat part of the CDF at bin 2: it must go to bin 3, never bin 2.
        assert_eq!(d.sample_continuous(0.5).2, 3);
    }

    #[test]
    fn values_sit_in_their_cells() {
        // A 3 x 2 grid: the point (0.5, 0.75) is in column 1 of row 1, cell 4; the last
        // cell's value is missing from the slice and is the default.
        let values = [10.0, 11.0, 12.0, 13.0, 14.0].map(Vec3::splat);
        let d = Distribution2D::with_values(&[1.0; 6], &values, 3, 2);
        assert_eq!(d.value(Vec2::new(0.5, 0.75)), Vec3::splat(14.0));
        assert_eq!(d.value(Vec2::new(0.0, 0.0)), Vec3::splat(10.0));
        assert_eq!(d.value(Vec2::new(0.99, 0.99)), Vec3::ZERO);
        assert_eq!(
            d.pdf_and_value(Vec2::new(0.5, 0.25)),
            (1.0, Vec3::splat(11.0))
        );
    }

    #[test]
    fn all_zero_falls_back_to_uniform() {
        let d = Distribution1D::new(&[0.0, 0.0]);
        assert_eq!(d.pdf(0.7), 1.0);
        assert_eq!(d.discrete_pdf(1), 0.5);
        let (x, _, _) = d.sample_continuous(0.75);
        assert!((x - 0.75).abs() < 1e-6);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        #[test]
        fn guided_search_equals_the_full_binary_search(
            weights in proptest::collection::vec(
                prop_oneof![Just(0.0f32), 0.0f32..1.0, 1e3f32..1e6], 1..300),
            us in proptest::collection::vec(
                prop_oneof![0.0f32..1.0, Just(0.0f32), Just(ONE_MINUS_EPSILON), -1.0f32..2.0], 32),
            picks in proptest::collection::vec(0usize..1000, 16),
        ) {
            let d = Distribution1D::new(&weights);
            let cdf: Vec<f32> = d.cells.iter().map(|c| c.bin.cdf).collect();
            // Random u, and u exactly on CDF entries and one ulp either side of them, where a
            // bucket boundary and a CDF step can meet.
            let mut probes = us.clone();
            for p in picks {
                let c = cdf[p % cdf.len()];
                probes.extend([c, f32::from_bits(c.to_bits().saturating_sub(1)), f32::from_bits(c.to_bits() + 1)]);
            }
            probes.push(f32::NAN);
            for u in probes {
                prop_assert_eq!(d.count_at_or_below(u), cdf.partition_point(|&c| c <= u), "u = {}", u);
            }
        }

        #[test]
        fn sampled_pdf_matches_evaluated_pdf(
            weights in proptest::collection::vec(0.0f32..10.0, 1..6),
            ux in 0.0f32..1.0, uy in 0.0f32..1.0,
        ) {
            let w = 2;
            let h = weights.len().div_ceil(w);
            let mut padded = weights.clone();
            padded.resize(w * h, 0.5);
            let d = Distribution2D::new(&padded, w, h);
            let (p, pdf) = d.sample(Vec2::new(ux, uy));
            prop_assert!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0);
            prop_assert!(pdf > 0.0);
            prop_assert!((d.pdf(p) - pdf).abs() <= 1e-4 * pdf.max(1.0));
        }

        #[test]
        fn a_sample_carries_the_value_of_the_cell_it_lands_in(
            weights in proptest::collection::vec(
                prop_oneof![Just(0.0f32), 0.0f32..10.0], 12),
            ux in 0.0f32..1.0, uy in 0.0f32..1.0,
        ) {
            // A 4 x 3 grid whose cells carry their own row-major index.
            let (w, h) = (4, 3);
            let values: Vec<Vec3> = (0..12).map(|i| Vec3::new(i as f32, 0.0, -1.0)).collect();
            let d = Distribution2D::with_values(&weights, &values, w, h);
            let (p, pdf, value) = d.sample_with_value(Vec2::new(ux, uy));
            let (x, y) = ((p.x * w as f32) as u32, (p.y * h as f32) as u32);
            prop_assert_eq!(value, Vec3::new((y * w as u32 + x) as f32, 0.0, -1.0));
            prop_assert_eq!(d.pdf_and_value(p), (pdf, value));
            prop_assert_eq!(d.cell(p).value, value.to_array());
            prop_assert_eq!(Distribution2D::new(&weights, w, h).sample(Vec2::new(ux, uy)), (p, pdf));
            // The cells to prefetch are the guide entry the sample reads in the row it picks,
            // and the first cell its search then compares.
            let row = d.row_at(d.marginal.sample_continuous(uy).2);
            let start = d.search_start(Vec2::new(ux, uy));
            prop_assert!(std::ptr::eq(start.guide_cell(), &row.cells[bucket(ux, w)]));
            let lo = row.cells[bucket(ux, w)].bin().guide as usize;
            prop_assert_eq!(start.row(), d.marginal.sample_continuous(uy).2);
            prop_assert_eq!(d.sample_with_value_in_row(Vec2::new(ux, uy), start.row()), (p, pdf, value));
            // A row past the last is the last, not a panic.
            let last = d.sample_with_value_in_row(Vec2::new(ux, uy), h - 1);
            prop_assert_eq!(d.sample_with_value_in_row(Vec2::new(ux, uy), usize::MAX), last);
            let [before, first, after] = start.searched_cells();
            prop_assert!(std::ptr::eq(first, &row.cells[lo]));
            prop_assert!(std::ptr::eq(before, &row.cells[lo.saturating_sub(1)]));
            prop_assert!(std::ptr::eq(after, &row.cells[(lo + 1).min(w)]));
            prop_assert!(lo <= row.count_at_or_below(ux));
        }

        #[test]
        fn each_row_samples_as_its_own_1d_distribution(
            weights in proptest::collection::vec(
                prop_oneof![Just(0.0f32), 0.0f32..10.0, 1e3f32..1e6], 1..60),
            width in 1usize..9,
            us in proptest::collection::vec(0.0f32..1.0, 8),
        ) {
            // The grid keeps its rows in one array; each must answer exactly as a
            // Distribution1D over the row's weights, and so must the marginal over their
            // integrals, whatever holds the cells.
            let height = weights.len().div_ceil(width);
            let mut padded = weights.clone();
            padded.resize(width * height, 0.0);
            let d = Distribution2D::new(&padded, width, height);
            let boxed = Distribution2D::with_values_stored(
                &padded, &[], width, height, Vec::into_boxed_slice);
            let rows: Vec<Distribution1D> =
                padded.chunks(width).map(Distribution1D::new).collect();
            let marginal =
                Distribution1D::new(&rows.iter().map(Distribution1D::integral).collect::<Vec<_>>());
            for pair in us.chunks(2) {
                let u2 = Vec2::new(pair[0], pair[1]);
                let (v, pdf_v, y) = marginal.sample_continuous(u2.y);
                let (u, pdf_u, _) = rows[y].sample_continuous(u2.x);
                let expected = (Vec2::new(u, v), pdf_u * pdf_v);
                prop_assert_eq!(d.sample(u2), expected);
                prop_assert_eq!(boxed.sample(u2), expected);
                let p = Vec2::new(u2.x, u2.y);
                let row = ((p.y * height as f32) as usize).min(height - 1);
                prop_assert_eq!(d.pdf(p), marginal.pdf(p.y) * rows[row].pdf(p.x));
                prop_assert_eq!(boxed.pdf(p), d.pdf(p));
            }
        }

        #[test]
        fn the_2d_pdf_integrates_to_one(weights in proptest::collection::vec(0.0f32..10.0, 6)) {
            let d = Distribution2D::new(&weights, 3, 2);
            // Midpoint rule over the grid's cells is exact for a piecewise-constant density.
            let mut sum = 0.0;
            for y in 0..2 {
                for x in 0..3 {
                    sum += d.pdf(Vec2::new((x as f32 + 0.5) / 3.0, (y as f32 + 0.5) / 2.0)) / 6.0;
                }
            }
            prop_assert!((sum - 1.0).abs() < 1e-4);
        }
    }
}
