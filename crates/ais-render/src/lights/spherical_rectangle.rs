//! Solid-angle sampling of a rectangle (Ureña, Fajardo and King, "An Area-Preserving
//! Parametrization for Spherical Rectangles", EGSR 2013): directions are uniform over the
//! solid angle the rectangle subtends, so the density is 1 / solid angle, however close or
//! oblique the rectangle is.

use super::ONE_BELOW;
use crate::geometry::Ray;
use glam::{DVec3, Vec3};
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

/// Views subtending at least this solid angle are sampled in f32, smaller ones in f64.
/// The sampler turns `u` into the angle `u · S + k` (`k` up to 2π); in f32 that angle
/// takes about `S / 5e-7` distinct values, so a light of 1e-3 sr keeps some 2000 of them
/// across its width (pbrt-v4 samples in f32 down to 3e-4 sr), while a tiny or distant
/// light would be drawn along a few lines (a chi-square test of the draws over the
/// rectangle fails at 4e-6 sr in f32, and passes at 4e-5 sr). f32 saved about 6% of a
/// Cornell-box frame, where these draws are a sixth of it.
pub const LEAST_F32_SOLID_ANGLE: f64 = 1e-3;

/// How many f32 draws [`Rectangle::sample_view_run`], and how many rays
/// [`Rectangle::distances_along`], works out at once.
pub(crate) const LANES: usize = 16;

/// The spherical rectangle seen from one point: everything the sampler needs, in f32
/// where that is precise enough ([`LEAST_F32_SOLID_ANGLE`]), else in f64.
#[derive(Clone, Copy, Debug)]
pub(crate) struct View {
    /// The solid angle subtended (in f64 whatever the draws use: the density is 1 / it).
    solid_angle: f64,
    draws: Draws,
}

impl View {
    /// The solid angle subtended.
    #[inline]
    pub(crate) fn solid_angle(&self) -> f64 {
        self.solid_angle
    }
}

/// The precision a view's draws are made in.
#[derive(Clone, Copy, Debug)]
enum Draws {
    /// f32.
    Fast(Spherical<f32>),
    /// f64.
    Precise(Spherical<f64>),
}

/// The spherical rectangle in its local frame (`x`, `y` along the edges, `z` away from
/// the point), in the precision `R` it is sampled in.
#[derive(Clone, Copy, Debug)]
struct Spherical<R> {
    x: [R; 3],
    y: [R; 3],
    z: [R; 3],
    x0: R,
    x1: R,
    y0: R,
    y1: R,
    z0: R,
    b0: R,
    b1: R,
    /// 1 − b0², worked out in f64.
    one_minus_b0_squared: R,
    k: R,
    solid_angle: R,
}

/// The arithmetic a draw needs, in f32 or f64.
trait Real:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::Neg<Output = Self>
{
    /// `value` in this precision.
    fn of(value: f64) -> Self;
    /// This value in f32.
    fn as_f32(self) -> f32;
    /// This value in f64.
    fn as_f64(self) -> f64;
    fn sqrt(self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn copysign(self, sign: Self) -> Self;
    fn max(self, other: Self) -> Self;
    fn clamp(self, low: Self, high: Self) -> Self;
}

macro_rules! real {
    ($t:ty, $sin_cos:path) => {
        impl Real for $t {
            #[inline]
            fn of(value: f64) -> Self {
                value as $t
            }
            #[inline]
            fn as_f32(self) -> f32 {
                self as f32
            }
            #[inline]
            fn as_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline]
            fn sin_cos(self) -> (Self, Self) {
                $sin_cos(self)
            }
            #[inline]
            fn copysign(self, sign: Self) -> Self {
                <$t>::copysign(self, sign)
            }
            #[inline]
            fn max(self, other: Self) -> Self {
                <$t>::max(self, other)
            }
            /// `clamp`'s answer (for `low <= high`) by two selects, with no assertion: a
            /// loop of draws runs in lanes.
            #[inline(always)]
            fn clamp(self, low: Self, high: Self) -> Self {
                let above = if self < low { low } else { self };
                if above > high {
                    high
                } else {
                    above
                }
            }
        }
    };
}
// The f32 draws take sin and cos without libm (within 2e-7): a draw's one angle.
real!(f32, ais::fast_trig::sin_cos);
real!(f64, f64::sin_cos);

