//! A shaft: the convex region that the shadow rays from one origin toward one light sweep,
//! bounded by planes. When no primitive but the light's own reaches into it, every such
//! ray is free, and a gather's later rays toward the light need no traversal.
//!
//! The planes are conservative: the light's outline is enclosed (a rectangle by its four
//! edges, a sphere by a square pyramid around the cone that it subtends), the far plane
//! lies at or beyond every point a ray aims at, and a near plane halfway between the
//! receiving surface and the rays' offset origin keeps that surface out. A primitive counts
//! as outside only if it lies beyond one plane by a margin of a few units in the last place
//! of the coordinates involved (about the rounding of the tests themselves): a ray inside
//! could meet it only by grazing it within rounding.

use super::Sphere;
use glam::Vec3;
use obvhs::aabb::Aabb;

/// The most planes a shaft has: four sides, the far plane and the near plane.
const MOST_PLANES: usize = 6;

/// The margin, relative to the magnitude of the coordinates involved, by which a primitive
/// must lie outside a plane (2^-22: about four units in the last place).
const RELATIVE_MARGIN: f32 = 1.0 / 4_194_304.0;

/// How far, relative to the coordinates' magnitude, the apex must lie from a flat light's
/// plane. A ray ends short of the light by 1e-4 of its length, so it ends 1e-4 of the
/// apex's height above the plane: from nearer, rays graze the plane, and tracing one can
/// find it blocked by the light itself within rounding. Such rays are left to be traced.
const LEAST_HEIGHT: f32 = 1.0 / 64.0;

/// A plane `normal · x = offset`; the shaft lies where `normal · x ≤ offset`.
#[derive(Clone, Copy, Debug)]
struct Plane {
    normal: Vec3,
    offset: f32,
}

impl Plane {
    /// The plane through `point` with `normal`, the shaft on the side away from `normal`.
    fn through(point: Vec3, normal: Vec3) -> Self {
        Plane {
            normal,
            offset: normal.dot(point),
        }
    }

    /// How far `point` lies outside (negative: inside).
    #[inline]
    fn outside_by(&self, point: Vec3) -> f32 {
        self.normal.dot(point) - self.offset
    }
}

/// The surface a gather's rays leave: its point, its unit geometric normal, and the offset
/// of the rays' origin along that normal ([`super::offset_origin`]).
#[derive(Clone, Copy, Debug)]
pub struct LeavingSurface {
    /// The gather's point on the surface.
    pub point: Vec3,
    /// The surface's unit geometric normal, on the side the rays leave to.
    pub normal: Vec3,
    /// How far above the surface the rays start.
    pub offset: f32,
}

impl LeavingSurface {
    /// How far `point` lies above the surface's tangent plane.
    fn height_of(&self, point: Vec3) -> f32 {
        self.normal.dot(point - self.point)
    }
}

/// The region swept by the rays from one origin toward the points of one light.
#[derive(Clone, Copy, Debug)]
pub struct Shaft {
    planes: [Plane; MOST_PLANES],
    /// A box around the shaft, tested first.
    bounds: Aabb,
    /// The largest coordinate magnitude of the apex (at least 1), for the margins.
    apex_magnitude: f32,
}

impl Shaft {
    /// The shaft from `surface`'s offset origin `apex` toward a rectangle of corners
    /// `corners` (in order around it), or `None` where the rectangle does not lie wholly in
    /// front of the surface, or the apex lies within 1/64 of the coordinates' magnitude of
    /// its plane (its rays would graze the light).
    pub fn to_rectangle(apex: Vec3, corners: [Vec3; 4], surface: LeavingSurface) -> Option<Self> {
        let centre = corners.iter().sum::<Vec3>() * 0.25;
        let sides: [Plane; 4] = std::array::from_fn(|i| {
            let normal = (corners[i] - apex).cross(corners[(i + 1) % 4] - apex);
            let normal = normal.normalize_or_zero();
            // Oriented so that the rectangle's centre lies inside.
            let normal = if normal.dot(centre - apex) > 0.0 {
                -normal
            } else {
                normal
            };
            Plane::through(apex, normal)
        });
        let facing = (corners[1] - corners[0]).cross(corners[3] - corners[0]);
        let facing = facing.normalize_or_zero();
        // The far plane is the rectangle's own, facing away from the apex.
        let far_normal = if facing.dot(apex - corners[0]) > 0.0 {
            -facing
        } else {
            facing
        };
        let far = Plane::through(corners[0], far_normal);
        let magnitude = (corners.iter().chain([&apex]))
            .map(|p| p.abs().max_element())
            .fold(1.0, f32::max);
        let degenerate = sides.iter().any(|side| side.normal == Vec3::ZERO)
            || facing == Vec3::ZERO
            || -far.outside_by(apex) < LEAST_HEIGHT * magnitude;
        if degenerate {
            return None;
        }
        let mut bounds = Aabb::from_point(apex.into());
        for corner in corners {
            bounds.extend(corner.into());
        }
        let lowest = (corners.iter())
            .map(|&corner| surface.height_of(corner))
            .fold(f32::INFINITY, f32::min);
        let planes = [sides[0], sides[1], sides[2], sides[3], far];
        Self::with_near_plane(apex, planes, bounds, surface, lowest)
    }

