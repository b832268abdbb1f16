//! Integrators available before lighting lands: shading normals and ambient occlusion.
//! They exist to verify geometry; the AIS gather integrator comes with the lighting issue.

use crate::geometry::{spawn_ray, Ray};
use crate::world::World;
use ais::rng::Pcg32;
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

/// What to compute at each camera sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
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
        counts: &mut RayCounts,
    ) -> [f32; 3] {
        counts.closest_hit += 1;
        let hit = world.geometry.intersect(ray);
        match (self, hit) {
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
