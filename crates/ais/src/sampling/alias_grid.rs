//! A discrete distribution over the cells of a grid, sampled in O(1) from two uniform
//! numbers: a row by one alias table, then a column by that row's alias table.
//!
//! All the rows' tables sit in one block, row after row, so a draw makes two dependent table
//! reads, not four (as a table per row, each behind its own pointer, would). This is the
//! layout for thousands of cells drawn once per sample. It suits independent random numbers:
//! it scatters stratified ones over the grid (see [`super::CdfGrid`], which keeps them).

use super::alias::{build_bins, draw, AliasBin};
use super::AliasTable;

/// A distribution over `rows × columns` cells (row-major) sampled in O(1).
#[derive(Clone, Debug)]
pub struct AliasGrid {
    columns: usize,
    /// The rows by their total weight.
    rows: AliasTable,
    /// Each row's cells by weight within the row: row `r` is `cells[r * columns..][..columns]`.
    cells: Vec<AliasBin>,
    /// Each cell's probability.
    probabilities: Vec<f32>,
}

impl AliasGrid {
    /// A grid proportional to `weights` (row-major, `columns` per row; a last partial row is
    /// dropped). Negative and non-finite weights count as zero; all-zero weights give the
    /// uniform distribution.
    pub fn new(weights: &[f64], columns: usize) -> Self {
        let columns = columns.max(1);
        let rows = (weights.len() / columns).max(1);
        let mut clean: Vec<f64> = (0..rows * columns)
            .map(|i| weights.get(i).copied().unwrap_or(0.0))
            .map(|w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
            .collect();
        if clean.iter().sum::<f64>() <= 0.0 {
            clean.iter_mut().for_each(|w| *w = 1.0);
        }
        let row_sums: Vec<f64> = clean
            .chunks_exact(columns)
            .map(|r| r.iter().sum())
            .collect();
        let sum: f64 = row_sums.iter().sum();
        let mut cells = Vec::with_capacity(rows * columns);
        for (row, &row_sum) in clean.chunks_exact(columns).zip(&row_sums) {
            if row_sum > 0.0 {
                cells.extend(build_bins(row, row_sum));
            } else {
                // Never drawn (the row has no weight); any valid table will do.
                cells.extend(build_bins(&vec![1.0; columns], columns as f64));
            }
        }
        AliasGrid {
            columns,
            rows: AliasTable::new(&row_sums),
            cells,
            probabilities: clean.iter().map(|&w| (w / sum) as f32).collect(),
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.probabilities.len()
    }

    /// Whether there are no cells (never: at least one cell exists).
    pub fn is_empty(&self) -> bool {
        self.probabilities.is_empty()
    }

    /// Probability of cell `cell` (row-major index).
    #[inline]
    pub fn probability(&self, cell: usize) -> f32 {
        self.probabilities[cell]
    }

    /// A cell (row-major index) drawn from `u` ∈ [0, 1)²: its row from `u[1]`, its column
    /// from `u[0]`. Also returns what is left of `u[0]` and `u[1]`, each uniform in [0, 1)
    /// and independent of the cell when `u` is uniform.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> (usize, [f32; 2]) {
        let (row, column, left) = self.sample_row_column(u);
        (row * self.columns + column, left)
    }

    /// [`AliasGrid::sample`], giving the cell as its row and column.
    #[inline]
    pub fn sample_row_column(&self, u: [f32; 2]) -> (usize, usize, [f32; 2]) {
        let (row, left_y) = self.rows.sample(u[1]);
        let start = row * self.columns;
        let (column, left_x) = draw(&self.cells[start..start + self.columns], u[0]);
        (row, column, [left_x, left_y])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// How often each cell is drawn over a fine grid of `u`.
    fn frequencies(grid: &AliasGrid, steps: usize) -> Vec<f64> {
        let mut counts = vec![0.0; grid.len()];
        for i in 0..steps {
            for j in 0..steps {
                let u = [
                    (i as f32 + 0.5) / steps as f32,
                    (j as f32 + 0.5) / steps as f32,
                ];
                let (cell, left) = grid.sample(u);
                assert!(left.iter().all(|l| (0.0..1.0).contains(l)));
                counts[cell] += 1.0 / (steps * steps) as f64;
            }
        }
        counts
    }

    #[test]
    fn cells_are_drawn_with_their_weight() {
        // Uneven weights, an empty row and zero cells, as a sky with a sun has.
        let weights = [1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 2.0, 2.0, 0.5, 0.0, 9.0, 0.5];
        let grid = AliasGrid::new(&weights, 3);
        let sum: f64 = weights.iter().sum();
        for (cell, frequency) in frequencies(&grid, 600).into_iter().enumerate() {
            let expected = weights[cell] / sum;
            assert!(
                (frequency - expected).abs() < 2e-3,
                "cell {cell}: {frequency}"
            );
            assert!((grid.probability(cell) as f64 - expected).abs() < 1e-6);
            if weights[cell] == 0.0 {
                assert_eq!(frequency, 0.0, "cell {cell} has no weight");
            }
        }
    }

    #[test]
    fn all_zero_weights_give_the_uniform_grid() {
        let grid = AliasGrid::new(&[0.0, f64::NAN, -1.0, 0.0], 2);
        for cell in 0..4 {
            assert!((grid.probability(cell) - 0.25).abs() < 1e-7);
        }
        assert_eq!(grid.sample([0.99, 0.99]).0, 3);
    }
}