    /// The shaft from `apex` toward the part of `sphere` seen from it (rays end before the
    /// sphere's near side), or `None` where the apex is not well outside the sphere or the
    /// sphere does not lie wholly in front of the surface.
    pub fn to_sphere(apex: Vec3, sphere: Sphere, surface: LeavingSurface) -> Option<Self> {
        let to_centre = sphere.center - apex;
        let distance = to_centre.length();
        // (A NaN distance fails too.)
        let well_outside = distance > sphere.radius * 1.001;
        if !well_outside {
            return None;
        }
        let axis = to_centre / distance;
        let sin = sphere.radius / distance;
        let cos = (1.0 - sin * sin).sqrt();
        let (u, v) = axis.any_orthonormal_pair();
        // Four planes through the apex tangent to the cone the sphere subtends.
        let side = |across: Vec3| Plane::through(apex, across * cos - axis * sin);
        // Every point seen on the sphere lies before the circle where the cone touches it.
        let far = Plane::through(apex + axis * (distance - sphere.radius * sin), axis);
        let reach = Vec3::splat(sphere.radius);
        let mut bounds = Aabb::from_point(apex.into());
        bounds.extend((sphere.center - reach).into());
        bounds.extend((sphere.center + reach).into());
        let planes = [side(u), side(-u), side(v), side(-v), far];
        let lowest = surface.height_of(sphere.center) - sphere.radius;
        Self::with_near_plane(apex, planes, bounds, surface, lowest)
    }

    /// The shaft of `planes` and the near plane of `surface`, or `None` unless the light's
    /// lowest point, `lowest` above the surface, lies at least as high as the apex: a ray
    /// from the apex toward the light then stays above the near plane all along.
    fn with_near_plane(
        apex: Vec3,
        planes: [Plane; 5],
        bounds: Aabb,
        surface: LeavingSurface,
        lowest: f32,
    ) -> Option<Self> {
        let above = lowest >= surface.offset && surface.offset > 0.0;
        if !above {
            return None;
        }
        // Halfway between the surface and the rays' origin, facing into the surface.
        let near = Plane::through(
            surface.point + surface.normal * (0.5 * surface.offset),
            -surface.normal,
        );
        let [a, b, c, d, e] = planes;
        Some(Shaft {
            planes: [a, b, c, d, e, near],
            bounds,
            apex_magnitude: apex.abs().max_element().max(1.0),
        })
    }

    /// The margin for a test of coordinates that reach `magnitude` at most (for boxes, the
    /// scene's: one margin for all of a traversal's boxes, the largest any of them needs).
    pub fn margin_for(&self, magnitude: f32) -> f32 {
        RELATIVE_MARGIN * (magnitude + self.apex_magnitude + 1.0)
    }

    /// [`Shaft::margin_for`] the largest coordinate of `aabb`.
    pub(crate) fn margin_for_box(&self, aabb: &Aabb) -> f32 {
        let magnitude = Vec3::from(aabb.min.abs().max(aabb.max.abs())).max_element();
        self.margin_for(magnitude)
    }

    /// Whether `aabb` lies wholly outside the shaft, by `margin` ([`Shaft::margin_for`]).
    #[inline]
    pub fn excludes_box(&self, aabb: &Aabb, margin: f32) -> bool {
        let (min, max) = (Vec3::from(aabb.min), Vec3::from(aabb.max));
        let (bounds_min, bounds_max) = (Vec3::from(self.bounds.min), Vec3::from(self.bounds.max));
        if (min - bounds_max).max_element() > margin || (bounds_min - max).max_element() > margin {
            return true;
        }
        self.planes.iter().any(|plane| {
            // The box's corner farthest inside the plane.
            let inmost = Vec3::select(plane.normal.cmpgt(Vec3::ZERO), min, max);
            plane.outside_by(inmost) > margin
        })
    }

    /// Whether the triangle of `vertices` lies wholly outside the shaft (by a margin).
    #[inline]
    pub fn excludes_triangle(&self, vertices: [Vec3; 3]) -> bool {
        let magnitude = vertices
            .iter()
            .map(|v| v.abs().max_element())
            .fold(0.0, f32::max);
        let margin = self.margin_for(magnitude);
        self.planes.iter().any(|plane| {
            vertices
                .iter()
                .all(|&vertex| plane.outside_by(vertex) > margin)
        })
    }

