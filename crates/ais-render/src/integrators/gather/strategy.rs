//! Proposal samplers for the gather: uniform, BSDF, light, and their MIS mixture. Each gives
//! a direction and the density of the whole strategy at that direction.

use crate::bsdf::{diffuse_direction, HitBsdf, ShadingFrame, SurfacePoint};
use crate::geometry::Hit;
use crate::lights::{AreaDraw, Draw, Lights, Receiver, Toward};
use crate::world::World;
use ais::sampling::uniform_sphere;
use glam::Vec3;
use std::f64::consts::PI;

/// Which distribution proposes the gather's candidate directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// Uniform over the sphere (half the candidates are outside a reflective BSDF's support).
    Uniform,
    /// BSDF sampling (cosine-weighted for diffuse).
    Bsdf,
    /// Light sampling: a light chosen in proportion to its power, then a direction toward it.
    Light,
    /// One-sample MIS with the balance heuristic, i.e. the 50/50 mixture of BSDF and light
    /// sampling, weighted by the mixture density.
    Mis,
}

impl Strategy {
    /// Parses a command-line or XML name.
    pub fn parse(name: &str) -> Option<Strategy> {
        match name {
            "uniform" => Some(Strategy::Uniform),
            "bsdf" => Some(Strategy::Bsdf),
            "light" | "emitter" => Some(Strategy::Light),
            "mis" => Some(Strategy::Mis),
            _ => None,
        }
    }

    /// The name [`Strategy::parse`] accepts.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Uniform => "uniform",
            Strategy::Bsdf => "bsdf",
            Strategy::Light => "light",
            Strategy::Mis => "mis",
        }
    }
}

/// Probability of the BSDF component in the MIS mixture, unless the gather learned another
/// ([`GatherPoint::mis_bsdf_share`]).
pub const MIS_BSDF_WEIGHT: f64 = 0.5;

/// Where a gather happens.
pub struct GatherPoint<'a> {
    /// The shading point, where light is received (with the environment guide of guided
    /// gathers, and what the gather's light queries share).
    pub receiver: Receiver<'a>,
    /// The frame that stands for the surface (for what keys on the normal, and for
    /// offsetting rays); the BSDF holds its materials' own frames.
    pub frame: ShadingFrame,
    /// Direction toward the viewer.
    pub wo: Vec3,
    /// The BSDF at the hit (with its textures' values there).
    pub bsdf: HitBsdf<'a>,
    /// The scene's emitters.
    pub lights: &'a Lights,
    /// The BSDF's share of the MIS mixture here ([`MIS_BSDF_WEIGHT`] unless learned).
    pub mis_bsdf_share: f64,
}

/// The gather point where `hit` is seen from direction `wo` (pointing away from it).
pub fn gather_point<'a>(world: &'a World, hit: &Hit, wo: Vec3) -> GatherPoint<'a> {
    let point = SurfacePoint {
        uv: hit.uv,
        shading_normal: hit.shading_normal,
        geometric_normal: hit.geometric_normal,
        wo,
        dp_du: hit.dp_du,
        dp_dv: hit.dp_dv,
        attributes: world.geometry.attribute_site(hit),
    };
    let (bsdf, frame) = world.surfaces[hit.shape as usize].at(&point);
    let mut receiver = Receiver::new(hit.point);
    receiver.support_side = bsdf.support_side();
    GatherPoint {
        receiver,
        frame,
        wo,
        bsdf,
        lights: &world.lights,
        mis_bsdf_share: MIS_BSDF_WEIGHT,
    }
}

