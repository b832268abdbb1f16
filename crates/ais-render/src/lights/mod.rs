//! All emitters of a scene: an optional environment, area lights and delta lights (point,
//! spot, directional), chosen in proportion to their estimated power for light sampling (an
//! alias table: O(1) per choice).

mod area;
mod delta;
mod environment;
mod environment_guide;
mod mesh_emitter;
pub(crate) mod reader;
mod receiver;
mod spherical_rectangle;
mod toward;

pub use area::{AreaLight, AreaSample, AreaShape};
pub use delta::{DeltaArrival, DeltaLight, Spot};
pub use environment::{luminance, Environment, EnvironmentMap};
pub use environment_guide::{EnvironmentGuide, EnvironmentPartition};
pub use mesh_emitter::MeshEmitter;
pub use receiver::Receiver;
pub use spherical_rectangle::Rectangle;
pub use toward::Toward;

use crate::geometry::Ray;
use ais::sampling::AliasTable;
use glam::Vec3;
use std::f64::consts::PI;

/// The emitters of a scene.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    /// The environment, if any.
    pub environment: Option<Environment>,
    /// Area lights.
    pub area: Vec<AreaLight>,
    /// Point, spot and directional lights.
    pub delta: Vec<DeltaLight>,
    /// For each geometry shape, its area light (index into `area`).
    pub shape_lights: Vec<Option<usize>>,
    /// Choice of a light: area lights first, then delta lights, then the environment.
    choice: Option<AliasTable>,
}

/// A scene's emitters, before [`Lights::new`] weighs them.
#[derive(Clone, Debug, Default)]
pub struct Emitters {
    /// The environment, if any.
    pub environment: Option<Environment>,
    /// Area lights.
    pub area: Vec<AreaLight>,
    /// Point, spot and directional lights.
    pub delta: Vec<DeltaLight>,
}

impl Lights {
    /// Lights with selection weights from their power; the environment's power is taken as
    /// π · mean luminance · π R² for a scene of bounding radius `scene_radius`.
    pub fn new(emitters: Emitters, shape_count: usize, scene_radius: f64) -> Self {
        let Emitters {
            environment,
            area,
            delta,
        } = emitters;
        let mut shape_lights = vec![None; shape_count];
        for (index, light) in area.iter().enumerate() {
            shape_lights[light.shape_index as usize] = Some(index);
        }
        let mut weights: Vec<f64> = area.iter().map(AreaLight::power).collect();
        weights.extend(delta.iter().map(|light| light.power(scene_radius)));
        if let Some(environment) = &environment {
            weights.push(PI * environment.mean_luminance() * PI * scene_radius * scene_radius);
        }
        let choice = (!weights.is_empty()).then(|| AliasTable::new(&weights));
        Lights {
            environment,
            area,
            delta,
            shape_lights,
            choice,
        }
    }

    /// The environment's index in the choice of a light.
    fn environment_index(&self) -> usize {
        self.area.len() + self.delta.len()
    }

    /// Whether the scene has no emitter at all.
    pub fn is_empty(&self) -> bool {
        self.choice.is_none()
    }

    /// Probability of choosing light `index` (area lights first, then the environment).
    fn choice_probability(&self, index: usize) -> f64 {
        self.choice
            .as_ref()
            .map_or(0.0, |c| c.probability(index) as f64)
    }

    /// A direction from `point` drawn by light sampling: a light chosen in proportion to its
    /// power, then a direction toward it. Its density is [`Lights::pdf`] (all lights that
    /// could have produced it), which callers evaluate once.
    pub fn sample_direction(&self, point: Vec3, u: [f32; 2]) -> Option<Vec3> {
        Some(self.sample_toward(&Receiver::new(point), u)?.direction)
    }

