//! Integrators available before lighting lands: shading normals and ambient occlusion.
//! They exist to verify geometry; the AIS gather integrator comes with the lighting issue.

use crate::bsdf::ShadingFrame;
use crate::geometry::{spawn_ray, Ray};
use crate::lights::luminance;
use crate::proposal::{GatherPoint, Strategy};
use crate::world::World;
use ais::rng::Pcg32;
use ais::{rating, Batch, BatchConfig, Decision, MapConfig, MapStart, Mode, Stopping};
use glam::Vec3;

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Closest-hit queries (camera rays).
    pub closest_hit: u64,
    /// Occlusion (any-hit) queries.
    pub occlusion: u64,
}

impl RayCounts {
    /// Adds another count.
    pub fn merge(&mut self, other: RayCounts) {
        self.closest_hit += other.closest_hit;
        self.occlusion += other.occlusion;
    }

    /// All rays.
    pub fn total(&self) -> u64 {
        self.closest_hit + self.occlusion
    }
}

/// AIS setting of the gather.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AisMode {
    /// No affinity map: every in-support candidate is traced.
    Off,
    /// The talk's aggressive map.
    Aggressive,
    /// The talk's conservative map (shadow-edge resets).
    Conservative,
}

impl AisMode {
    /// Parses a command-line or XML name.
    pub fn parse(name: &str) -> Option<AisMode> {
        match name {
            "off" => Some(AisMode::Off),
            "aggressive" => Some(AisMode::Aggressive),
            "conservative" => Some(AisMode::Conservative),
            _ => None,
        }
    }
}

/// Settings of the multi-ray gather integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherSettings {
    /// The proposal sampler.
    pub strategy: Strategy,
    /// AIS off, aggressive or conservative.
    pub ais: AisMode,
    /// Rays per gather (n).
    pub rays: u32,
    /// The map's tol (a_min = 1 / (tol h²)).
    pub tol: f32,
    /// The map's height in texels.
    pub map_height: u32,
    /// Halton (the talk's) or independent random candidates.
    pub placement: ais::Placement,
}

impl Default for GatherSettings {
    fn default() -> Self {
        let map = MapConfig::default();
        GatherSettings {
            strategy: Strategy::Mis,
            // Measured: per-batch AIS with Halton placement loses to AIS off in every room
            // and scene tried so far (BENCHMARKS.md), so the renderer starts with it off.
            ais: AisMode::Off,
            rays: 16,
            tol: map.tol,
            map_height: map.height,
            placement: ais::Placement::Halton,
        }
    }
}

impl GatherSettings {
    /// The batch configuration. Every mode uses the candidate-budget stopping rule, which is
    /// exactly unbiased with Halton placement even when candidates fall outside the support.
    pub fn batch_config(&self) -> BatchConfig {
        let base = BatchConfig {
            stopping: Stopping::CandidateBudget,
            placement: self.placement,
            ..BatchConfig::default()
        };
        match self.ais {
            AisMode::Off => BatchConfig {
                affinity: None,
                learning: ais::Learning::Off,
                ..base
            },
            AisMode::Aggressive | AisMode::Conservative => BatchConfig {
                affinity: Some(MapConfig {
                    height: self.map_height,
                    tol: self.tol,
                    mode: if self.ais == AisMode::Aggressive {
                        Mode::Aggressive
                    } else {
                        Mode::Conservative
                    },
                    ..MapConfig::default()
                }),
                ..base
            },
        }
    }
}

/// Per-thread state of a render: counters and the reusable AIS batch.
#[derive(Default)]
pub struct SampleContext {
    /// Rays traced.
    pub counts: RayCounts,
    /// The gather's batch driver (allocated on first use).
    pub batch: Option<Batch<[f32; 3]>>,
    /// Time spent in AIS calls (sampled).
    pub ais_timer: crate::ais_timer::AisTimer,
}

/// What to compute at each camera sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Direct light gathered at the first hit with `rays` rays through the AIS batch
    /// driver, plus emitters seen directly.
    Gather(GatherSettings),
    /// Shading normal mapped to colour, (n + 1) / 2; black on a miss.
    Normals,
    /// Ambient occlusion by `rays` cosine-weighted hemisphere rays of length `distance`
    /// around the shading normal: 1 where nothing is within `distance`. White on a miss.
    AmbientOcclusion {
        /// Rays per camera sample.
        rays: u32,
        /// Occlusion distance (world units).
        distance: f32,
    },
}

/// An orthonormal basis around `n` (Duff et al.'s branchless construction).
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