impl GatherPoint<'_> {
    /// Whether light arriving along `toward` can reach the viewer: a specular lobe's
    /// direction always can, any other only inside the BSDF's continuous support.
    #[inline]
    pub fn carries(&self, toward: &Toward) -> bool {
        toward.specular.is_some() || self.bsdf.in_support(self.wo, toward.direction)
    }

    /// What the surface multiplies the radiance arriving along `toward` by: a specular
    /// lobe's mass, or the BSDF times the cosine.
    #[inline]
    pub fn scattering(&self, toward: &Toward) -> Vec3 {
        match toward.specular {
            Some(mass) => mass.weight,
            None => self.bsdf.eval(self.wo, toward.direction),
        }
    }

    /// The direction of a draw, made now if it was left for later.
    #[inline]
    pub fn finish(&self, draw: CandidateDraw) -> Option<Toward> {
        match draw {
            CandidateDraw::Made(toward) => toward,
            CandidateDraw::Environment(u) => {
                self.lights.finish(&self.receiver, Draw::Environment(u))
            }
            CandidateDraw::Area(draw) => self.lights.finish(&self.receiver, Draw::Area(draw)),
            CandidateDraw::Bsdf(u) => self.sample_bsdf(u),
        }
    }

    /// The BSDF's draws for `numbers`, each given to `put` with its index: a diffuse
    /// material's worked out over the run's lanes at once, another's one by one. The same
    /// directions as [`GatherPoint::finish`] gives.
    pub fn draw_bsdf_run(&self, numbers: &[[f32; 2]], mut put: impl FnMut(usize, Option<Toward>)) {
        let Some(frame) = self.bsdf.diffuse_frame() else {
            for (k, &u) in numbers.iter().enumerate() {
                put(k, self.sample_bsdf(u));
            }
            return;
        };
        for (run, numbers) in numbers.chunks(BSDF_LANES).enumerate() {
            // As many lanes as draws: a short run does not pay for sixteen.
            let mut directions = [Vec3::ZERO; BSDF_LANES];
            for (direction, &u) in directions.iter_mut().zip(numbers) {
                *direction = diffuse_direction(frame, u);
            }
            for (k, &direction) in directions[..numbers.len()].iter().enumerate() {
                put(run * BSDF_LANES + k, Some(Toward::new(direction)));
            }
        }
    }

    /// A direction drawn from the BSDF (`None`: nothing scatters toward the viewer).
    #[inline]
    fn sample_bsdf(&self, u: [f32; 2]) -> Option<Toward> {
        let sample = self.bsdf.sample_lobe(self.wo, u)?;
        Some(match sample.specular {
            Some(mass) => Toward::specular(sample.direction, mass),
            None => Toward::new(sample.direction),
        })
    }
}

/// How many BSDF draws [`GatherPoint::draw_bsdf_run`] works out at once.
const BSDF_LANES: usize = 16;

/// A candidate's draw from a proposal: made, or left to be made with the run's other draws
/// of its kind (an environment map's, [`crate::lights::EnvironmentDraws`]; an area
/// light's, [`crate::lights::AreaDraws`]; a BSDF's, [`GatherPoint::draw_bsdf_run`]).
#[derive(Clone, Copy, Debug)]
pub enum CandidateDraw {
    /// The draw is made (`None`: no direction).
    Made(Option<Toward>),
    /// A direction from the environment for these numbers is still to be drawn.
    Environment([f32; 2]),
    /// A point of an area light is still to be drawn.
    Area(AreaDraw),
    /// A direction from the BSDF for these numbers is still to be drawn.
    Bsdf([f32; 2]),
}

impl From<Draw> for CandidateDraw {
    fn from(draw: Draw) -> Self {
        match draw {
            Draw::Made(toward) => CandidateDraw::Made(toward),
            Draw::Environment(u) => CandidateDraw::Environment(u),
            Draw::Area(draw) => CandidateDraw::Area(draw),
        }
    }
}

impl Strategy {
    /// The strategy actually usable at a point: light-based ones fall back to BSDF sampling
    /// in a scene without emitters.
    fn effective(self, at: &GatherPoint) -> Strategy {
        match self {
            Strategy::Light | Strategy::Mis if at.lights.is_empty() => Strategy::Bsdf,
            other => other,
        }
    }

    /// A candidate direction and the strategy's density over directions there (`None`: no
    /// direction, a zero). The gather weighs candidates by [`Strategy::pdf`] instead, which
    /// counts only what a direction meets first; this is the distribution it draws from.
    pub fn sample(self, at: &GatherPoint, u: [f32; 2]) -> Option<(Vec3, f64)> {
        match self.effective(at) {
            Strategy::Uniform => Some((uniform_sphere(u), 1.0 / (4.0 * PI))),
            Strategy::Bsdf => Some(at.bsdf.sample(at.wo, u)),
            Strategy::Light | Strategy::Mis => {
                let direction = self.sample_direction(at, u)?.direction;
                let pdf = self.density(at, direction);
                (pdf > 0.0).then_some((direction, pdf))
            }
        }
    }

    /// The density over directions of [`Strategy::sample`] at `direction`, in solid angle.
    pub fn density(self, at: &GatherPoint, direction: Vec3) -> f64 {
        let light = || at.lights.pdf_over_directions(&at.receiver, direction);
        match self.effective(at) {
            Strategy::Uniform => 1.0 / (4.0 * PI),
            Strategy::Bsdf => at.bsdf.pdf(at.wo, direction),
            Strategy::Light => light(),
            Strategy::Mis => MisParts {
                bsdf: at.bsdf.pdf(at.wo, direction),
                light: light(),
            }
            .mixed(at.mis_bsdf_share),
        }
    }