impl Spherical<f64> {
    /// The same view in f32.
    fn to_f32(self) -> Spherical<f32> {
        let vector = |v: [f64; 3]| v.map(|c| c as f32);
        Spherical {
            x: vector(self.x),
            y: vector(self.y),
            z: vector(self.z),
            x0: self.x0 as f32,
            x1: self.x1 as f32,
            y0: self.y0 as f32,
            y1: self.y1 as f32,
            z0: self.z0 as f32,
            b0: self.b0 as f32,
            one_minus_b0_squared: self.one_minus_b0_squared as f32,
            b1: self.b1 as f32,
            k: self.k as f32,
            solid_angle: self.solid_angle as f32,
        }
    }
}

impl<R: Real> Spherical<R> {
    /// The direction for `u` (uniform over the solid angle when `u` is uniform) and the
    /// distance to the point drawn. Inline and without a branch, so that a loop of draws
    /// runs in lanes.
    #[inline(always)]
    fn sample(&self, u: [f32; 2]) -> (Vec3, f32) {
        let one = R::of(1.0);
        let au = R::of(u[0] as f64) * self.solid_angle + self.k;
        let (sin_au, cos_au) = au.sin_cos();
        // The paper's x_u = −z0 c_u / √(1 − c_u²), with c_u = sign(f_u) / √(f_u² + b0²) and
        // f_u = n / sin a_u, n = cos a_u · b0 − b1, is −z0 sign(n) sin a_u / √(n² − (1 −
        // b0²) sin² a_u): one square root and one division in the chain where there were
        // three of each.
        let n = cos_au * self.b0 - self.b1;
        let below = (n * n - self.one_minus_b0_squared * sin_au * sin_au).max(R::of(1e-30));
        let xu = (-self.z0 * one.copysign(n) * sin_au / below.sqrt()).clamp(self.x0, self.x1);
        let distance_squared = xu * xu + self.z0 * self.z0;
        let distance = distance_squared.sqrt();
        let h0 = self.y0 / (distance_squared + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (distance_squared + self.y1 * self.y1).sqrt();
        let hv = h0 + R::of(u[1] as f64) * (h1 - h0);
        let hv2 = hv * hv;
        // (In f32, 1 − 1e-12 rounds to 1.) Worked out either way and then selected, for
        // the lanes: at the edge the quotient is not finite, and not taken.
        let inside = (hv * distance / (one - hv2).sqrt()).clamp(self.y0, self.y1);
        let yv = if hv2 < one - R::of(1e-12) {
            inside
        } else {
            self.y1
        };
        // x, y and z are orthonormal: the offset's length needs no sum over its components.
        let length = (distance_squared + yv * yv).sqrt();
        let scale = one / length;
        let direction: [f32; 3] = std::array::from_fn(|i| {
            ((xu * self.x[i] + yv * self.y[i] + self.z0 * self.z[i]) * scale).as_f32()
        });
        (Vec3::from(direction), length.as_f32())
    }

    /// The point of the sample square that [`Spherical::sample`] maps to the point at
    /// `offset` from the receiver (on the rectangle), worked out in f64: `u₀` is the share
    /// of the solid angle left of the point, `u₁` its place between the rectangle's edges
    /// along `y`, as the draw measures them.
    fn square_of(&self, offset: Vec3) -> [f32; 2] {
        let f = Real::as_f64;
        let along = |axis: &[R; 3]| (0..3).map(|i| offset[i] as f64 * f(axis[i])).sum::<f64>();
        let (z0, y0, y1) = (f(self.z0), f(self.y0), f(self.y1));
        let xu = along(&self.x).clamp(f(self.x0), f(self.x1));
        let yv = along(&self.y).clamp(y0, y1);
        // The solid angle of the part [x0, xu] × [y0, y1]: the view's sum with x1 = xu (its
        // `k` does not depend on x1).
        let n0 = DVec3::new(0.0, z0, -y0).normalize();
        let n1 = DVec3::new(-z0, 0.0, xu).normalize();
        let n2 = DVec3::new(0.0, -z0, y1).normalize();
        let part = angle_between(n0, n1) + angle_between(n1, n2) - f(self.k);
        let distance_squared = xu * xu + z0 * z0;
        let h = |y: f64| y / (distance_squared + y * y).sqrt();
        let (h0, h1) = (h(y0), h(y1));
        let v = if h1 > h0 {
            (h(yv) - h0) / (h1 - h0)
        } else {
            0.5
        };
        [part / f(self.solid_angle), v].map(|c| (c as f32).clamp(0.0, ONE_BELOW))
    }
}

/// The interior angle of a spherical polygon between edges of inner normals `a` and `b`.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    (-a.dot(b)).clamp(-1.0, 1.0).acos()
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

