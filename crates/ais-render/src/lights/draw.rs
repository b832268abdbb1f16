//! A candidate's draw by light sampling, made at once or left to be made together with the
//! other draws of its kind in a run of candidates, whose steps then overlap or run in
//! vector lanes: an environment map's ([`super::EnvironmentDraws`]) and an area light's
//! ([`super::AreaDraws`]).

use super::{AreaDraw, Toward};

/// A candidate's draw: made, or left to be made with other candidates'.
#[derive(Clone, Copy, Debug)]
pub enum Draw {
    /// The draw is made (`None`: no direction).
    Made(Option<Toward>),
    /// A direction from the environment for these numbers is still to be drawn.
    Environment([f32; 2]),
    /// A point of an area light is still to be drawn.
    Area(AreaDraw),
}

/// The most draws a run holds.
pub const RUN: usize = 16;

/// Draws of one kind left for later in a run of candidates, each with its candidate's slot.
#[derive(Debug)]
pub(super) struct HeldDraws<T> {
    slots: [usize; RUN],
    draws: [T; RUN],
    count: usize,
}

impl<T: Copy + Default> Default for HeldDraws<T> {
    fn default() -> Self {
        HeldDraws {
            slots: [0; RUN],
            draws: [T::default(); RUN],
            count: 0,
        }
    }
}

impl<T> HeldDraws<T> {
    /// Holds `draw` for the candidate in `slot`. At most [`RUN`] draws are held.
    pub(super) fn push(&mut self, slot: usize, draw: T) {
        assert!(self.count < RUN, "a run holds at most {RUN} draws");
        (self.slots[self.count], self.draws[self.count]) = (slot, draw);
        self.count += 1;
    }

    /// The draws held and their slots, in the order held; none is held afterwards.
    pub(super) fn take(&mut self) -> (&[usize], &mut [T]) {
        let count = std::mem::take(&mut self.count);
        (&self.slots[..count], &mut self.draws[..count])
    }
}
