//! Area lights: spheres (sampled uniformly inside the subtended cone), rectangles (by solid
//! angle), disks and cylinders (uniformly by area) and triangle meshes ([`MeshEmitter`]: area-weighted triangle choice, uniform points
//! on the triangle, a BVH for densities and hits). Emission is one-sided, toward the surface normal, as in Mitsuba.
//! A textured radiance is looked up at the emitting point's texture coordinates (Mitsuba's
//! layouts on spheres and rectangles, the mesh's own elsewhere); sampling stays by solid
//! angle or area, which any radiance keeps unbiased.

use super::mesh_emitter::MeshEmitter;
use super::spherical_rectangle::Rectangle;
use super::Receiver;
use crate::geometry::{sphere_texcoords, Quadric, Ray, Sphere, Triangle};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f64::consts::PI;
use std::sync::Arc;

/// How far below a receiver's plane (a cosine) a light must lie to be left undrawn: f32
/// draws toward it come out within 1e-6 of their exact direction, far inside this.
const BEHIND_MARGIN: f32 = 1e-4;

/// The emitting surface.
#[derive(Clone, Debug)]
pub enum AreaShape {
    /// A sphere emitting outward (inward when its normals are flipped).
    Sphere {
        /// The sphere.
        sphere: Sphere,
        /// Whether the shape's normals are flipped.
        flipped: bool,
    },
    /// A rectangle, sampled uniformly in the solid angle it subtends.
    Rectangle(Rectangle),
    /// A disk or a cylinder, sampled uniformly by area, emitting toward its normal (away
    /// from it when its normals are flipped).
    Quadric {
        /// The surface.
        quadric: Quadric,
        /// Whether the shape's normals are flipped.
        flipped: bool,
    },
    /// Triangles, each emitting toward the side of its (possibly flipped) winding normal.
    Triangles(Box<MeshEmitter>),
}

/// A light sample: where it points and what it sends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaSample {
    /// Unit direction from the receiver toward the light.
    pub direction: Vec3,
    /// Density in solid angle at the receiver of drawing this point of the light.
    pub pdf: f64,
    /// Distance from the receiver to the point drawn.
    pub distance: f32,
    /// The light's geometric normal there (toward its emitting side for a front face).
    pub normal: Vec3,
    /// Which triangle of a mesh light, and where on it.
    pub spot: LightSpot,
}

impl AreaSample {
    /// The sample of a point of `rectangle` drawn along `direction` with density `pdf`, at
    /// `distance`.
    #[inline]
    pub(super) fn on_rectangle(
        rectangle: &Rectangle,
        direction: Vec3,
        pdf: f64,
        distance: f32,
    ) -> Self {
        AreaSample {
            direction,
            pdf,
            distance,
            normal: rectangle.normal,
            spot: LightSpot::default(),
        }
    }
}

/// Where on a mesh light a point lies (unused by spheres and rectangles, whose texture
/// coordinates follow from the point).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSpot {
    /// The triangle's index in the light.
    pub triangle: u32,
    /// Barycentric coordinates of the point (of the second and third vertex).
    pub barycentrics: Vec2,
}

/// The nearest point of an area light along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaHit {
    /// Its distance.
    pub distance: f32,
    /// The light's geometric normal there.
    pub normal: Vec3,
    /// Which triangle of a mesh light.
    pub spot: LightSpot,
}

/// An area light.
#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The surface.
    pub shape: AreaShape,
    /// Emitted radiance (front side); a texture's value multiplies it.
    pub radiance: Vec3,
    /// The texture that gives the radiance over the surface, if one does.
    pub texture: Option<Arc<Texture>>,
    /// The geometry shape it belongs to.
    pub shape_index: u32,
}

/// A sphere seen from a point outside it: the cone of directions it subtends, and how far
/// its centre is.
struct SphereView {
    /// Toward the centre (unit).
    axis: Vec3,
    /// The cosine of the cone's half-angle.
    cos_max: f64,
    /// The squared distance to the centre.
    distance_squared: f64,
    /// The squared radius.
    radius_squared: f64,
}

