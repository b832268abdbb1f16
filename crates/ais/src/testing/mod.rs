//! The test kit (cargo feature `testing`): what a host needs to validate its own samplers
//! and its integration of the library.
//! - [`ChiSquareTest`]: the chi-square harness for samplers of directions, shaped like
//!   Mitsuba 3's `ChiSquareTest(domain, sample, pdf)`;
//! - [`chi2`]: the statistic and its p-value, for other domains;
//! - [`crate::analytic`]: gather scenes with exact integrals.

pub mod chi2;
mod chi_square_test;

pub use chi_square_test::{ChiSquareOutcome, ChiSquareTest, Drawn};
