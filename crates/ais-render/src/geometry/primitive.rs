//! The primitives the BVH holds: triangles and spheres, with exact intersection, and
//! instances of shape groups (intersected by [`super::Geometry`], which holds the groups).

use super::ray::Ray;
use glam::{Vec2, Vec3};

/// A triangle of a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertices.
    pub vertices: [Vec3; 3],
    /// Index of its mesh in [`super::Geometry`], and of its first vertex normal there.
    pub mesh: u32,
    /// Index of the triangle in its mesh.
    pub index: u32,
}

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
}

/// One primitive of the scene, with the shape it belongs to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    /// A triangle.
    Triangle(Triangle),
    /// A sphere.
    Sphere(Sphere),
    /// A disk or a cylinder: its index among the geometry's quadrics.
    Quadric {
        /// Its index.
        index: u32,
        /// The surface.
        quadric: super::quadric::Quadric,
    },
    /// An instance of a shape group: its index, and its box in world space.
    Instance {
        /// The instance's index.
        index: u32,
        /// Its bounds.
        bounds: obvhs::aabb::Aabb,
    },
}

/// A primitive as traversal tests it, in the BVH's order: a triangle by its first vertex and
/// two edges (36 bytes, computed once rather than per test), or a sphere. What shading needs
/// (mesh, triangle index) lives elsewhere, so the hot array stays small.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Packed {
    /// A triangle: v0, v1 − v0, v2 − v0.
    Triangle([Vec3; 3]),
    /// A sphere.
    Sphere(Sphere),
    /// A disk or a cylinder, by index (kept in [`super::Geometry`]: it is larger than a
    /// triangle).
    Quadric(u32),
    /// An instance of a shape group, by index (its geometry lives in [`super::Geometry`]).
    Instance(u32),
}

impl Packed {
    /// The packed form of `primitive`.
    pub(crate) fn new(primitive: &Primitive) -> Self {
        match primitive {
            Primitive::Triangle(t) => {
                let [v0, v1, v2] = t.vertices;
                Packed::Triangle([v0, v1 - v0, v2 - v0])
            }
            Primitive::Sphere(s) => Packed::Sphere(*s),
            Primitive::Quadric { index, .. } => Packed::Quadric(*index),
            Primitive::Instance { index, .. } => Packed::Instance(*index),
        }
    }

    /// The distance and barycentrics (zero for a sphere) of the hit, if within the ray (an
    /// instance or a quadric is not tested here: see [`super::Geometry`]).
    #[inline]
    pub(crate) fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Vec2)> {
        match self {
            Packed::Triangle([v0, e1, e2]) => moller_trumbore(*v0, *e1, *e2, ray, t_max),
            Packed::Sphere(s) => s.intersect(ray, t_max).map(|t| (t, Vec2::ZERO)),
            Packed::Quadric(_) | Packed::Instance(_) => None,
        }
    }
}

/// Möller-Trumbore with the edges given: the distance and barycentrics (b1, b2) of the hit,
/// if within the ray.
#[inline(always)]
fn moller_trumbore(v0: Vec3, e1: Vec3, e2: Vec3, ray: &Ray, t_max: f32) -> Option<(f32, Vec2)> {
    let p = ray.direction.cross(e2);
    let determinant = e1.dot(p);
    if determinant.abs() < 1e-20 {
        return None;
    }
    let inverse = 1.0 / determinant;
    let s = ray.origin - v0;
    let b1 = s.dot(p) * inverse;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = ray.direction.dot(q) * inverse;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inverse;
    (t > 0.0 && t < t_max).then_some((t, Vec2::new(b1, b2)))
}

impl Triangle {
    /// Möller-Trumbore: the distance and barycentrics (b1, b2) of the hit, if within the ray.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Vec2)> {
        let [v0, v1, v2] = self.vertices;
        moller_trumbore(v0, v1 - v0, v2 - v0, ray, t_max)
    }

    /// The unnormalised geometric normal (e1 × e2), oriented by the winding.
    pub fn normal(&self) -> Vec3 {
        let [v0, v1, v2] = self.vertices;
        (v1 - v0).cross(v2 - v0)
    }
}

impl Sphere {
    /// The nearest hit distance within the ray, if any (the far hit when starting inside).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let (along, discriminant) = self.chord(ray.origin, ray.direction);
        if discriminant < 0.0 {
            return None;
        }
        let half_chord = discriminant.sqrt();
        let near = along - half_chord;
        let far = along + half_chord;
        if near > 0.0 && near < t_max {
            Some(near)
        } else if far > 0.0 && far < t_max {
            Some(far)
        } else {
            None
        }
    }

    /// Which of the lines from `origin` along `directions` miss the sphere: those whose
    /// [`Sphere::intersect`] stops at its first test, worked out by the same steps over
    /// all the lanes at once.
    #[inline(always)]
    pub fn missed_along<const N: usize>(&self, origin: Vec3, directions: &[Vec3; N]) -> [bool; N] {
        std::array::from_fn(|k| self.chord(origin, directions[k]).1 < 0.0)
    }

    /// How far along the line from `origin` along `direction` the point nearest the centre
    /// lies, and the square of half the chord the line cuts (negative: it misses). The
    /// centre is projected onto the line first, a numerically careful form.
    #[inline(always)]
    fn chord(&self, origin: Vec3, direction: Vec3) -> (f32, f32) {
        let to_center = self.center - origin;
        let along = to_center.dot(direction);
        let closest = to_center - along * direction;
        (along, self.radius * self.radius - closest.length_squared())
    }
}

impl obvhs::Boundable for Triangle {
    fn aabb(&self) -> obvhs::aabb::Aabb {
        let [a, b, c] = self.vertices.map(glam::Vec3A::from);
        obvhs::aabb::Aabb::new(a.min(b).min(c), a.max(b).max(c))
    }
}

impl obvhs::Boundable for Primitive {
    fn aabb(&self) -> obvhs::aabb::Aabb {
        match self {
            Primitive::Triangle(t) => t.aabb(),
            Primitive::Sphere(s) => {
                let c = glam::Vec3A::from(s.center);
                let r = glam::Vec3A::splat(s.radius);
                obvhs::aabb::Aabb::new(c - r, c + r)
            }
            Primitive::Quadric { quadric, .. } => quadric.bounds(),
            Primitive::Instance { bounds, .. } => *bounds,
        }
    }
}