impl SphereView {
    /// `sphere` seen from `point` (`None` from inside it).
    #[inline]
    fn new(sphere: &Sphere, point: Vec3) -> Option<Self> {
        let to_center = sphere.center - point;
        let distance_squared = to_center.length_squared() as f64;
        let radius_squared = (sphere.radius as f64).powi(2);
        if distance_squared <= radius_squared {
            return None;
        }
        Some(SphereView {
            axis: to_center.normalize(),
            cos_max: (1.0 - radius_squared / distance_squared).max(0.0).sqrt(),
            distance_squared,
            radius_squared,
        })
    }

    /// The density of directions drawn uniformly in the cone, in solid angle.
    #[inline]
    fn density(&self) -> f64 {
        1.0 / (2.0 * PI * (1.0 - self.cos_max))
    }

    /// A point of `sphere` (seen from `point` as this view) drawn uniformly in the cone's
    /// solid angle from `u`; its normal faces inward where the sphere's normals are
    /// `flipped`.
    #[inline]
    fn sample(&self, sphere: &Sphere, flipped: bool, point: Vec3, u: [f32; 2]) -> AreaSample {
        // The cone's angle in f64 (a small cone's 1 − cos θ is below f32's resolution at
        // 1); the azimuth needs no more than f32.
        let cos_theta = 1.0 - u[0] as f64 * (1.0 - self.cos_max);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt() as f32;
        let (sin_phi, cos_phi) = ais::fast_trig::sin_cos(std::f32::consts::TAU * u[1]);
        let (t, b) = crate::geometry::basis(self.axis);
        let direction =
            (t * (sin_theta * cos_phi) + b * (sin_theta * sin_phi) + self.axis * cos_theta as f32)
                .normalize();
        let distance = self.distance_at(cos_theta) as f32;
        let outward = (point + direction * distance - sphere.center) / sphere.radius;
        AreaSample {
            direction,
            pdf: self.density(),
            distance,
            normal: if flipped { -outward } else { outward },
            spot: LightSpot::default(),
        }
    }

    /// How far the near side of the sphere is along a direction at `cos_theta` from the
    /// axis (within the cone): the near root of the ray's quadratic, in closed form. At
    /// the rim, where rounding puts the direction just outside, the tangent point.
    #[inline]
    fn distance_at(&self, cos_theta: f64) -> f64 {
        let sin_squared = (1.0 - cos_theta * cos_theta).max(0.0);
        let half_chord = (self.radius_squared - self.distance_squared * sin_squared).max(0.0);
        self.distance_squared.sqrt() * cos_theta - half_chord.sqrt()
    }
}

impl AreaLight {
    /// Triangles (wound toward the emitting side) as a light.
    pub fn from_triangles(triangles: Vec<Triangle>, radiance: Vec3, shape_index: u32) -> Self {
        AreaLight {
            shape: AreaShape::Triangles(Box::new(MeshEmitter::new(triangles, None))),
            radiance,
            texture: None,
            shape_index,
        }
    }

    /// Emitted power, π · luminance · area (one-sided Lambertian emitter).
    pub fn power(&self) -> f64 {
        let area = match &self.shape {
            AreaShape::Sphere { sphere, .. } => 4.0 * PI * (sphere.radius as f64).powi(2),
            AreaShape::Rectangle(rectangle) => rectangle.area(),
            AreaShape::Quadric { quadric, .. } => quadric.area(),
            AreaShape::Triangles(mesh) => mesh.area(),
        };
        let mean = self
            .texture
            .as_ref()
            .map_or(1.0, |t| t.mean_luminance() as f64);
        PI * super::luminance(self.radiance) as f64 * mean * area
    }

    /// Radiance leaving the light toward `-direction` at `point`, with geometric normal
    /// `normal` (front side only), on triangle `spot` of a mesh light.
    #[inline]
    pub fn emitted(&self, normal: Vec3, direction: Vec3, point: Vec3, spot: LightSpot) -> Vec3 {
        if normal.dot(direction) >= 0.0 {
            return Vec3::ZERO;
        }
        match &self.texture {
            None => self.radiance,
            Some(texture) => self.radiance * texture.eval(self.texcoords(point, spot)),
        }
    }

    /// [`AreaLight::emitted`] where the texture coordinates are known (a camera ray's hit).
    pub fn emitted_at_uv(&self, normal: Vec3, direction: Vec3, uv: Vec2) -> Vec3 {
        if normal.dot(direction) >= 0.0 {
            return Vec3::ZERO;
        }
        match &self.texture {
            None => self.radiance,
            Some(texture) => self.radiance * texture.eval(uv),
        }
    }

