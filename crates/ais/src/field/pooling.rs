//! A cell's texel visibilities pooled up a quadtree of its octahedral texels.
//!
//! A fine map learns slowly: a cell of 16 × 16 texels splits its rays 256 ways, and a texel
//! seen by three rays says little. Its neighbours' rays say more about it than its cell's
//! average does, since visibility changes little from one texel to the next except at an
//! edge. So the estimate of a texel leans on its 2 × 2 block, the block's on its 2 × 2
//! block of blocks, and so on up to the whole cell: at each level, a block's own counts get
//! `prior` pseudo-observations at its parent's estimate. Where a texel has many rays, its
//! own evidence decides (a window's edge stays sharp); where it has few, its block speaks
//! for it. The octahedral square subdivides into squares, so a block is a patch of
//! neighbouring directions (its sides cross the square's diagonals only where the
//! hemispheres meet).

use super::{texel_visibility, TexelCounts};

/// The visibility of every texel of a `side × side` cell (row-major counts) whose own
/// visibility is `cell`, pooled with `prior` pseudo-observations per level (see the module
/// documentation).
pub fn pooled_visibilities(counts: &[TexelCounts], side: u32, cell: f32, prior: f32) -> Vec<f32> {
    // Block sums level by level, finest first; level 0 is the texels themselves.
    let mut levels = vec![(side as usize, counts.to_vec())];
    while let Some(&(size, ref finer)) = levels.last().filter(|(size, _)| *size > 1) {
        let coarse = size.div_ceil(2);
        let mut sums = vec![TexelCounts::default(); coarse * coarse];
        for (index, &count) in finer.iter().enumerate() {
            let (row, column) = (index / size, index % size);
            sums[(row / 2) * coarse + column / 2].add(count);
        }
        levels.push((coarse, sums));
    }
    // Estimates from the top down; the coarsest level (one block: the cell) is `cell`.
    let (mut estimates, mut parent_size) = (vec![cell], 1);
    for (size, sums) in levels.iter().rev().skip(1) {
        estimates = sums
            .iter()
            .enumerate()
            .map(|(index, &count)| {
                let (row, column) = (index / size, index % size);
                texel_visibility(
                    count,
                    estimates[(row / 2) * parent_size + column / 2],
                    prior,
                )
            })
            .collect();
        parent_size = *size;
    }
    estimates
}

/// Whether any ray of the cell went into the 2 × 2 block of texels holding texel `index`
/// (the texel itself on a 1 × 1 map): elsewhere (mostly behind the surface) the cell knows
/// nothing, and its estimate is only its blocks'.
pub fn block_seen(counts: &[TexelCounts], side: u32, index: usize) -> bool {
    let side = side as usize;
    let (row, column) = (index / side / 2 * 2, index % side / 2 * 2);
    (row..(row + 2).min(side))
        .flat_map(|r| (column..(column + 2).min(side)).map(move |c| r * side + c))
        .any(|texel| counts[texel].traced > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(free: u32, traced: u32) -> TexelCounts {
        TexelCounts { free, traced }
    }

    #[test]
    fn a_texel_with_few_rays_leans_on_its_block() {
        // 4 × 4 texels; the top-left 2 × 2 block is blocked (40 rays each but one texel,
        // which has a single free ray); the rest are unseen.
        let mut grid = vec![TexelCounts::default(); 16];
        for texel in [0, 1, 4] {
            grid[texel] = counts(0, 40);
        }
        grid[5] = counts(1, 1);
        let estimates = pooled_visibilities(&grid, 4, 0.5, 2.0);
        // Alone, the texel with one free ray would be (1 + 2 · 0.5) / 3 = 0.67; its block
        // (1 free of 121: (1 + 2 · 0.5) / 123) pulls it to (1 + 2 · 2/123) / 3.
        assert!(
            (estimates[5] - (1.0 + 4.0 / 123.0) / 3.0).abs() < 1e-6,
            "{}",
            estimates[5]
        );
        assert!(estimates[0] < 0.01);
        // Unseen texels are their block's estimate; an unseen block, its parent's.
        assert_eq!(estimates[10], estimates[15]);
        assert!(estimates[10] > estimates[5]);
        assert!(block_seen(&grid, 4, 5) && !block_seen(&grid, 4, 10));
    }

    #[test]
    fn a_texel_with_many_rays_keeps_its_own_evidence() {
        // A window's edge: one texel always free among blocked ones, each seen 400 times.
        let mut grid = vec![counts(0, 400); 16];
        grid[6] = counts(400, 400);
        let estimates = pooled_visibilities(&grid, 4, 0.1, 2.0);
        assert!(estimates[6] > 0.99, "{}", estimates[6]);
        assert!(estimates[7] < 0.01);
    }

    #[test]
    fn odd_sides_and_a_single_texel_are_pooled_too() {
        let grid = vec![counts(3, 4); 9];
        let estimates = pooled_visibilities(&grid, 3, 0.75, 2.0);
        assert_eq!(estimates.len(), 9);
        assert!(estimates.iter().all(|&e| (e - 0.75).abs() < 1e-6));
        assert_eq!(pooled_visibilities(&[counts(0, 5)], 1, 0.3, 2.0), vec![0.3]);
        assert!(block_seen(&grid, 3, 8));
    }
}
