//! All emitters of a scene: an optional environment, area lights and delta lights (point,
//! spot, directional), chosen in proportion to their estimated power for light sampling (an
//! alias table: O(1) per choice).

mod area;
mod area_draws;
mod delta;
mod draw;
mod environment;
mod environment_draws;
mod environment_guide;
mod mesh_emitter;
pub(crate) mod reader;
mod receiver;
mod regions;
mod resolve;
mod spherical_rectangle;
mod toward;

pub use area::{AreaHit, AreaLight, AreaSample, AreaShape, LightSpot};
pub use area_draws::{AreaChoice, AreaDraw, AreaDraws};
pub use delta::{DeltaArrival, DeltaLight, Spot};
pub use draw::Draw;
pub(crate) use environment::LANES as MAP_LANES;
pub use environment::{luminance, Environment, EnvironmentMap, MapLocation};
pub use environment_draws::EnvironmentDraws;
pub use environment_guide::{EnvironmentGuide, EnvironmentPartition, GuideLayout, MapWeights};
pub use mesh_emitter::MeshEmitter;
pub use receiver::Receiver;
pub use regions::{region_of, RegionChoice, REGIONS, REGION_SIDE};
pub(crate) use spherical_rectangle::LANES;
pub use spherical_rectangle::{Rectangle, LEAST_F32_SOLID_ANGLE};
pub use toward::Toward;
pub(crate) use toward::{AreaPoint, Source};

use crate::geometry::{LeavingSurface, Ray, Shaft, Sphere};
use ais::sampling::AliasTable;
use glam::Vec3;
use std::f64::consts::PI;

/// The largest f32 below 1: a point of the unit interval clamped there stays inside it.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

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
    /// Where a field cell counts each light's rays ([`Lights::source_of`]).
    sources: SourceLayout,
    /// Whether there are area lights and all are rectangles: a run's directions are then
    /// resolved together ([`Lights::resolve_run`]).
    only_rectangles: bool,
    /// Whether there are area lights and all are spheres or meshes: a run's directions
    /// that miss them all are then found over lanes ([`Lights::sources_along`]).
    misses_in_lanes: bool,
    /// Per area light, whether a shaft can bound its rays ([`Lights::shaft_toward`]).
    bounded_by_shafts: Vec<bool>,
    /// Whether some shadow rays are bounded by no shaft ([`Lights::some_rays_unbounded`]).
    some_unbounded: bool,
}

/// Where a field cell counts each light's rays: one source per light, or, for the lights
/// with regions ([`AreaLight::has_regions`]), one per region of the light's sample square,
/// as long as the scene's sources stay within what a cell counts
/// ([`ais::field::MOST_SOURCES`]).
#[derive(Clone, Debug, Default)]
struct SourceLayout {
    /// Each light's first source (in the order light sampling chooses them), then the
    /// number of sources.
    first: Vec<usize>,
}

impl SourceLayout {
    /// The layout for lights of which those flagged in `regions` have regions.
    fn new(regions: &[bool]) -> Self {
        let with_regions: usize = regions.iter().map(|&r| if r { REGIONS } else { 1 }).sum();
        let split = with_regions <= ais::field::MOST_SOURCES as usize;
        let mut first = vec![0];
        for &r in regions {
            let count = if r && split { REGIONS } else { 1 };
            first.push(first.last().copied().unwrap_or(0) + count);
        }
        SourceLayout { first }
    }
}

/// Where a candidate's shadow ray goes ([`Lights::aim`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Aim {
    /// It surely brings nothing: no ray is needed.
    Nothing,
    /// It must be free up to this point (of an area light, or a point or spot light).
    Point(Vec3),
    /// It must be free all the way (the environment, a directional light).
    Unbounded,
}

/// The shaft toward an area light ([`Lights::shaft_toward`]) and the light's own shape,
/// which the shaft's rays end before.
#[derive(Clone, Copy, Debug)]
pub struct LightShaft {
    /// The planes around the rays.
    pub shaft: Shaft,
    /// The scene's index of the light's shape.
    pub own_shape: u32,
}

/// What a shaft toward an area light is built around ([`Lights::shaft_toward`]).
enum ShaftOutline {
    /// A rectangle's corners, in order around it (a flat mesh's: a rectangle around it).
    Rectangle([Vec3; 4]),
    /// A sphere emitting outward.
    Sphere(Sphere),
}