    /// The texture coordinates of `point` on the light (on triangle `spot` of a mesh).
    fn texcoords(&self, point: Vec3, spot: LightSpot) -> Vec2 {
        match &self.shape {
            AreaShape::Sphere { sphere, .. } => {
                sphere_texcoords((point - sphere.center).normalize_or(Vec3::Z))
            }
            AreaShape::Rectangle(rectangle) => {
                let offset = point - rectangle.corner;
                let along = |edge: Vec3| offset.dot(edge) / edge.length_squared();
                Vec2::new(along(rectangle.edge_x), along(rectangle.edge_y))
            }
            AreaShape::Quadric { quadric, .. } => quadric.surface_at(point).uv,
            AreaShape::Triangles(mesh) => mesh.texcoords(spot),
        }
    }

    /// A direction toward the light from `point`.
    pub fn sample(&self, point: Vec3, u: [f32; 2]) -> Option<AreaSample> {
        self.sample_for(&Receiver::new(point), u)
    }

    /// [`AreaLight::sample`] for a receiver that keeps what its other queries can reuse.
    #[inline]
    pub fn sample_for(&self, receiver: &Receiver, u: [f32; 2]) -> Option<AreaSample> {
        if self.out_of_reach(receiver) {
            return None;
        }
        self.sample_in_reach(receiver, u)
    }

    /// [`AreaLight::sample_for`] for a receiver the light is known not to lie wholly behind.
    #[inline]
    fn sample_in_reach(&self, receiver: &Receiver, u: [f32; 2]) -> Option<AreaSample> {
        let point = receiver.point;
        match &self.shape {
            AreaShape::Sphere { sphere, flipped } => {
                let cone = SphereView::new(sphere, point)?;
                Some(cone.sample(sphere, *flipped, point, u))
            }
            AreaShape::Rectangle(rectangle) => {
                let (direction, pdf, distance) = receiver
                    .with_rectangle_view(rectangle, |view| Rectangle::sample_view(view, u))?;
                Some(AreaSample::on_rectangle(
                    rectangle, direction, pdf, distance,
                ))
            }
            AreaShape::Quadric { quadric, flipped } => {
                let drawn = quadric.sample(u);
                let offset = drawn.point - point;
                let distance = offset.length();
                let direction = offset / distance;
                let normal = if *flipped {
                    -drawn.normal
                } else {
                    drawn.normal
                };
                let mut sample = AreaSample {
                    direction,
                    pdf: 0.0,
                    distance,
                    normal,
                    spot: LightSpot::default(),
                };
                // Where the direction first meets the light is the point drawn, take it as
                // the ray finds it, as the density of a direction is found (at a grazing
                // silhouette the two differ in f32).
                let first = self.intersect(&Ray::new(point, direction));
                if let Some(hit) = first.filter(|h| (h.distance - distance).abs() < 1e-4 * distance)
                {
                    (sample.distance, sample.normal) = (hit.distance, hit.normal);
                }
                sample.pdf = self.density_at(receiver, direction, sample.distance, sample.normal);
                (sample.pdf.is_finite() && sample.pdf > 0.0).then_some(sample)
            }
            AreaShape::Triangles(mesh) => mesh.sample(point, u),
        }
    }

    /// Whether every draw from `receiver` would fall outside its support: the light lies
    /// wholly behind it.
    #[inline]
    pub(super) fn out_of_reach(&self, receiver: &Receiver) -> bool {
        (receiver.support_side).is_some_and(|side| self.wholly_behind(receiver.point, side))
    }