    /// Its four corners, in order around it.
    pub fn corners(&self) -> [Vec3; 4] {
        let (corner, x, y) = (self.corner, self.edge_x, self.edge_y);
        [corner, corner + x, corner + x + y, corner + y]
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
        let n0 = DVec3::new(0.0, z0, -y0).normalize();
        let n1 = DVec3::new(-z0, 0.0, x1).normalize();
        let n2 = DVec3::new(0.0, -z0, y1).normalize();
        let n3 = DVec3::new(z0, 0.0, -x0).normalize();
        let angle = angle_between;
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = 2.0 * PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        if solid_angle <= 1e-12 {
            return None;
        }
        let precise = Spherical {
            x: x.into(),
            y: y.into(),
            z: z.into(),
            x0,
            x1,
            y0,
            y1,
            z0,
            b0: n0.z,
            one_minus_b0_squared: 1.0 - n0.z * n0.z,
            b1: n2.z,
            k,
            solid_angle,
        };
        let draws = if solid_angle >= LEAST_F32_SOLID_ANGLE {
            Draws::Fast(precise.to_f32())
        } else {
            Draws::Precise(precise)
        };
        Some(View { solid_angle, draws })
    }

    /// A direction from `point`, uniform over the subtended solid angle, and its density.
    pub fn sample(&self, point: Vec3, u: [f32; 2]) -> Option<(Vec3, f64)> {
        let (direction, pdf, _) = Self::sample_view(&self.view(point)?, u);
        Some((direction, pdf))
    }

    /// [`Rectangle::sample`] from the point where `v` was seen, with the distance to the
    /// point drawn.
    pub(crate) fn sample_view(view: &View, u: [f32; 2]) -> (Vec3, f64, f32) {
        let (direction, distance) = match &view.draws {
            Draws::Fast(fast) => fast.sample(u),
            Draws::Precise(precise) => precise.sample(u),
        };
        (direction, 1.0 / view.solid_angle, distance)
    }

    /// [`Rectangle::sample_view`] for each of `numbers`, given to `put` with its index, the
    /// direction, the density and the distance: an f32 view's draws worked out over runs of
    /// [`LANES`] at once, to the bit as one at a time.
    pub(crate) fn sample_view_run(
        view: &View,
        numbers: &[[f32; 2]],
        mut put: impl FnMut(usize, Vec3, f64, f32),
    ) {
        let pdf = 1.0 / view.solid_angle;
        let Draws::Fast(fast) = &view.draws else {
            for (k, &u) in numbers.iter().enumerate() {
                let (direction, pdf, distance) = Self::sample_view(view, u);
                put(k, direction, pdf, distance);
            }
            return;
        };
        for (run, numbers) in numbers.chunks(LANES).enumerate() {
            // Lanes past the run's numbers draw from (harmless) zeros.
            let mut lanes = [[0.0; 2]; LANES];
            lanes[..numbers.len()].copy_from_slice(numbers);
            let drawn: [(Vec3, f32); LANES] = std::array::from_fn(|k| fast.sample(lanes[k]));
            for (k, &(direction, distance)) in drawn[..numbers.len()].iter().enumerate() {
                put(run * LANES + k, direction, pdf, distance);
            }
        }
    }