    /// Whether `sphere` lies wholly outside the shaft (by a margin).
    #[inline]
    pub fn excludes_sphere(&self, sphere: &Sphere) -> bool {
        let margin = self.margin_for(sphere.center.abs().max_element() + sphere.radius);
        (self.planes.iter()).any(|plane| plane.outside_by(sphere.center) > sphere.radius + margin)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floor point's surface (normal +y), its rays' origin, and a square light of side 2
    /// centred 4 above it.
    fn floor_and_square_light() -> (LeavingSurface, Vec3, [Vec3; 4]) {
        let surface = LeavingSurface {
            point: Vec3::ZERO,
            normal: Vec3::Y,
            offset: 1.0 / 65536.0,
        };
        let apex = Vec3::Y * surface.offset;
        let corners = [
            Vec3::new(-1.0, 4.0, -1.0),
            Vec3::new(1.0, 4.0, -1.0),
            Vec3::new(1.0, 4.0, 1.0),
            Vec3::new(-1.0, 4.0, 1.0),
        ];
        (surface, apex, corners)
    }

    #[test]
    fn a_rectangle_shaft_keeps_what_it_crosses_and_excludes_the_rest() {
        let (surface, apex, corners) = floor_and_square_light();
        let shaft = Shaft::to_rectangle(apex, corners, surface).unwrap();
        let across = |y: f32, x: f32| {
            [
                Vec3::new(x - 0.2, y, -0.2),
                Vec3::new(x + 0.2, y, -0.2),
                Vec3::new(x, y, 0.3),
            ]
        };
        // Halfway up, the shaft spans x from −½ to ½.
        assert!(!shaft.excludes_triangle(across(2.0, 0.0)));
        assert!(
            !shaft.excludes_triangle(across(2.0, 0.5)),
            "straddles a side"
        );
        assert!(
            shaft.excludes_triangle(across(2.0, 1.0)),
            "beside the shaft"
        );
        assert!(
            shaft.excludes_triangle(across(4.5, 0.0)),
            "beyond the light"
        );
        // The floor the rays leave, through the gather's point: below the near plane.
        let floor = [
            Vec3::new(-10.0, 0.0, -10.0),
            Vec3::new(10.0, 0.0, -10.0),
            Vec3::new(0.0, 0.0, 10.0),
        ];
        assert!(shaft.excludes_triangle(floor));
        // A sliver just above the floor, higher than the rays' origin, is kept.
        let lifted = floor.map(|v| v + Vec3::Y * 2.0 * surface.offset);
        assert!(!shaft.excludes_triangle(lifted));
        let margin = shaft.margin_for(10.0);
        let beside = Aabb::new(
            Vec3::new(0.7, 1.9, -0.1).into(),
            Vec3::new(1.0, 2.1, 0.1).into(),
        );
        assert!(shaft.excludes_box(&beside, margin));
        let inside = Aabb::new(
            Vec3::new(-0.1, 1.9, -0.1).into(),
            Vec3::new(0.1, 2.1, 0.1).into(),
        );
        assert!(!shaft.excludes_box(&inside, margin));
    }

    #[test]
    fn no_shaft_toward_a_light_the_surface_cuts_or_from_its_own_plane() {
        let (surface, apex, corners) = floor_and_square_light();
        // A light reaching below the surface: some rays would leave from its other side.
        let sunk = corners.map(|c| c - Vec3::Y * 4.5);
        assert!(Shaft::to_rectangle(apex, sunk, surface).is_none());
        // The origin in the light's plane.
        let level = corners.map(|c| c - Vec3::Y * 4.0 + Vec3::Y * surface.offset);
        assert!(Shaft::to_rectangle(apex, level, surface).is_none());
        let around = Sphere {
            center: apex,
            radius: 1.0,
        };
        assert!(Shaft::to_sphere(apex, around, surface).is_none(), "inside");
    }

    #[test]
    fn a_sphere_shaft_holds_the_cone_it_subtends() {
        let (surface, apex, _) = floor_and_square_light();
        let light = Sphere {
            center: Vec3::new(0.0, 4.0, 0.0),
            radius: 1.0,
        };
        let shaft = Shaft::to_sphere(apex, light, surface).unwrap();
        let small = |center: Vec3| Sphere {
            center,
            radius: 0.1,
        };
        // The cone's half-angle is asin(1/4): 0.5 wide at height 2.
        assert!(!shaft.excludes_sphere(&small(Vec3::new(0.45, 2.0, 0.0))));
        assert!(shaft.excludes_sphere(&small(Vec3::new(0.8, 2.0, 0.0))));
        assert!(
            shaft.excludes_sphere(&small(Vec3::new(0.0, 4.9, 0.0))),
            "behind the cap"
        );
        assert!(
            !shaft.excludes_sphere(&light),
            "the light itself reaches in"
        );
    }
}
