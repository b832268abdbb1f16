//! Solid-angle sampling of a rectangle (Ureña, Fajardo and King, "An Area-Preserving
//! Parametrization for Spherical Rectangles", EGSR 2013): directions are uniform over the
//! solid angle the rectangle subtends, so the density is 1 / solid angle, however close or
//! oblique the rectangle is.

use crate::geometry::Ray;
use glam::Vec3;
use std::f64::consts::PI;

/// A rectangle: a corner and two orthogonal edges; it emits toward `normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rectangle {
    /// One corner.
    pub corner: Vec3,
    /// First edge (from the corner).
    pub edge_x: Vec3,
    /// Second edge, orthogonal to the first.
    pub edge_y: Vec3,
    /// Unit normal of the emitting side.
    pub normal: Vec3,
}

/// The spherical rectangle seen from one point: everything the sampler needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct View {
    x: glam::DVec3,
    y: glam::DVec3,
    z: glam::DVec3,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    b0: f64,
    b1: f64,
    k: f64,
    solid_angle: f64,
}

impl Rectangle {
    /// The rectangle with corner `corner` and edges `edge_x`, `edge_y`, if the edges are
    /// orthogonal and non-degenerate; it emits toward `edge_x × edge_y`, or the opposite side
    /// when `flipped`.
    pub fn new(corner: Vec3, edge_x: Vec3, edge_y: Vec3, flipped: bool) -> Option<Self> {
        let (lx, ly) = (edge_x.length(), edge_y.length());
        if lx <= 0.0 || ly <= 0.0 || edge_x.dot(edge_y).abs() > 1e-5 * lx * ly {
            return None;
        }
        let normal = edge_x.cross(edge_y).normalize();
        Some(Rectangle {
            corner,
            edge_x,
            edge_y,
            normal: if flipped { -normal } else { normal },
        })
    }

    /// Area.
    pub fn area(&self) -> f64 {
        self.edge_x.cross(self.edge_y).length() as f64
    }

    /// How the rectangle looks from `point` (None: from its plane, or subtending nothing).
    pub(crate) fn view(&self, point: Vec3) -> Option<View> {
        let origin = point.as_dvec3();
        let ex = self.edge_x.as_dvec3();
        let ey = self.edge_y.as_dvec3();
        let (exl, eyl) = (ex.length(), ey.length());
        let x = ex / exl;
        let y = ey / eyl;
        let mut z = x.cross(y);
        let d = self.corner.as_dvec3() - origin;
        let mut z0 = d.dot(z);
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        if z0.abs() < 1e-9 {
            return None; // the point lies in the rectangle's plane
        }
        let x0 = d.dot(x);
        let y0 = d.dot(y);
        let (x1, y1) = (x0 + exl, y0 + eyl);
        let n0 = glam::DVec3::new(0.0, z0, -y0).normalize();
        let n1 = glam::DVec3::new(-z0, 0.0, x1).normalize();
        let n2 = glam::DVec3::new(0.0, -z0, y1).normalize();
        let n3 = glam::DVec3::new(z0, 0.0, -x0).normalize();
        let angle = |a: glam::DVec3, b: glam::DVec3| (-a.dot(b)).clamp(-1.0, 1.0).acos();
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = 2.0 * PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        (solid_angle > 1e-12).then_some(View {
            x,
            y,
            z,
            x0,
            x1,
            y0,
            y1,
            z0,
            b0: n0.z,
            b1: n2.z,
            k,
            solid_angle,
        })
    }

    /// A direction from `point`, uniform over the subtended solid angle, and its density.
    pub fn sample(&self, point: Vec3, u: [f32; 2]) -> Option<(Vec3, f64)> {
        let (direction, pdf, _) = Self::sample_view(&self.view(point)?, u);
        Some((direction, pdf))
    }

    /// [`Rectangle::sample`] from the point where `v` was seen, with the distance to the
    /// point drawn.
    pub(crate) fn sample_view(v: &View, u: [f32; 2]) -> (Vec3, f64, f32) {
        let au = u[0] as f64 * v.solid_angle + v.k;
        let fu = (au.cos() * v.b0 - v.b1) / au.sin();
        let cu = (1.0 / (fu * fu + v.b0 * v.b0).sqrt())
            .copysign(fu)
            .clamp(-1.0, 1.0);
        let xu = (-(cu * v.z0) / (1.0 - cu * cu).max(1e-18).sqrt()).clamp(v.x0, v.x1);
        let distance = (xu * xu + v.z0 * v.z0).sqrt();
        let h0 = v.y0 / (distance * distance + v.y0 * v.y0).sqrt();
        let h1 = v.y1 / (distance * distance + v.y1 * v.y1).sqrt();
        let hv = h0 + u[1] as f64 * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 {
            (hv * distance / (1.0 - hv2).sqrt()).clamp(v.y0, v.y1)
        } else {
            v.y1
        };
        let offset = xu * v.x + yv * v.y + v.z0 * v.z;
        let distance = offset.length();
        (
            (offset / distance).as_vec3(),
            1.0 / v.solid_angle,
            distance as f32,
        )
    }

    /// The solid angle the rectangle subtends at `point` (0 in its plane).
    pub fn solid_angle(&self, point: Vec3) -> f64 {
        self.view(point).map_or(0.0, |v| v.solid_angle)
    }

    /// The solid angle it subtends where `view` was seen from (0 for no view).
    pub(crate) fn view_solid_angle(view: Option<View>) -> f64 {
        view.map_or(0.0, |v| v.solid_angle)
    }

    /// Distance along the ray to the rectangle, if it hits it (either side).
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let denominator = ray.direction.dot(self.normal);
        if denominator.abs() < 1e-12 {
            return None;
        }
        let t = (self.corner - ray.origin).dot(self.normal) / denominator;
        if !(t > 0.0 && t < ray.t_max) {
            return None;
        }
        let local = ray.at(t) - self.corner;
        let a = local.dot(self.edge_x) / self.edge_x.length_squared();
        let b = local.dot(self.edge_y) / self.edge_y.length_squared();
        ((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solid_angle_of_a_square_seen_from_its_axis() {
        // A 2 × 2 square at distance 1 subtends 4 asin(1/3) · ... = 2π/3.
        let square = Rectangle::new(
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            false,
        )
        .unwrap();
        assert!((square.solid_angle(Vec3::ZERO) - 2.0 * PI / 3.0).abs() < 1e-9);
        assert_eq!(square.solid_angle(Vec3::new(5.0, 0.0, 1.0)), 0.0);
    }

    #[test]
    fn samples_hit_the_rectangle() {
        let r = Rectangle::new(
            Vec3::new(0.2, -0.5, 2.0),
            Vec3::new(1.0, 0.0, 0.3),
            Vec3::new(0.0, 0.8, 0.0),
            true,
        )
        .unwrap();
        let mut rng = ais::rng::Pcg32::new(1, 1);
        let origin = Vec3::new(0.1, 0.1, 0.0);
        for _ in 0..1000 {
            let (d, pdf) = r.sample(origin, [rng.next_f32(), rng.next_f32()]).unwrap();
            assert!(r.intersect(&Ray::new(origin, d)).is_some());
            assert!((pdf - 1.0 / r.solid_angle(origin)).abs() < 1e-9);
        }
        assert!(
            Rectangle::new(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), false).is_none(),
            "sheared"
        );
    }
}
