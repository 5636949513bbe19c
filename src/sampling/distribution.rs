//! Piecewise-constant distributions on `[0, 1)` and `[0, 1)^2`, sampled by inverting their
//! cumulative sums (pbrt-v4's `PiecewiseConstant1D` and `PiecewiseConstant2D`; Pharr, Jakob
//! and Humphreys, *Physically Based Rendering*, 4th ed., sections A.4.2 and A.5.2).
//!
//! The environment light samples its image with one. Sums are kept in double precision and
//! sampled with 53-bit numbers, so that a cell whose share is below f32's grid of 2^-24 (a sky
//! texel beside a sun 10^6 times brighter) is still drawn as often as its density says.

/// A piecewise-constant density on `[0, 1)` over `n` equal cells, proportional to the
/// (non-negative) weights it was built from.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// `cdf[i]`: the weight of cells `0..i` over the total; `cdf[0] = 0`, `cdf[n] = 1`.
    cdf: Vec<f64>,
    /// The sum of the weights.
    total: f64,
}

impl Distribution1D {
    /// The distribution of `weights` (negative and NaN weights count as 0). With no weight at
    /// all it is empty: [`Distribution1D::sample`] then gives `None`.
    pub fn new(weights: impl IntoIterator<Item = f64>) -> Self {
        let mut cdf = vec![0.0];
        let mut acc = 0.0;
        for w in weights {
            // `max` sends NaN to 0 as well.
            acc += w.max(0.0);
            cdf.push(acc);
        }
        let total = acc;
        if total > 0.0 && total.is_finite() {
            cdf.iter_mut().for_each(|c| *c /= total);
            if let Some(last) = cdf.last_mut() {
                *last = 1.0;
            }
        }
        Distribution1D { cdf, total }
    }

    /// Number of cells.
    #[inline]
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// True if it has no cells.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sum of the weights.
    #[inline]
    pub fn total(&self) -> f64 {
        self.total
    }

    /// True if it can be sampled: some weight, finite.
    #[inline]
    pub fn is_samplable(&self) -> bool {
        self.total > 0.0 && self.total.is_finite()
    }

    /// Probability of cell `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f64 {
        if !self.is_samplable() {
            return 0.0;
        }
        self.cdf[i + 1] - self.cdf[i]
    }

    /// The cell that `u`, uniform in `[0, 1)`, picks (the first whose cumulative share exceeds
    /// `u`: a cell of weight 0 is never picked), `u`'s place within it in `[0, 1)`, and the
    /// cell's probability; `None` when there is no weight.
    #[inline]
    pub fn sample(&self, u: f64) -> Option<(usize, f64, f64)> {
        if !self.is_samplable() {
            return None;
        }
        let n = self.len();
        // cdf[0] = 0 <= u always, so the count is at least 1.
        let i = (self.cdf.partition_point(|&c| c <= u) - 1).min(n - 1);
        let pmf = self.cdf[i + 1] - self.cdf[i];
        let offset = ((u - self.cdf[i]) / pmf).clamp(0.0, 1.0 - f64::EPSILON / 2.0);
        Some((i, offset, pmf))
    }
}

/// A piecewise-constant density on `[0, 1)^2` over `columns x rows` equal cells: a row is
/// picked by its total weight (the marginal), then a cell within it (the conditional).
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    /// One distribution over the columns per row.
    rows: Vec<Distribution1D>,
    /// The rows' totals.
    marginal: Distribution1D,
}

impl Distribution2D {
    /// The distribution of `weight(column, row)` over `columns x rows` cells.
    pub fn new(columns: usize, rows: usize, weight: impl Fn(usize, usize) -> f64) -> Self {
        let rows: Vec<Distribution1D> = (0..rows)
            .map(|r| Distribution1D::new((0..columns).map(|c| weight(c, r))))
            .collect();
        let marginal = Distribution1D::new(rows.iter().map(Distribution1D::total));
        Distribution2D { rows, marginal }
    }

    /// Number of columns and of rows.
    #[inline]
    pub fn size(&self) -> (usize, usize) {
        (
            self.rows.first().map_or(0, Distribution1D::len),
            self.rows.len(),
        )
    }

    /// The sum of all weights.
    #[inline]
    pub fn total(&self) -> f64 {
        self.marginal.total()
    }

    /// A point of `[0, 1)^2` drawn from `(u1, u2)`, uniform in `[0, 1)^2` (`u2` picks the row,
    /// `u1` the column), with its density; `None` when there is no weight.
    #[inline]
    pub fn sample(&self, u1: f64, u2: f64) -> Option<((f64, f64), f64)> {
        let (r, dv, pr) = self.marginal.sample(u2)?;
        let (c, du, pc) = self.rows[r].sample(u1)?;
        let (nc, nr) = self.size();
        let point = ((c as f64 + du) / nc as f64, (r as f64 + dv) / nr as f64);
        Some((point, pr * pc * (nc * nr) as f64))
    }

    /// The density at cell `(column, row)`.
    #[inline]
    pub fn pdf_cell(&self, column: usize, row: usize) -> f64 {
        let (nc, nr) = self.size();
        self.marginal.pmf(row) * self.rows[row].pmf(column) * (nc * nr) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each cell is picked exactly over the share of `[0, 1)` its weight gives it, and the
    /// offset runs across the cell.
    #[test]
    fn cells_follow_their_weights() {
        let d = Distribution1D::new([1.0, 0.0, 3.0]);
        assert_eq!(d.sample(0.0), Some((0, 0.0, 0.25)));
        assert_eq!(d.sample(0.125).map(|s| s.0), Some(0));
        assert_eq!(d.sample(0.25).map(|s| (s.0, s.1)), Some((2, 0.0)));
        assert_eq!(d.sample(0.625).map(|s| (s.0, s.1)), Some((2, 0.5)));
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(Distribution1D::new([0.0, f64::NAN, -1.0]).sample(0.5), None);
    }

    /// A cell of share 1e-12 (below f32's grid) is picked where its share lies.
    #[test]
    fn tiny_cells_are_reachable() {
        let d = Distribution1D::new([1e12, 1.0, 1e12]);
        assert_eq!(d.sample(0.5).map(|s| s.0), Some(1));
        assert!((d.pmf(1) / 0.5e-12 - 1.0).abs() < 1e-3);
    }

    /// The 2D density integrates to 1 over its cells and matches the weights.
    #[test]
    fn density_matches_weights() {
        let d = Distribution2D::new(3, 2, |c, r| (c + 2 * r) as f64);
        let total: f64 = (0..2)
            .flat_map(|r| (0..3).map(move |c| (c, r)))
            .map(|(c, r)| d.pdf_cell(c, r) / 6.0)
            .sum();
        assert!((total - 1.0).abs() < 1e-12);
        assert!((d.pdf_cell(2, 1) - 4.0 / 12.0 * 6.0).abs() < 1e-12);
        let ((x, y), pdf) = d.sample(0.99, 0.99).unwrap();
        assert!(x > 2.0 / 3.0 && y > 0.5);
        assert!((pdf - d.pdf_cell(2, 1)).abs() < 1e-12);
    }
}