    /// [`AreaLight::sample_for`] for each of `squares`, the points given to `put` with their
    /// index in `squares` (none where no point is drawn): the draws of a run of candidates,
    /// made so that they overlap. A rectangle's view is read once and its draws worked out
    /// over vector lanes ([`Rectangle::sample_view_run`]); a sphere's view is worked out
    /// once; a mesh's triangles are all picked before any point is drawn
    /// ([`MeshEmitter::sample_run`]). The points are the same to the bit as one draw at a
    /// time.
    #[inline(always)]
    pub(super) fn sample_run(
        &self,
        receiver: &Receiver,
        squares: &[[f32; 2]],
        mut put: impl FnMut(usize, &AreaSample),
    ) {
        if self.out_of_reach(receiver) {
            return;
        }
        let point = receiver.point;
        match &self.shape {
            AreaShape::Rectangle(rectangle) => {
                // The draws made where the view is held, not from a copy of it.
                receiver.with_rectangle_view(rectangle, |view| {
                    Rectangle::sample_view_run(view, squares, |k, direction, pdf, distance| {
                        put(
                            k,
                            &AreaSample::on_rectangle(rectangle, direction, pdf, distance),
                        )
                    })
                });
            }
            AreaShape::Sphere { sphere, flipped } => {
                let Some(cone) = SphereView::new(sphere, point) else {
                    return;
                };
                for (k, &u) in squares.iter().enumerate() {
                    put(k, &cone.sample(sphere, *flipped, point, u));
                }
            }
            AreaShape::Triangles(mesh) => mesh.sample_run(point, squares, put),
            AreaShape::Quadric { .. } => {
                for (k, &u) in squares.iter().enumerate() {
                    if let Some(sample) = self.sample_in_reach(receiver, u) {
                        put(k, &sample);
                    }
                }
            }
        }
    }

    /// The rectangle of a rectangle light.
    #[inline]
    pub(super) fn rectangle(&self) -> Option<&Rectangle> {
        match &self.shape {
            AreaShape::Rectangle(rectangle) => Some(rectangle),
            _ => None,
        }
    }

    /// Whether [`AreaLight::missed_along`] can find misses: the light is a sphere or a mesh.
    pub(super) fn has_misses_in_lanes(&self) -> bool {
        matches!(
            self.shape,
            AreaShape::Sphere { .. } | AreaShape::Triangles(_)
        )
    }

    /// Which of the unbounded rays from `origin` along `directions` surely miss the light,
    /// found over lanes by the first test of its own intersection ([`AreaLight::intersect`]
    /// then finds nothing either): a sphere's chord, a mesh's ball. For other shapes, no
    /// lane.
    #[inline(always)]
    pub(super) fn missed_along<const N: usize>(
        &self,
        origin: Vec3,
        directions: &[Vec3; N],
    ) -> [bool; N] {
        match &self.shape {
            AreaShape::Sphere { sphere, .. } => sphere.missed_along(origin, directions),
            AreaShape::Triangles(mesh) => mesh.missed_along(origin, directions),
            _ => [false; N],
        }
    }

    /// Light sampling's density (solid angle, this light alone) of drawing the point where a
    /// ray from `receiver` along `direction` first meets the light, at `distance` with
    /// geometric normal `normal`.
    #[inline]
    pub fn density_at(
        &self,
        receiver: &Receiver,
        direction: Vec3,
        distance: f32,
        normal: Vec3,
    ) -> f64 {
        match &self.shape {
            AreaShape::Sphere { sphere, .. } => {
                SphereView::new(sphere, receiver.point).map_or(0.0, |cone| cone.density())
            }
            AreaShape::Rectangle(rectangle) => 1.0 / receiver.rectangle_solid_angle(rectangle),
            AreaShape::Quadric { quadric, .. } => {
                let point = receiver.point + direction * distance;
                let cos = normal.dot(direction).abs() as f64;
                quadric.area_density(point) * (distance as f64).powi(2) / cos
            }
            AreaShape::Triangles(mesh) => mesh.density_at(direction, distance, normal),
        }
    }

    /// Density of [`AreaLight::sample`] at `direction` from `point`, in solid angle.
    pub fn pdf(&self, point: Vec3, direction: Vec3) -> f64 {
        self.pdf_for(&Receiver::new(point), direction)
    }

    /// [`AreaLight::pdf`] for a receiver that keeps what its other queries can reuse.
    #[inline]
    pub fn pdf_for(&self, receiver: &Receiver, direction: Vec3) -> f64 {
        let point = receiver.point;
        match &self.shape {
            AreaShape::Sphere { sphere, .. } => {
                let Some(cone) = SphereView::new(sphere, point) else {
                    return 0.0;
                };
                // The support is decided by intersecting the sphere, as radiance is: a cone
                // test in f32 disagrees with it at the rim, and a direction that brings
                // light but has no light density gives a huge weight (seen at 17 radii).
                if self.intersect(&Ray::new(point, direction)).is_some() {
                    cone.density()
                } else {
                    0.0
                }
            }
            AreaShape::Rectangle(rectangle) => {
                if rectangle.intersect(&Ray::new(point, direction)).is_some() {
                    1.0 / receiver.rectangle_solid_angle(rectangle)
                } else {
                    0.0
                }
            }
            AreaShape::Quadric { .. } => {
                let Some(hit) = self.intersect(&Ray::new(point, direction)) else {
                    return 0.0;
                };
                self.density_at(receiver, direction, hit.distance, hit.normal)
            }
            AreaShape::Triangles(mesh) => mesh.pdf(point, direction),
        }
    }

