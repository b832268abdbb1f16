//! Sampling maths, one home, each with the verbs sample, pdf and invert:
//! - [`warp`]: the unit square to directions (uniform sphere, cosine hemisphere);
//! - [`alias`]: a discrete distribution sampled in O(1) (Walker's alias method);
//! - [`cdf_grid`]: a distribution over a grid's cells, a row then a column by inversion,
//!   which keeps stratified numbers stratified (an environment map's cells);
//! - [`distribution`]: piecewise-constant densities in one and two dimensions (the
//!   environment map's importance sampling);
//! - [`texel_distribution`]: a piecewise-constant density over a lat-long map's texels, to
//!   fold a fixed affinity map into a proposal.

pub mod alias;
pub mod cdf_grid;
pub mod distribution;
pub mod texel_distribution;
pub mod warp;

pub use alias::AliasTable;
pub use cdf_grid::{cumulative, guide_table, invert_cumulative, invert_guided, CdfGrid};
pub use distribution::{Distribution1D, Distribution2D};
pub use texel_distribution::TexelDistribution;
pub use warp::{cosine_hemisphere, uniform_sphere};
