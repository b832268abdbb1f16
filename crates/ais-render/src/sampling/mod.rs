//! Sampling maths, one home: warps from the unit square to directions, and piecewise-constant
//! distributions in one and two dimensions (sample, pdf, invert).

mod distribution;
mod warp;

pub use distribution::{Distribution1D, Distribution2D};
pub use warp::{cosine_hemisphere, uniform_sphere};
