//! Mitsuba's `disk` and `cylinder` as exact surfaces: the unit disk (z = 0, radius 1) and
//! the open unit cylinder (radius 1 around z, from z = 0 to 1) under an affine transform.
//! A ray is carried into the shape's frame (where distances along it do not change, as its
//! direction is not renormalised) and solved there; what shading needs follows Mitsuba's
//! conventions: on a disk the texture coordinates are (radius, azimuth / 2π), on a cylinder
//! (azimuth / 2π, height), normals go through the inverse transpose.
//!
//! Points are drawn uniformly over the surface's area, for area lights, with their density
//! per unit area in the world (exact under any affine transform: on an elliptic cylinder it
//! varies with the azimuth).

use super::ray::Ray;
use glam::{Affine3A, DMat4, DVec3, Mat3, Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use std::f64::consts::TAU;

/// Which surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QuadricKind {
    /// The unit disk.
    Disk,
    /// The open unit cylinder.
    Cylinder,
}

/// A disk or a cylinder in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// Which surface.
    pub kind: QuadricKind,
    to_world: Affine3A,
    to_local: Affine3A,
    /// The inverse transpose of the linear part: normals to the world.
    normals_to_world: Mat3,
    /// Area in the world.
    area: f64,
}

/// What shading needs at a point of a quadric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadricSurface {
    /// Unit normal (outward on a cylinder, along +z of the frame on a disk).
    pub normal: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// ∂p/∂u.
    pub dp_du: Vec3,
    /// ∂p/∂v.
    pub dp_dv: Vec3,
}

/// A point drawn on a quadric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadricSample {
    /// The point.
    pub point: Vec3,
    /// Its unit normal (as [`QuadricSurface::normal`]).
    pub normal: Vec3,
    /// The density of drawing it, per unit area.
    pub density: f64,
}

impl Quadric {
    /// The unit disk under `to_world` (`None`: the transform flattens it).
    pub fn disk(to_world: DMat4) -> Option<Self> {
        Self::new(QuadricKind::Disk, to_world)
    }

    /// Mitsuba's cylinder of `radius` from `p0` to `p1`, under `to_world` (`None`: it is
    /// degenerate). Its azimuth starts along the first axis of the frame around p1 − p0.
    pub fn cylinder(to_world: DMat4, p0: DVec3, p1: DVec3, radius: f64) -> Option<Self> {
        let axis = p1 - p0;
        let length = axis.length();
        if !(length > 0.0 && radius > 0.0) {
            return None;
        }
        let (x, y) = super::basis(axis.normalize().as_vec3());
        let frame = DMat4::from_cols(
            (x.as_dvec3() * radius).extend(0.0),
            (y.as_dvec3() * radius).extend(0.0),
            axis.extend(0.0),
            p0.extend(1.0),
        );
        Self::new(QuadricKind::Cylinder, to_world * frame)
    }

    fn new(kind: QuadricKind, to_world: DMat4) -> Option<Self> {
        let determinant = to_world.determinant();
        if determinant == 0.0 || !to_world.is_finite() {
            return None;
        }
        let to_world = Affine3A::from_mat4(to_world.as_mat4());
        let to_local = to_world.inverse();
        let mut quadric = Quadric {
            kind,
            to_world,
            to_local,
            normals_to_world: Mat3::from(to_local.matrix3).transpose(),
            area: 0.0,
        };
        quadric.area = quadric.world_area();
        (quadric.area > 0.0 && quadric.area.is_finite()).then_some(quadric)
    }

    /// Area in the world.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// How much the transform stretches area at azimuth `phi` (cylinder: per unit azimuth
    /// and height; disk: per unit area of the unit disk, the same everywhere).
    fn area_scale(&self, phi: f64) -> f64 {
        let m = |v: Vec3| self.to_world.transform_vector3(v).as_dvec3();
        match self.kind {
            QuadricKind::Disk => m(Vec3::X).cross(m(Vec3::Y)).length(),
            QuadricKind::Cylinder => {
                let around = Vec3::new(-phi.sin() as f32, phi.cos() as f32, 0.0);
                m(around).cross(m(Vec3::Z)).length()
            }
        }
    }

