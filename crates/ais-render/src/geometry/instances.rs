//! Instancing: a shape group's geometry is built once, in its own BVH, and every instance
//! of it is one primitive of the scene's BVH, bounded by the group's box under the
//! instance's transform. A ray that reaches an instance is carried into the group's frame,
//! traced there, and what it hits is carried back, as Mitsuba's `instance` does it:
//! points and tangents by the transform, normals by its inverse transpose.

use super::{Geometry, Hit, Ray};
use glam::{Affine3A, Mat3, Vec3, Vec3A};
use obvhs::aabb::Aabb;

/// A shape group's shapes, in its own frame, for [`Geometry::build_instanced`].
#[derive(Clone, Debug, Default)]
pub struct ShapeGroupInput {
    /// Its shapes (numbered after the scene's own shapes, group after group).
    pub shapes: Vec<super::ShapeInput>,
}

/// One instance of a shape group.
#[derive(Clone, Copy, Debug)]
pub struct InstanceInput {
    /// The group (its index among the groups given).
    pub group: u32,
    /// Group frame → world.
    pub to_world: Affine3A,
}

/// The scene's shapes, groups and instances, for [`Geometry::build_instanced`].
#[derive(Clone, Debug, Default)]
pub struct SceneShapes {
    /// The shapes placed in the scene itself (numbered first).
    pub shapes: Vec<super::ShapeInput>,
    /// The shape groups.
    pub groups: Vec<ShapeGroupInput>,
    /// The instances of the groups.
    pub instances: Vec<InstanceInput>,
}

/// A group's geometry and the box around it, in the group's frame.
pub(super) struct GroupGeometry {
    pub(super) geometry: Geometry,
    pub(super) bounds: Aabb,
}

/// An instance, with the transforms a ray and a hit need.
#[derive(Clone, Copy, Debug)]
pub(super) struct Instance {
    pub(super) group: u32,
    to_world: Affine3A,
    to_group: Affine3A,
    /// The inverse transpose of the linear part: normals to world.
    normals_to_world: Mat3,
}

impl Instance {
    /// The instance of `input`, or `None` if its transform cannot be inverted.
    pub(super) fn new(input: &InstanceInput) -> Option<Self> {
        let determinant = input.to_world.matrix3.determinant();
        if determinant == 0.0 || !determinant.is_finite() {
            return None;
        }
        let to_group = input.to_world.inverse();
        Some(Instance {
            group: input.group,
            to_world: input.to_world,
            to_group,
            normals_to_world: Mat3::from(to_group.matrix3).transpose(),
        })
    }

    /// The box around the group's `bounds` under the instance's transform.
    pub(super) fn world_bounds(&self, bounds: &Aabb) -> Aabb {
        let mut world = Aabb::empty();
        for corner in 0..8 {
            let pick = |bit: usize, axis: usize| {
                if corner & bit == 0 {
                    bounds.min[axis]
                } else {
                    bounds.max[axis]
                }
            };
            let point = Vec3A::new(pick(1, 0), pick(2, 1), pick(4, 2));
            world.extend(self.to_world.transform_point3a(point));
        }
        world
    }

    /// `ray` (ending at `t_max`) in the group's frame, with a unit direction, and how much
    /// longer a distance is there than in the world.
    fn ray_in_group(&self, ray: &Ray, t_max: f32) -> Option<(Ray, f32)> {
        let direction = self.to_group.transform_vector3(ray.direction);
        let stretch = direction.length();
        (stretch > 0.0 && stretch.is_finite()).then(|| {
            let local = Ray {
                origin: self.to_group.transform_point3(ray.origin),
                direction: direction / stretch,
                t_max: t_max * stretch,
            };
            (local, stretch)
        })
    }

    /// The closest hit of `ray` (ending at `t_max`) on the instance, in world space.
    pub(super) fn intersect(&self, group: &Geometry, ray: &Ray, t_max: f32) -> Option<Hit> {
        let (local, stretch) = self.ray_in_group(ray, t_max)?;
        let hit = group.intersect(&local)?;
        let to_normal = |n: Vec3| (self.normals_to_world * n).normalize_or_zero();
        let t = hit.t / stretch;
        Some(Hit {
            t,
            point: ray.at(t),
            geometric_normal: to_normal(hit.geometric_normal),
            shading_normal: to_normal(hit.shading_normal),
            dp_du: self.to_world.transform_vector3(hit.dp_du),
            dp_dv: self.to_world.transform_vector3(hit.dp_dv),
            ..hit
        })
    }

    /// Whether anything of the instance blocks `ray` before `t_max`.
    pub(super) fn occludes(&self, group: &Geometry, ray: &Ray, t_max: f32) -> bool {
        self.ray_in_group(ray, t_max)
            .is_some_and(|(local, _)| group.occluded(&local))
    }
}