    /// Whether light sampling draws this light through a one-to-one map of the sample
    /// square that [`AreaLight::sample_square_of`] inverts (spheres and rectangles), so that
    /// the square's regions can be weighed ([`super::RegionChoice`]).
    pub fn has_regions(&self) -> bool {
        matches!(
            self.shape,
            AreaShape::Sphere { .. } | AreaShape::Rectangle(_)
        )
    }

    /// The point of the sample square from which [`AreaLight::sample_for`] draws the point
    /// `target` of the light, seen along `direction` from `receiver` (`None` for lights
    /// without regions, or where the receiver sees nothing of the light).
    pub fn sample_square_of(
        &self,
        receiver: &Receiver,
        direction: Vec3,
        target: Vec3,
    ) -> Option<[f32; 2]> {
        match &self.shape {
            AreaShape::Sphere { sphere, .. } => {
                let cone = SphereView::new(sphere, receiver.point)?;
                let direction = direction.as_dvec3();
                let (t, b) = crate::geometry::basis(cone.axis);
                let u0 = (1.0 - direction.dot(cone.axis.as_dvec3())) / (1.0 - cone.cos_max);
                let phi = direction
                    .dot(b.as_dvec3())
                    .atan2(direction.dot(t.as_dvec3()));
                let u1 = phi.rem_euclid(2.0 * PI) / (2.0 * PI);
                Some([u0, u1].map(|c| (c as f32).clamp(0.0, super::ONE_BELOW)))
            }
            AreaShape::Rectangle(rectangle) => {
                let offset = target - receiver.point;
                receiver.with_rectangle_view(rectangle, |view| Rectangle::square_of(view, offset))
            }
            _ => None,
        }
    }

    /// Whether every direction from `point` toward the light makes a cosine below
    /// −[`BEHIND_MARGIN`] with `side`: clearly below the plane, so that no draw's rounding
    /// can bring it above. Only spheres and rectangles are checked (others: false).
    fn wholly_behind(&self, point: Vec3, side: Vec3) -> bool {
        let below = |offset: Vec3| offset.dot(side) < -BEHIND_MARGIN * offset.length();
        match &self.shape {
            AreaShape::Sphere { sphere, .. } => {
                // The sphere's nearest approach to the plane, with the margin on its radius.
                let centre = sphere.center - point;
                centre.dot(side) + sphere.radius < -BEHIND_MARGIN * centre.length()
            }
            AreaShape::Rectangle(r) => {
                let corner = r.corner - point;
                [
                    corner,
                    corner + r.edge_x,
                    corner + r.edge_y,
                    corner + r.edge_x + r.edge_y,
                ]
                .into_iter()
                .all(below)
            }
            AreaShape::Quadric { .. } | AreaShape::Triangles(_) => false,
        }
    }

    /// The nearest point of the light along a ray.
    pub fn intersect(&self, ray: &Ray) -> Option<AreaHit> {
        let (distance, normal) = match &self.shape {
            AreaShape::Sphere { sphere, flipped } => {
                let t = sphere.intersect(ray, ray.t_max)?;
                let n = (ray.at(t) - sphere.center).normalize();
                (t, if *flipped { -n } else { n })
            }
            AreaShape::Rectangle(rectangle) => (rectangle.intersect(ray)?, rectangle.normal),
            AreaShape::Quadric { quadric, flipped } => {
                let t = quadric.intersect(ray, ray.t_max)?;
                let n = quadric.surface_at(ray.at(t)).normal;
                (t, if *flipped { -n } else { n })
            }
            AreaShape::Triangles(mesh) => return mesh.intersect(ray),
        };
        Some(AreaHit {
            distance,
            normal,
            spot: LightSpot::default(),
        })
    }
}
