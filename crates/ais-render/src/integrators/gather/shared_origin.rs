//! What a gather's shadow rays, which share an origin, learn from one another: the blockers
//! they met ([`RecentBlockers`]), and the lights toward which nothing can block them. The
//! blockers also go on to the tile's next gather where most of the rays were blocked
//! ([`RecentBlockers::passed_on`]).
//!
//! Toward a rectangle or a sphere light, every ray from the gather's origin lies in one
//! shaft ([`Shaft`]). Once a ray toward the light has come back free, and the run of
//! candidates being traced still holds a few rays toward it, the next one asks the
//! geometry whether anything but the light reaches into the shaft. If nothing does, that
//! ray and every later one toward the light are free without a traversal; if something
//! does, the light's rays are traced one by one as before, and its shaft is not asked
//! about again. The answers are those of tracing every ray, but for a ray that grazes a
//! sphere light's rim: tracing can find it blocked by the light itself within rounding,
//! where the segment to a point seen on a sphere never enters it.
//!
//! [`Shaft`]: crate::geometry::Shaft

use super::strategy::GatherPoint;
use crate::geometry::{LeavingSurface, Ray, RecentBlockers};
use crate::lights::Toward;
use crate::world::World;
use glam::Vec3;

/// How many rays toward a light, the one about to be traced included, a run must still
/// hold for its shaft to be asked about: a shaft's test costs about as much as a few rays,
/// and pays only for the rays it answers.
const RAYS_TO_COME_FOR_TEST: u8 = 3;

/// How many area lights (the first, by index) a gather keeps a shaft's answer for.
const TRACKED_LIGHTS: usize = 8;

/// What a gather knows of the shaft toward one light.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum ShaftState {
    /// No ray toward the light yet.
    #[default]
    Untried,
    /// Rays toward it came back free, and none was blocked.
    Free,
    /// Nothing reaches into the shaft from this apex (the rays' origin).
    Clear(Vec3),
    /// A ray was blocked, or something may reach into the shaft: rays are traced.
    Traced,
}

/// The shadow rays of one gather: the blockers they met, and what is known of the shafts
/// toward the lights they aim at.
#[derive(Debug, Default)]
pub struct SharedOrigin {
    /// The blockers, tried first ([`RecentBlockers`]).
    pub blockers: RecentBlockers,
    shafts: [ShaftState; TRACKED_LIGHTS],
    /// How many rays toward each light the run being traced still holds.
    to_come: [u8; TRACKED_LIGHTS],
}

impl SharedOrigin {
    /// A gather's shadow rays, starting from the blockers an earlier gather passed on
    /// ([`RecentBlockers::passed_on`]).
    pub fn after(blockers: RecentBlockers) -> Self {
        SharedOrigin {
            blockers,
            ..SharedOrigin::default()
        }
    }

    /// Counts the rays toward each light in a run of candidates about to be traced
    /// (`drawn`, their sources found); without it, no shaft is asked about.
    pub fn expect_run(&mut self, world: &World, drawn: &[Option<Toward>]) {
        let lights = drawn.iter().flatten();
        self.expect(lights.map(|toward| world.lights.aimed_shaft_light(toward)));
    }

    /// [`SharedOrigin::expect_run`] for a run whose rays aim at `lights` (each ray's light
    /// whose shafts bound its rays, [`crate::lights::Lights::aimed_shaft_light`]).
    pub fn expect(&mut self, lights: impl IntoIterator<Item = Option<usize>>) {
        self.to_come = [0; TRACKED_LIGHTS];
        for light in lights.into_iter().flatten() {
            if light < TRACKED_LIGHTS {
                self.to_come[light] = self.to_come[light].saturating_add(1);
            }
        }
    }

    /// Whether `ray`, the shadow ray of `toward` from `at`, is blocked.
    pub fn occluded(
        &mut self,
        world: &World,
        at: &GatherPoint,
        toward: &Toward,
        ray: &Ray,
    ) -> bool {
        let light = world.lights.aimed_shaft_light(toward);
        self.occluded_aiming(world, at, light, ray)
    }

    /// Whether `ray` from `at`, a shadow ray toward `light` (as in
    /// [`SharedOrigin::expect`]), is blocked.
    pub fn occluded_aiming(
        &mut self,
        world: &World,
        at: &GatherPoint,
        light: Option<usize>,
        ray: &Ray,
    ) -> bool {
        let Some(light) = light.filter(|&l| l < TRACKED_LIGHTS) else {
            return world.geometry.occluded_after(ray, &mut self.blockers);
        };
        let to_come = self.to_come[light];
        self.to_come[light] = to_come.saturating_sub(1);
        match self.shafts[light] {
            ShaftState::Clear(apex) if apex == ray.origin => {
                self.blockers.note_free();
                return false;
            }
            ShaftState::Free if to_come >= RAYS_TO_COME_FOR_TEST => {
                if shaft_is_clear(world, at, light, ray.origin) {
                    self.shafts[light] = ShaftState::Clear(ray.origin);
                    self.blockers.note_free();
                    return false;
                }
                self.shafts[light] = ShaftState::Traced;
            }
            _ => {}
        }
        let blocked = world.geometry.occluded_after(ray, &mut self.blockers);
        self.shafts[light] = match (self.shafts[light], blocked) {
            (ShaftState::Untried | ShaftState::Free, true) => ShaftState::Traced,
            (ShaftState::Untried, false) => ShaftState::Free,
            (state, _) => state,
        };
        blocked
    }
}

/// Whether nothing but `light` itself reaches into the shaft from `apex` (a ray's origin,
/// offset from `at`'s surface) toward it.
fn shaft_is_clear(world: &World, at: &GatherPoint, light: usize, apex: Vec3) -> bool {
    let (point, normal) = (at.receiver.point, at.frame.geometric);
    // The side of the surface the rays leave to is the apex's.
    let height = normal.dot(apex - point);
    let surface = LeavingSurface {
        point,
        normal: normal * height.signum(),
        offset: height.abs(),
    };
    let shaft = world.lights.shaft_toward(light, apex, surface);
    shaft.is_some_and(|toward| {
        world
            .geometry
            .shaft_is_clear(&toward.shaft, toward.own_shape)
    })
}