    fn world_area(&self) -> f64 {
        match self.kind {
            QuadricKind::Disk => std::f64::consts::PI * self.area_scale(0.0),
            QuadricKind::Cylinder => {
                // Exact for a circular section; an elliptic one to far below f32's precision.
                let steps = 512;
                (0..steps)
                    .map(|k| self.area_scale(TAU * (k as f64 + 0.5) / steps as f64))
                    .sum::<f64>()
                    * TAU
                    / steps as f64
            }
        }
    }

    /// The nearest distance along `ray` in (0, `t_max`) where it meets the surface.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let o = self.to_local.transform_point3(ray.origin).as_dvec3();
        let d = self.to_local.transform_vector3(ray.direction).as_dvec3();
        let within = |t: f64| t > 0.0 && t < t_max as f64;
        match self.kind {
            QuadricKind::Disk => {
                let t = -o.z / d.z;
                let (x, y) = (o.x + t * d.x, o.y + t * d.y);
                (within(t) && x * x + y * y <= 1.0).then_some(t as f32)
            }
            QuadricKind::Cylinder => {
                let a = d.x * d.x + d.y * d.y;
                let b = 2.0 * (o.x * d.x + o.y * d.y);
                let c = o.x * o.x + o.y * o.y - 1.0;
                let discriminant = b * b - 4.0 * a * c;
                if a == 0.0 || discriminant < 0.0 {
                    return None;
                }
                // The stable form of the two roots.
                let q = -0.5 * (b + b.signum() * discriminant.sqrt());
                let (r0, r1) = (q / a, c / q);
                let (near, far) = (r0.min(r1), r0.max(r1));
                [near, far]
                    .into_iter()
                    .find(|&t| within(t) && (0.0..=1.0).contains(&(o.z + t * d.z)))
                    .map(|t| t as f32)
            }
        }
    }

    /// Normal, texture coordinates and tangents at `point` (on the surface).
    pub fn surface_at(&self, point: Vec3) -> QuadricSurface {
        let local = self.to_local.transform_point3(point);
        let radius = local.x.hypot(local.y);
        let (cos_phi, sin_phi) = if radius > 0.0 {
            (local.x / radius, local.y / radius)
        } else {
            (1.0, 0.0)
        };
        let mut azimuth = sin_phi.atan2(cos_phi) / std::f32::consts::TAU;
        if azimuth < 0.0 {
            azimuth += 1.0;
        }
        let m = |v: Vec3| self.to_world.transform_vector3(v);
        let (local_normal, uv, dp_du, dp_dv) = match self.kind {
            QuadricKind::Disk => (
                Vec3::Z,
                Vec2::new(radius, azimuth),
                m(Vec3::new(cos_phi, sin_phi, 0.0)),
                m(Vec3::new(-sin_phi, cos_phi, 0.0)),
            ),
            QuadricKind::Cylinder => (
                Vec3::new(cos_phi, sin_phi, 0.0),
                Vec2::new(azimuth, local.z.clamp(0.0, 1.0)),
                m(Vec3::new(-sin_phi, cos_phi, 0.0) * std::f32::consts::TAU),
                m(Vec3::Z),
            ),
        };
        QuadricSurface {
            normal: (self.normals_to_world * local_normal).normalize_or(Vec3::Z),
            uv,
            dp_du,
            dp_dv,
        }
    }

    /// A point drawn uniformly over the surface's area.
    pub fn sample(&self, u: [f32; 2]) -> QuadricSample {
        let phi = TAU * u[1] as f64;
        let local = match self.kind {
            QuadricKind::Disk => {
                let r = (u[0] as f64).sqrt();
                DVec3::new(r * phi.cos(), r * phi.sin(), 0.0)
            }
            QuadricKind::Cylinder => DVec3::new(phi.cos(), phi.sin(), u[0] as f64),
        };
        let point = self.to_world.transform_point3(local.as_vec3());
        QuadricSample {
            point,
            normal: self.surface_at(point).normal,
            density: self.area_density(point),
        }
    }

    /// The density of [`Quadric::sample`] per unit area at `point` (on the surface).
    pub fn area_density(&self, point: Vec3) -> f64 {
        match self.kind {
            QuadricKind::Disk => 1.0 / self.area,
            QuadricKind::Cylinder => {
                let local = self.to_local.transform_point3(point);
                let phi = (local.y as f64).atan2(local.x as f64);
                1.0 / (TAU * self.area_scale(phi))
            }
        }
    }

    /// The box around the surface.
    pub fn bounds(&self) -> Aabb {
        // An ellipse's box: its centre ± the length of each row of its two axes.
        let ellipse = |centre: Vec3| {
            let (x, y) = (
                self.to_world.transform_vector3(Vec3::X),
                self.to_world.transform_vector3(Vec3::Y),
            );
            let half = Vec3A::new(x.x.hypot(y.x), x.y.hypot(y.y), x.z.hypot(y.z));
            let centre = Vec3A::from(self.to_world.transform_point3(centre));
            Aabb::new(centre - half, centre + half)
        };
        match self.kind {
            QuadricKind::Disk => ellipse(Vec3::ZERO),
            QuadricKind::Cylinder => ellipse(Vec3::ZERO).union(&ellipse(Vec3::Z)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn areas_are_exact() {
        let disk = Quadric::disk(DMat4::from_scale(DVec3::new(2.0, 3.0, 1.0))).unwrap();
        assert!((disk.area() - std::f64::consts::PI * 6.0).abs() < 1e-4);
        let cylinder =
            Quadric::cylinder(DMat4::IDENTITY, DVec3::ZERO, DVec3::new(0.0, 2.0, 0.0), 0.5)
                .unwrap();
        assert!((cylinder.area() - TAU * 0.5 * 2.0).abs() < 1e-4);
        assert!(Quadric::disk(DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0))).is_none());
    }

    #[test]
    fn a_ray_meets_the_near_side_of_a_cylinder_and_the_far_side_from_inside() {
        let cylinder =
            Quadric::cylinder(DMat4::IDENTITY, DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0), 1.0)
                .unwrap();
        let from_outside = Ray::new(Vec3::new(-3.0, 0.0, 1.0), Vec3::X);
        assert!((cylinder.intersect(&from_outside, f32::INFINITY).unwrap() - 2.0).abs() < 1e-6);
        let from_inside = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::X);
        assert!((cylinder.intersect(&from_inside, f32::INFINITY).unwrap() - 1.0).abs() < 1e-6);
        let above = Ray::new(Vec3::new(-3.0, 0.0, 2.5), Vec3::X);
        assert!(cylinder.intersect(&above, f32::INFINITY).is_none());
        let surface = cylinder.surface_at(Vec3::new(-1.0, 0.0, 1.0));
        assert!((surface.normal - Vec3::NEG_X).length() < 1e-6);
        assert!((surface.uv.y - 0.5).abs() < 1e-6);
    }

    #[test]
    fn boxes_hold_their_surfaces() {
        let to_world = DMat4::from_rotation_x(0.7) * DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0));
        for quadric in [
            Quadric::disk(to_world).unwrap(),
            Quadric::cylinder(to_world, DVec3::ZERO, DVec3::new(1.0, 1.0, 2.0), 0.7).unwrap(),
        ] {
            let bounds = quadric.bounds();
            for k in 0..400 {
                let u = [(k % 20) as f32 / 19.0, (k / 20) as f32 / 20.0];
                let p = Vec3A::from(quadric.sample(u).point);
                let slack = Vec3A::splat(1e-4);
                assert!(p.cmpge(bounds.min - slack).all() && p.cmple(bounds.max + slack).all());
            }
        }
    }
}