    /// [`Lights::sample_direction`] for `receiver`, located on the environment map when drawn
    /// from it, with the environment map sampled by the receiver's guide (its product with an
    /// affinity map) when it has one; the density is then [`Lights::pdf_toward`].
    #[inline]
    pub fn sample_toward(&self, receiver: &Receiver, u: [f32; 2]) -> Option<Toward> {
        let choice = self.choice.as_ref()?;
        let (index, u0) = choice.sample(u[0]);
        if index < self.area.len() {
            let sample = self.area[index].sample_for(receiver, [u0, u[1]])?;
            return Some(Toward::new(sample.direction));
        }
        if index < self.environment_index() {
            let delta = index - self.area.len();
            let arrival = self.delta[delta].arrival(receiver.point)?;
            return Some(Toward::delta(delta, arrival));
        }
        match (self.environment.as_ref()?, receiver.environment_guide) {
            (Environment::Map(map), Some(guide)) => Some(guide.sample(map, [u0, u[1]])),
            (environment, _) => Some(environment.sample_toward([u0, u[1]])),
        }
    }

    /// [`Lights::sample_direction`] with its density.
    pub fn sample(&self, point: Vec3, u: [f32; 2]) -> Option<(Vec3, f64)> {
        let direction = self.sample_direction(point, u)?;
        let pdf = self.pdf(point, direction);
        (pdf > 0.0).then_some((direction, pdf))
    }

    /// Density of light sampling at `direction` from `point`, in solid angle.
    pub fn pdf(&self, point: Vec3, direction: Vec3) -> f64 {
        self.pdf_toward(&Receiver::new(point), &mut Toward::new(direction))
    }

    /// Density of [`Lights::sample_toward`] for the same receiver.
    #[inline]
    pub fn pdf_toward(&self, receiver: &Receiver, toward: &mut Toward) -> f64 {
        // A delta light is a point mass: only its choice counts, and no density adds to it.
        if let Some((delta, _)) = toward.delta_light() {
            return self.choice_probability(self.area.len() + delta);
        }
        let mut pdf = 0.0;
        for (index, light) in self.area.iter().enumerate() {
            let p = self.choice_probability(index);
            if p > 0.0 {
                pdf += p * light.pdf_for(receiver, toward.direction);
            }
        }
        if let Some(environment) = &self.environment {
            let density = match (environment, receiver.environment_guide) {
                (Environment::Map(map), Some(guide)) => guide.pdf(map, toward),
                (environment, _) => environment.pdf_toward(toward),
            };
            pdf += self.choice_probability(self.environment_index()) * density;
        }
        pdf
    }

    /// Radiance arriving along the ray from the first emitter, ignoring every occluder that
    /// is not an emitter, and the distance to that emitter (infinite for the environment):
    /// what the ray would bring if nothing blocked it, and how far it must be free. `toward`
    /// is the ray's direction, perhaps already located on the environment map.
    #[inline]
    pub fn unoccluded(&self, ray: &Ray, toward: &mut Toward) -> (Vec3, f32) {
        if let Some((_, arrival)) = toward.delta_light() {
            return (arrival.light, arrival.distance);
        }
        let nearest = self
            .area
            .iter()
            .filter_map(|light| light.intersect(ray).map(|(t, n)| (t, n, light)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        match nearest {
            Some((t, normal, light)) => (light.emitted(normal, ray.direction), t),
            None => {
                let background = self
                    .environment
                    .as_ref()
                    .map_or(Vec3::ZERO, |e| e.radiance_toward(toward));
                (background, f32::INFINITY)
            }
        }
    }

    /// Radiance of the environment in `direction` (black without one).
    pub fn background(&self, direction: Vec3) -> Vec3 {
        self.environment
            .as_ref()
            .map_or(Vec3::ZERO, |e| e.radiance(direction))
    }

    /// Radiance emitted toward `-direction` by shape `shape` at a point with geometric
    /// normal `normal` (zero if the shape is not an emitter).
    pub fn emitted(&self, shape: u32, normal: Vec3, direction: Vec3) -> Vec3 {
        match self.shape_lights.get(shape as usize).copied().flatten() {
            Some(index) => self.area[index].emitted(normal, direction),
            None => Vec3::ZERO,
        }
    }
}
