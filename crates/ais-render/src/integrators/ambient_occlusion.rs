//! Ambient occlusion: the share of cosine-weighted hemisphere rays that nothing blocks within
//! a distance.

use crate::geometry::{basis, spawn_ray, Ray};
use crate::render::RayCounts;
use crate::world::World;
use ais::rng::Pcg32;
use ais::sampling::cosine_hemisphere;

/// Ambient-occlusion settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusion {
    /// Rays per camera sample.
    pub rays: u32,
    /// Occlusion distance (world units).
    pub distance: f32,
}

impl AmbientOcclusion {
    /// The unoccluded share of `rays` cosine-weighted rays around the shading normal at the
    /// first hit of `ray`: 1 where nothing is within `distance`, white on a miss.
    pub fn value(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        counts: &mut RayCounts,
    ) -> [f32; 3] {
        counts.closest_hit += 1;
        let Some(hit) = world.geometry.intersect(ray) else {
            return [1.0; 3];
        };
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
        for _ in 0..self.rays {
            let local = cosine_hemisphere([rng.next_f32(), rng.next_f32()]);
            let direction = (t * local.x + b * local.y + n * local.z).normalize();
            if direction.dot(ng) <= 0.0 {
                continue; // below the geometric surface: blocked by it
            }
            let mut shadow = spawn_ray(hit.point, ng, direction);
            shadow.t_max = self.distance;
            counts.occlusion += 1;
            if !world.geometry.occluded(&shadow) {
                visible += 1;
            }
        }
        [visible as f32 / self.rays as f32; 3]
    }
}
