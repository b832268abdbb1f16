//! Shading normals as colours, for checking geometry.

use crate::geometry::Ray;
use crate::render::RayCounts;
use crate::world::World;

/// The shading normal at the first hit mapped to colour, (n + 1) / 2; black on a miss.
pub fn normal_colour(world: &World, ray: &Ray, counts: &mut RayCounts) -> [f32; 3] {
    counts.closest_hit += 1;
    match world.geometry.intersect(ray) {
        None => [0.0; 3],
        Some(hit) => (hit.shading_normal * 0.5 + 0.5).to_array(),
    }
}