    /// The point of the sample square that [`Rectangle::sample_view`] maps to the point
    /// `offset` from where `view` was seen (a point of the rectangle).
    pub(crate) fn square_of(view: &View, offset: Vec3) -> [f32; 2] {
        match &view.draws {
            Draws::Fast(fast) => fast.square_of(offset),
            Draws::Precise(precise) => precise.square_of(offset),
        }
    }

    /// The solid angle the rectangle subtends at `point` (0 in its plane).
    pub fn solid_angle(&self, point: Vec3) -> f64 {
        self.view(point).as_ref().map_or(0.0, View::solid_angle)
    }

    /// Distance along the ray to the rectangle, if it hits it (either side).
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let t = self.distance_along(ray);
        (t != f32::INFINITY).then_some(t)
    }

    /// [`Rectangle::intersect`] for unbounded rays from `origin` along each of
    /// `directions`, worked out over the lanes at once (infinite where a ray misses).
    pub(crate) fn distances_along(&self, origin: Vec3, directions: &[Vec3; LANES]) -> [f32; LANES] {
        std::array::from_fn(|k| self.distance_along(&Ray::new(origin, directions[k])))
    }

    /// The distance along `ray` to the rectangle, infinite where it misses. Every test is
    /// made and then combined, with no branch, so that a loop of rays runs in lanes.
    #[inline(always)]
    fn distance_along(&self, ray: &Ray) -> f32 {
        let denominator = ray.direction.dot(self.normal);
        let t = (self.corner - ray.origin).dot(self.normal) / denominator;
        let local = ray.at(t) - self.corner;
        let a = local.dot(self.edge_x) / self.edge_x.length_squared();
        let b = local.dot(self.edge_y) / self.edge_y.length_squared();
        let within = |c: f32| (0.0..=1.0).contains(&c);
        let hit = (denominator.abs() >= 1e-12) & (t > 0.0) & (t < ray.t_max);
        if hit & within(a) & within(b) {
            t
        } else {
            f32::INFINITY
        }
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

    /// A rectangle tilted against the axes, emitting toward the origin's side.
    fn tilted() -> Rectangle {
        Rectangle::new(
            Vec3::new(0.2, -0.5, 2.0),
            Vec3::new(1.0, 0.0, 0.3),
            Vec3::new(0.0, 0.8, 0.0),
            true,
        )
        .unwrap()
    }

    #[test]
    fn samples_hit_the_rectangle() {
        let r = tilted();
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

    #[test]
    fn the_inverse_map_finds_the_point_of_the_square_a_direction_was_drawn_from() {
        // A large view (drawn in f32) and a small one (in f64).
        let r = tilted();
        let mut rng = ais::rng::Pcg32::new(4, 2);
        for origin in [Vec3::new(0.1, 0.1, 0.0), Vec3::new(30.0, -20.0, -40.0)] {
            let view = r.view(origin).unwrap();
            for _ in 0..2000 {
                let u = [rng.next_f32(), rng.next_f32()];
                let (direction, _, distance) = Rectangle::sample_view(&view, u);
                let found = Rectangle::square_of(&view, direction * distance);
                let error = (found[0] - u[0]).abs().max((found[1] - u[1]).abs());
                assert!(error < 2e-3, "{u:?} came back as {found:?} from {origin}");
            }
        }
    }
}