/// What a shaft toward `light` is built around: a rectangle, a sphere emitting outward, or
/// a flat mesh; `None` for other lights.
fn shaft_outline(light: &AreaLight) -> Option<ShaftOutline> {
    match &light.shape {
        AreaShape::Rectangle(rectangle) => Some(ShaftOutline::Rectangle(rectangle.corners())),
        AreaShape::Sphere {
            sphere,
            flipped: false,
        } => Some(ShaftOutline::Sphere(*sphere)),
        AreaShape::Triangles(mesh) => mesh.outline().map(ShaftOutline::Rectangle),
        _ => None,
    }
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
        let mut regions: Vec<bool> = area.iter().map(AreaLight::has_regions).collect();
        regions.resize(weights.len(), false);
        let bounded_by_shafts: Vec<bool> =
            area.iter().map(|l| shaft_outline(l).is_some()).collect();
        Lights {
            only_rectangles: !area.is_empty() && area.iter().all(|l| l.rectangle().is_some()),
            misses_in_lanes: !area.is_empty() && area.iter().all(AreaLight::has_misses_in_lanes),
            some_unbounded: environment.is_some()
                || !delta.is_empty()
                || bounded_by_shafts.iter().any(|&bounded| !bounded),
            bounded_by_shafts,
            environment,
            area,
            delta,
            shape_lights,
            choice,
            sources: SourceLayout::new(&regions),
        }
    }

    /// The environment's index in the choice of a light.
    fn environment_index(&self) -> usize {
        self.area.len() + self.delta.len()
    }

    /// Probability of choosing the environment for `receiver`.
    #[inline]
    pub(crate) fn environment_choice(&self, receiver: &Receiver) -> f64 {
        self.choice_probability(receiver, self.environment_index())
    }

    /// Probability of choosing delta light `delta` for `receiver`: a point mass of light
    /// sampling.
    #[inline]
    pub(crate) fn delta_choice(&self, receiver: &Receiver, delta: usize) -> f64 {
        self.choice_probability(receiver, self.area.len() + delta)
    }

    /// Whether the scene has no emitter at all.
    pub fn is_empty(&self) -> bool {
        self.choice.is_none()
    }

    /// How many lights light sampling chooses among (area, delta, the environment): the
    /// sources of [`Lights::source_of`].
    pub fn source_count(&self) -> usize {
        self.environment_index() + usize::from(self.environment.is_some())
    }

    /// How many sources a field cell counts the lights' rays by ([`Lights::source_of`]):
    /// one per light, or one per region of a light's sample square.
    pub fn field_sources(&self) -> usize {
        self.sources.first.last().copied().unwrap_or(0)
    }

    /// The sources of light `index` (in the order light sampling chooses them): one, or
    /// one per region of its sample square ([`REGIONS`], indexed as [`region_of`]).
    pub fn sources_of_light(&self, index: usize) -> std::ops::Range<usize> {
        self.sources.first[index]..self.sources.first[index + 1]
    }

    /// The probabilities of choosing each light by its power (indexed as light sampling
    /// chooses them: area lights, delta lights, the environment).
    pub fn power_choice(&self) -> Vec<f64> {
        (0..self.source_count())
            .map(|index| self.power_probability(index))
            .collect()
    }

    /// The field's source (see [`Lights::field_sources`]) that `toward` (resolved) meets
    /// first: the light, and for a light counted by regions, the region of its sample
    /// square that the point met lies in (`None`: nothing emits along it, or it was not
    /// resolved).
    pub fn source_of(&self, receiver: &Receiver, toward: &Toward) -> Option<usize> {
        let light = match toward.source {
            Source::Area(point) => point.light,
            Source::Delta(delta, _) => self.area.len() + delta,
            Source::Environment => self.environment_index(),
            Source::Dark | Source::Unknown => return None,
        };
        let sources = self.sources_of_light(light);
        if sources.len() == 1 {
            return Some(sources.start);
        }
        let Source::Area(point) = toward.source else {
            return Some(sources.start);
        };
        let region = point.region.map(usize::from).or_else(|| {
            let square =
                self.area[light].sample_square_of(receiver, toward.direction, point.target);
            square.map(region_of)
        })?;
        Some(sources.start + region)
    }

    /// The choice of a light for `receiver`: its own (a field cell's), else by power.
    #[inline]
    fn choice_for<'r>(&'r self, receiver: &Receiver<'r>) -> Option<&'r AliasTable> {
        receiver.light_choice.or(self.choice.as_ref())
    }

    /// Probability of choosing light `index` by its power.
    fn power_probability(&self, index: usize) -> f64 {
        self.choice
            .as_ref()
            .map_or(0.0, |c| c.probability(index) as f64)
    }

    /// Probability of choosing light `index` (area lights first, then delta lights, then
    /// the environment) for `receiver`.
    #[inline]
    fn choice_probability(&self, receiver: &Receiver, index: usize) -> f64 {
        self.choice_for(receiver)
            .map_or(0.0, |c| c.probability(index) as f64)
    }

    /// A direction from `point` drawn by light sampling: a light chosen in proportion to its
    /// power, then a direction toward it. Its density over directions is [`Lights::pdf`].
    pub fn sample_direction(&self, point: Vec3, u: [f32; 2]) -> Option<Vec3> {
        Some(self.sample_toward(&Receiver::new(point), u)?.direction)
    }

    /// [`Lights::sample_direction`] for `receiver`, knowing what it was drawn toward (a point
    /// of an area light, the environment with its place on the map, a delta light), with the
    /// environment map sampled by the receiver's guide (its product with an affinity map)
    /// when it has one.
    #[inline]
    pub fn sample_toward(&self, receiver: &Receiver, u: [f32; 2]) -> Option<Toward> {
        self.finish(receiver, self.begin_sample(receiver, u))
    }

    /// The direction of `draw` for `receiver`, made now if it was left for later.
    #[inline]
    pub fn finish(&self, receiver: &Receiver, draw: Draw) -> Option<Toward> {
        match draw {
            Draw::Made(toward) => toward,
            Draw::Environment(u) => self.environment_toward(receiver, u),
            Draw::Area(draw) => {
                let light = &self.area[draw.choice.light];
                let sample = light.sample_for(receiver, draw.square)?;
                Some(self.area_toward(receiver, draw.choice, &sample))
            }
        }
    }

    /// [`Lights::sample_toward`], except that a draw from the environment or an area light is
    /// left to be made together with other candidates' ([`EnvironmentDraws`], [`AreaDraws`]).
    /// (Inlined into every caller: a call returned the draw through memory, written a field
    /// at a time and read back whole, and the reads waited for the writes.)
    #[inline(always)]
    pub fn begin_sample(&self, receiver: &Receiver, u: [f32; 2]) -> Draw {
        let Some(choice) = self.choice_for(receiver) else {
            return Draw::Made(None);
        };
        let (index, u0) = choice.sample(u[0]);
        if index < self.area.len() {
            let probability = choice.probability(index) as f64;
            return self.begin_area(receiver, index, probability, [u0, u[1]]);
        }
        if index < self.environment_index() {
            let delta = index - self.area.len();
            let arrival = self.delta[delta].arrival(receiver.point);
            return Draw::Made(arrival.map(|arrival| Toward::delta(delta, arrival)));
        }
        Draw::Environment([u0, u[1]])
    }

    /// A point of area light `index` (chosen with `probability`) drawn from `square` for
    /// `receiver`, left to be made with the run's others (which draw nothing where the light
    /// lies wholly behind the receiver's support: [`AreaLight::sample_run`] asks that once
    /// for the run).
    #[inline]
    fn begin_area(
        &self,
        receiver: &Receiver,
        index: usize,
        probability: f64,
        square: [f32; 2],
    ) -> Draw {
        // A receiver that weighs the light's regions draws the square's point from them.
        let (square, region, factor) = match receiver.region_choice(index) {
            Some(regions) => {
                let (square, region) = regions.sample(square);
                (square, region, regions.factor(region))
            }
            None => (square, region_of(square), 1.0),
        };
        let choice = AreaChoice {
            light: index,
            probability,
            factor,
            region: region as u8,
        };
        Draw::Area(AreaDraw { choice, square })
    }

    /// The candidate toward the point `sample` drew on the light of `choice`.
    #[inline]
    fn area_toward(&self, receiver: &Receiver, choice: AreaChoice, sample: &AreaSample) -> Toward {
        let light = &self.area[choice.light];
        let target = receiver.point + sample.direction * sample.distance;
        let point = AreaPoint {
            light: choice.light,
            target,
            radiance: light.emitted(sample.normal, sample.direction, target, sample.spot),
            density: choice.probability * sample.pdf * choice.factor,
            region: Some(choice.region),
        };
        Toward::area(sample.direction, point)
    }

    /// The environment's direction from `u` (drawn by the receiver's guide when it has one).
    #[inline]
    fn environment_toward(&self, receiver: &Receiver, u: [f32; 2]) -> Option<Toward> {
        Some(receiver.sample_environment(self.environment.as_ref()?, u))
    }

    /// [`Lights::sample_direction`] with its density over directions.
    pub fn sample(&self, point: Vec3, u: [f32; 2]) -> Option<(Vec3, f64)> {
        let direction = self.sample_direction(point, u)?;
        let pdf = self.pdf(point, direction);
        (pdf > 0.0).then_some((direction, pdf))
    }

    /// Density of light sampling over directions at `direction` from `point`, in solid
    /// angle: every light that could have drawn it, and every crossing of an emitting mesh.
    /// This is what [`Lights::sample_direction`] draws from; the gather weighs a candidate by
    /// [`Lights::pdf_toward`] instead.
    pub fn pdf(&self, point: Vec3, direction: Vec3) -> f64 {
        self.pdf_over_directions(&Receiver::new(point), direction)
    }

    /// [`Lights::pdf`] for `receiver` (with its environment guide, if any).
    pub fn pdf_over_directions(&self, receiver: &Receiver, direction: Vec3) -> f64 {
        let mut pdf = 0.0;
        for (index, light) in self.area.iter().enumerate() {
            let p = self.choice_probability(receiver, index);
            if p > 0.0 {
                let (factor, _) = self.region_factor(receiver, index, direction, None);
                pdf += p * light.pdf_for(receiver, direction) * factor;
            }
        }
        pdf + self.environment_density(receiver, &mut Toward::new(direction))
    }

    /// The density with which light sampling draws what `toward` meets first: the point of
    /// an area light, the environment in that direction, or (a point mass) a delta light.
    /// Light sampling draws other points along the direction too, behind the first; they
    /// bring nothing, as what lies in front occludes them, so this density, not the sum
    /// over every way of drawing the direction, gives each candidate its unbiased weight
    /// (as Mitsuba's direct integrator weighs its emitter samples). It needs no loop over
    /// the lights for a direction drawn by light sampling.
    #[inline]
    pub fn pdf_toward(&self, receiver: &Receiver, toward: &mut Toward) -> f64 {
        self.resolve(receiver, toward);
        match toward.source {
            Source::Delta(delta, _) => self.delta_choice(receiver, delta),
            Source::Area(point) => point.density,
            Source::Environment => self.environment_density(receiver, toward),
            Source::Dark | Source::Unknown => 0.0,
        }
    }

    /// Light sampling's density of the environment at `toward` (choice included).
    fn environment_density(&self, receiver: &Receiver, toward: &mut Toward) -> f64 {
        let Some(environment) = &self.environment else {
            return 0.0;
        };
        let density = match receiver.environment_guide {
            Some(guide) => guide.pdf(environment, toward),
            None => environment.pdf_toward(toward),
        };
        self.environment_choice(receiver) * density
    }

    /// What `toward` brings to `receiver` if nothing that does not emit is in the way, and
    /// the point the ray must be free to: the radiance of the first emitter along it and
    /// its point (`None`, unbounded, for the environment and a directional light), or a
    /// delta light's light and position.
    #[inline]
    pub fn unoccluded(&self, receiver: &Receiver, toward: &mut Toward) -> (Vec3, Option<Vec3>) {
        let radiance = self.radiance_toward(receiver, toward);
        (radiance, self.target(receiver, &toward.source))
    }

    /// The radiance of [`Lights::unoccluded`] alone, without the point it comes from.
    #[inline]
    pub fn radiance_toward(&self, receiver: &Receiver, toward: &mut Toward) -> Vec3 {
        self.resolve(receiver, toward);
        match toward.source {
            Source::Delta(_, arrival) => arrival.light,
            Source::Area(point) => point.radiance,
            Source::Environment => {
                let environment = self.environment.as_ref();
                environment.map_or(Vec3::ZERO, |e| e.radiance_toward(toward))
            }
            Source::Dark | Source::Unknown => Vec3::ZERO,
        }
    }

    /// Where the shadow ray of `toward` (resolved) must be free to: a finite point, or
    /// `None` toward the environment and a directional light.
    fn target(&self, receiver: &Receiver, source: &Source) -> Option<Vec3> {
        match *source {
            Source::Delta(_, arrival) => arrival
                .distance
                .is_finite()
                .then(|| receiver.point + arrival.direction * arrival.distance),
            Source::Area(point) => Some(point.target),
            _ => None,
        }
    }

    /// Where the shadow ray of `toward` goes, known before the radiance it would bring is
    /// looked up: [`Aim::Nothing`] when it surely brings nothing (no emitter along it, an
    /// area light's back, a delta light sending nothing). The environment's radiance, a
    /// texture lookup, is left for after the shadow ray, which most often is blocked
    /// where occlusion matters; it may be zero there (a black part of the map).
    #[inline]
    pub fn aim(&self, receiver: &Receiver, toward: &mut Toward) -> Aim {
        self.resolve(receiver, toward);
        self.aim_at(receiver, &toward.source)
    }

    /// [`Lights::aim`] for a direction from `receiver` that meets `source` first.
    #[inline]
    pub(crate) fn aim_at(&self, receiver: &Receiver, source: &Source) -> Aim {
        let brings_nothing = match *source {
            Source::Delta(_, arrival) => arrival.light == Vec3::ZERO,
            Source::Area(point) => point.radiance == Vec3::ZERO,
            Source::Environment => false,
            Source::Dark | Source::Unknown => true,
        };
        if brings_nothing {
            return Aim::Nothing;
        }
        self.target(receiver, source)
            .map_or(Aim::Unbounded, Aim::Point)
    }

    /// The factor that `receiver`'s weighing of area light `index`'s regions puts on the
    /// light's density along `direction` (toward `target` on the light, found if not
    /// given), and the region (`(1, None)` where the receiver does not weigh them).
    fn region_factor(
        &self,
        receiver: &Receiver,
        index: usize,
        direction: Vec3,
        target: Option<Vec3>,
    ) -> (f64, Option<u8>) {
        let Some(regions) = receiver.region_choice(index) else {
            return (1.0, None);
        };
        let light = &self.area[index];
        let target = target.or_else(|| {
            let hit = light.intersect(&Ray::new(receiver.point, direction))?;
            Some(receiver.point + direction * hit.distance)
        });
        let square = target.and_then(|t| light.sample_square_of(receiver, direction, t));
        match square.map(region_of) {
            Some(region) => (regions.factor(region), Some(region as u8)),
            None => (1.0, None),
        }
    }

    /// Radiance of the environment in `direction` (black without one).
    pub fn background(&self, direction: Vec3) -> Vec3 {
        self.environment
            .as_ref()
            .map_or(Vec3::ZERO, |e| e.radiance(direction))
    }

    /// The area light whose point `toward` aims at, where it is a rectangle, a sphere or a
    /// flat mesh (the lights whose shafts [`Lights::shaft_toward`] bounds).
    #[inline]
    pub fn aimed_shaft_light(&self, toward: &Toward) -> Option<usize> {
        self.shaft_light_of(&toward.source)
    }

    /// Whether some shadow rays toward the lights are bounded by no shaft
    /// ([`Lights::shaft_light_of`]): rays toward an environment, a delta light, or an
    /// area light no shaft bounds.
    #[inline]
    pub(crate) fn some_rays_unbounded(&self) -> bool {
        self.some_unbounded
    }

    /// The area light whose point `source` is, where a shaft bounds its rays
    /// ([`Lights::aimed_shaft_light`]).
    #[inline]
    pub(crate) fn shaft_light_of(&self, source: &Source) -> Option<usize> {
        let Source::Area(point) = source else {
            return None;
        };
        self.bounded_by_shafts[point.light].then_some(point.light)
    }

    /// The shaft from `apex`, the offset origin of rays leaving `surface`, toward area light
    /// `light` (a rectangle, a sphere emitting outward, or a flat mesh by a rectangle
    /// around it in its plane), with the light's geometry shape; `None` for other lights,
    /// or where the shaft cannot bound the rays ([`Shaft::to_rectangle`],
    /// [`Shaft::to_sphere`]).
    pub fn shaft_toward(
        &self,
        light: usize,
        apex: Vec3,
        surface: LeavingSurface,
    ) -> Option<LightShaft> {
        let light = &self.area[light];
        let shaft = match shaft_outline(light)? {
            ShaftOutline::Rectangle(corners) => Shaft::to_rectangle(apex, corners, surface),
            ShaftOutline::Sphere(sphere) => Shaft::to_sphere(apex, sphere, surface),
        }?;
        Some(LightShaft {
            shaft,
            own_shape: light.shape_index,
        })
    }

    /// Radiance emitted toward `-direction` by shape `shape` at a point with geometric
    /// normal `normal` and texture coordinates `uv` (zero if the shape is not an emitter).
    pub fn emitted(&self, shape: u32, normal: Vec3, direction: Vec3, uv: glam::Vec2) -> Vec3 {
        match self.shape_lights.get(shape as usize).copied().flatten() {
            Some(index) => self.area[index].emitted_at_uv(normal, direction, uv),
            None => Vec3::ZERO,
        }
    }
}