impl Integrator {
    /// The value of one camera ray.
    pub fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        context: &mut SampleContext,
    ) -> [f32; 3] {
        if let Integrator::Gather(settings) = self {
            return gather(world, settings, ray, rng, context).to_array();
        }
        let counts = &mut context.counts;
        counts.closest_hit += 1;
        let hit = world.geometry.intersect(ray);
        match (self, hit) {
            (Integrator::Gather(_), _) => unreachable!("handled above"),
            (Integrator::Normals, None) => [0.0; 3],
            (Integrator::Normals, Some(hit)) => (hit.shading_normal * 0.5 + 0.5).to_array(),
            (Integrator::AmbientOcclusion { .. }, None) => [1.0; 3],
            (Integrator::AmbientOcclusion { rays, distance }, Some(hit)) => {
                // Face the normals toward the viewer so both sides of thin surfaces get AO.
                let facing = if hit.geometric_normal.dot(ray.direction) > 0.0 {
                    -1.0
                } else {
                    1.0
                };
                let n = hit.shading_normal * facing;
                let ng = hit.geometric_normal * facing;
                let (t, b) = basis(n);
                let mut visible = 0u32;
                for _ in 0..*rays {
                    let (u1, u2) = (rng.next_f32(), rng.next_f32());
                    let r = u1.sqrt();
                    let phi = std::f32::consts::TAU * u2;
                    let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
                    let direction = (t * local.x + b * local.y + n * local.z).normalize();
                    if direction.dot(ng) <= 0.0 {
                        continue; // below the geometric surface: blocked by it
                    }
                    let mut shadow = spawn_ray(hit.point, ng, direction);
                    shadow.t_max = *distance;
                    counts.occlusion += 1;
                    if !world.geometry.occluded(&shadow) {
                        visible += 1;
                    }
                }
                [visible as f32 / *rays as f32; 3]
            }
        }
    }
}

/// The gather: emitted radiance at the first hit plus `n` rays of direct light through the
/// AIS batch driver.
fn gather(
    world: &World,
    settings: &GatherSettings,
    ray: &Ray,
    rng: &mut Pcg32,
    context: &mut SampleContext,
) -> Vec3 {
    context.counts.closest_hit += 1;
    let Some(hit) = world.geometry.intersect(ray) else {
        return world.lights.background(ray.direction);
    };
    let emitted = world
        .lights
        .emitted(hit.shape, hit.geometric_normal, ray.direction);
    if world.lights.is_empty() {
        return emitted;
    }
    let wo = -ray.direction;
    let material = &world.materials[hit.shape as usize];
    let frame = ShadingFrame::new(material, hit.shading_normal, hit.geometric_normal, wo);
    let at = GatherPoint {
        point: hit.point,
        frame,
        wo,
        material,
        lights: &world.lights,
    };
    let SampleContext {
        counts,
        batch,
        ais_timer: timer,
    } = context;
    let batch = batch.get_or_insert_with(|| {
        Batch::new(settings.batch_config()).expect("valid gather configuration")
    });
    let seed = ((rng.next_u32() as u64) << 32) | rng.next_u32() as u64;
    timer.start_gather();
    batch.begin(settings.rays, seed, MapStart::Empty);
    while let Some(candidate) = batch.next_candidate() {
        let Some((direction, pdf)) = settings
            .strategy
            .sample(&at, candidate.u)
            .filter(|s| s.1 > 0.0)
        else {
            timer.decided(frame.normal, false);
            batch.decide(frame.normal, false);
            continue;
        };
        let in_support = material.in_support(&frame, wo, direction);
        timer.decided(direction, in_support);
        if let Decision::Trace { .. } = batch.decide(direction, in_support) {
            let mut leaving = spawn_ray(hit.point, frame.geometric, direction);
            let (unoccluded, distance) = world.lights.unoccluded(&leaving);
            // The emitter's own surface is in the BVH: stop just short of it. A ray whose
            // unoccluded radiance is zero brings zero whatever blocks it: no need to trace.
            let actual = if unoccluded == Vec3::ZERO {
                Vec3::ZERO
            } else {
                leaving.t_max = distance * (1.0 - 1e-4);
                counts.occlusion += 1;
                if world.geometry.occluded(&leaving) {
                    Vec3::ZERO
                } else {
                    unoccluded
                }
            };
            let value = material.eval(&frame, wo, direction) * actual / pdf as f32;
            let rating = rating(luminance(actual), luminance(unoccluded));
            timer.recorded(value.to_array(), rating);
            batch.record(value.to_array(), rating);
        }
    }
    let estimate = batch.finish();
    timer.end_gather(batch.config(), settings.rays, seed);
    emitted + Vec3::from(estimate.value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal() {
        let mut rng = Pcg32::new(4, 4);
        for _ in 0..1000 {
            let n = Vec3::new(
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
            )
            .normalize();
            let (t, b) = basis(n);
            assert!(t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5 && t.dot(b).abs() < 1e-5);
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
        }
    }
}
