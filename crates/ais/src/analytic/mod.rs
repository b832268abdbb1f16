//! Analytic gather scenes whose exact integrals are known.
//!
//! A gather point with normal +z sees a linear sky `L(w) = c0 + c1 (d·w)`, optionally a small
//! bright sun cap, and occluders made of spherical caps (either caps that block, or "windows":
//! everything is blocked except the caps). The integrand is diffuse direct lighting,
//! `f(w) = L(w) · V(w) · max(0, w_z) / π`, and its integral is closed-form because the first
//! and second moments of a spherical cap are. These scenes validate the library (tests, the
//! study example, the gather example) and can validate a host's integration code too.

mod cap;
mod gather;
mod moments;
mod proposal;
mod scene;

pub use cap::Cap;
pub use gather::{AnalyticGather, GatherTarget};
pub use moments::Moments;
pub use proposal::Proposal;
pub use scene::{Occlusion, Scene, SceneError, Sky, Sun};