    /// The direction of [`Strategy::sample`] without its density, which costs more than the
    /// direction for light sampling and MIS: a gather that may skip the candidate asks for
    /// the density only when it traces it. A direction drawn from the environment map
    /// carries its place there, for the density and the radiance.
    #[inline]
    pub fn sample_direction(self, at: &GatherPoint, u: [f32; 2]) -> Option<Toward> {
        at.finish(self.begin_direction(at, u))
    }

    /// [`Strategy::sample_direction`], except that a draw from an environment map, an area
    /// light or the BSDF is left to be made together with other candidates' of its kind
    /// ([`CandidateDraw`]).
    #[inline]
    pub fn begin_direction(self, at: &GatherPoint, u: [f32; 2]) -> CandidateDraw {
        match self.effective(at) {
            Strategy::Uniform => CandidateDraw::Made(Some(Toward::new(uniform_sphere(u)))),
            Strategy::Bsdf => CandidateDraw::Bsdf(u),
            Strategy::Light => at.lights.begin_sample(&at.receiver, u).into(),
            Strategy::Mis => match MisPick::of(at.mis_bsdf_share, u) {
                MisPick::Bsdf(u) => CandidateDraw::Bsdf(u),
                MisPick::Light(u) => at.lights.begin_sample(&at.receiver, u).into(),
            },
        }
    }

    /// The density that weighs a candidate: the strategy's density of drawing what the
    /// direction meets first ([`crate::lights::Lights::pdf_toward`]); toward a delta light,
    /// the probability of drawing that light, and along a specular lobe, the probability of
    /// picking it (point masses, which no density adds to).
    #[inline]
    pub fn pdf(self, at: &GatherPoint, toward: &mut Toward) -> f64 {
        let light = |toward: &mut Toward| at.lights.pdf_toward(&at.receiver, toward);
        if let Some(mass) = toward.specular {
            let share = match self.effective(at) {
                Strategy::Mis => at.mis_bsdf_share,
                _ => 1.0,
            };
            return share * mass.probability as f64;
        }
        match self.effective(at) {
            Strategy::Uniform => 1.0 / (4.0 * PI),
            Strategy::Bsdf => at.bsdf.pdf(at.wo, toward.direction),
            Strategy::Light => light(toward),
            // Toward a point, spot or directional light: a point mass of light sampling,
            // which the BSDF's density does not add to.
            Strategy::Mis if toward.is_delta() => (1.0 - at.mis_bsdf_share) * light(toward),
            Strategy::Mis => MisParts::toward(at, toward).mixed(at.mis_bsdf_share),
        }
    }

    /// The two densities MIS mixes at a candidate drawn from a continuous density (not a
    /// specular lobe or a delta light): BSDF sampling's and light sampling's, the latter of
    /// what the direction meets first. `None` for other strategies and candidates.
    #[inline]
    pub fn mis_parts(self, at: &GatherPoint, toward: &mut Toward) -> Option<MisParts> {
        let continuous = toward.specular.is_none() && !toward.is_delta();
        (self.effective(at) == Strategy::Mis && continuous).then(|| MisParts::toward(at, toward))
    }
}

/// Which of MIS's two samplers a candidate's numbers go to, with the numbers rescaled for
/// it: the BSDF's below its share, light sampling's above.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MisPick {
    /// BSDF sampling, with these numbers.
    Bsdf([f32; 2]),
    /// Light sampling, with these numbers.
    Light([f32; 2]),
}

impl MisPick {
    /// Where numbers `u` ∈ [0, 1)² go when the BSDF's share is `share`.
    #[inline]
    pub fn of(share: f64, u: [f32; 2]) -> Self {
        let w = share as f32;
        if u[0] < w {
            MisPick::Bsdf([u[0] / w, u[1]])
        } else {
            MisPick::Light([((u[0] - w) / (1.0 - w)).min(1.0 - 1e-7), u[1]])
        }
    }
}

/// The densities that MIS mixes at one direction ([`Strategy::mis_parts`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MisParts {
    /// BSDF sampling's density.
    pub bsdf: f64,
    /// Light sampling's density.
    pub light: f64,
}

impl MisParts {
    /// The two densities at `toward`, light sampling's of what it meets first.
    #[inline]
    fn toward(at: &GatherPoint, toward: &mut Toward) -> Self {
        MisParts {
            bsdf: at.bsdf.pdf(at.wo, toward.direction),
            light: at.lights.pdf_toward(&at.receiver, toward),
        }
    }

    /// The mixture's density with the BSDF's share `share`.
    #[inline]
    pub fn mixed(self, share: f64) -> f64 {
        share * self.bsdf + (1.0 - share) * self.light
    }
}
