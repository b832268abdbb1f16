//! A point receiving light, and what the light queries of one gather there share.
//!
//! Every candidate of a gather starts at the same point. A rectangle light's spherical
//! rectangle as seen from that point (four acos in f64, and the solid angle) is needed to
//! sample it and for its density; a [`Receiver`] computes it once per light and keeps it for
//! the gather's other candidates, in a few direct-mapped slots (no allocation). A view is
//! over a hundred bytes, so candidates read it in place rather than copy it.

use super::spherical_rectangle::{Rectangle, View};
use super::{Environment, EnvironmentGuide, RegionChoice, Toward};
use ais::sampling::AliasTable;
use glam::Vec3;
use std::cell::RefCell;

/// How many rectangle lights' views a receiver keeps at once.
const VIEW_SLOTS: usize = 4;

/// A slot: the rectangle's address (its key within one scene's lights) and its view.
type ViewSlot = RefCell<Option<(usize, Option<View>)>>;

/// A point where light is gathered.
pub struct Receiver<'a> {
    /// The point.
    pub point: Vec3,
    /// Light sampling draws the environment from its product with this guide (guided
    /// gathers), or from the environment alone (`None`).
    pub environment_guide: Option<&'a EnvironmentGuide>,
    /// Light sampling chooses among the lights by this table (a field cell's learned
    /// choice), or by their power (`None`).
    pub light_choice: Option<&'a AliasTable>,
    /// Light sampling draws area light `l`'s sample square from `region_choices[l]` where
    /// that is given (a field cell's learned regions), else uniformly.
    pub region_choices: &'a [Option<RegionChoice>],
    /// A normal `m` such that no direction `w` with `m · w <= 0` can carry light to the
    /// viewer (the surface's BSDF only reflects), where known: lights wholly on the other
    /// side are not drawn.
    pub support_side: Option<Vec3>,
    views: [ViewSlot; VIEW_SLOTS],
}

impl<'a> Receiver<'a> {
    /// A receiver at `point`, unguided.
    pub fn new(point: Vec3) -> Self {
        Receiver {
            point,
            environment_guide: None,
            light_choice: None,
            region_choices: &[],
            support_side: None,
            views: Default::default(),
        }
    }

    /// A receiver at `point` whose light sampling draws the environment through `guide`.
    pub fn guided(point: Vec3, guide: &'a EnvironmentGuide) -> Self {
        Receiver {
            environment_guide: Some(guide),
            ..Receiver::new(point)
        }
    }

    /// A direction drawn from `u` from `environment`, by this receiver's guide when it has
    /// one.
    #[inline(always)]
    pub fn sample_environment(&self, environment: &Environment, u: [f32; 2]) -> Toward {
        match self.environment_guide {
            Some(guide) => guide.sample(environment, u),
            None => environment.sample_toward(u),
        }
    }

    /// The weighing of area light `light`'s regions, if the receiver has one.
    #[inline]
    pub fn region_choice(&self, light: usize) -> Option<&'a RegionChoice> {
        self.region_choices.get(light)?.as_ref()
    }

    /// `read` of how `rectangle` looks from the point (None: seen edge-on, and `read` is not
    /// called), the view computed on first use.
    #[inline]
    pub(super) fn with_rectangle_view<R>(
        &self,
        rectangle: &Rectangle,
        read: impl FnOnce(&View) -> R,
    ) -> Option<R> {
        let key = rectangle as *const Rectangle as usize;
        let slot = &self.views[(key / std::mem::align_of::<Rectangle>()) % VIEW_SLOTS];
        if let Some((held, view)) = slot.borrow().as_ref() {
            if *held == key {
                return view.as_ref().map(read);
            }
        }
        let view = rectangle.view(self.point);
        let result = view.as_ref().map(read);
        *slot.borrow_mut() = Some((key, view));
        result
    }

    /// The solid angle `rectangle` subtends at the point (0 where it is seen edge-on).
    #[inline]
    pub(super) fn rectangle_solid_angle(&self, rectangle: &Rectangle) -> f64 {
        self.with_rectangle_view(rectangle, View::solid_angle)
            .unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_rectangle_gets_its_own_view_even_when_slots_collide() {
        // More rectangles than slots, so some share a slot and must not see another's view.
        let rectangles: Vec<Rectangle> = (0..3 * VIEW_SLOTS)
            .map(|i| {
                let corner = Vec3::new(i as f32 * 0.5 - 2.0, -0.5, 1.0 + i as f32 * 0.3);
                Rectangle::new(corner, Vec3::X * (0.2 + i as f32 * 0.1), Vec3::Y, false)
                    .expect("orthogonal edges")
            })
            .collect();
        let point = Vec3::new(0.1, 0.2, 0.0);
        let receiver = Receiver::new(point);
        for round in 0..3 {
            for (i, rectangle) in rectangles.iter().enumerate().rev().skip(round) {
                let held = receiver.rectangle_solid_angle(rectangle);
                assert_eq!(held, rectangle.solid_angle(point), "rectangle {i}");
            }
        }
    }
}
