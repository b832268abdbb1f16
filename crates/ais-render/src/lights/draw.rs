//! A candidate's draw by light sampling, made at once or left to be made together with the
//! other draws of its kind in a run of candidates, whose steps then overlap or run in
//! vector lanes: an environment map's ([`super::EnvironmentDraws`]) and a rectangle light's
//! ([`super::RectangleDraws`]).

use super::{RectangleDraw, Toward};

/// A candidate's draw: made, or left to be made with other candidates'.
#[derive(Clone, Copy, Debug)]
pub enum Draw {
    /// The draw is made (`None`: no direction).
    Made(Option<Toward>),
    /// A direction from the environment map for these numbers is still to be drawn.
    Environment([f32; 2]),
    /// A point of a rectangle light is still to be drawn.
    Rectangle(RectangleDraw),
}
