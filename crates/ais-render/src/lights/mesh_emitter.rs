//! An emitting triangle mesh: a triangle chosen in proportion to its area by an alias table,
//! a uniform point on it, and its own BVH so that the density of a direction and the
//! nearest emitting point along a ray cost O(log n) rather than a loop over the triangles.
//!
//! Most rays that ask for the nearest emitting point miss the mesh altogether: a test
//! against a ball around it answers those before the BVH is entered.
//!
//! A direction may cross several triangles of a non-convex mesh. Light sampling reaches
//! each crossing point, and the gather takes the radiance of the nearest one, so the
//! density of a direction is the sum over all its crossings of distance² / (|cos| · area).

use super::area::{AreaHit, LightSpot};
use super::draw::RUN;
use super::AreaSample;
use crate::geometry::{Ray, Triangle};
use ais::sampling::AliasTable;
use glam::{Vec2, Vec3};
use obvhs::cwbvh::CwBvh;
use std::time::Duration;

/// An emitting triangle mesh, in world space.
#[derive(Clone, Debug)]
pub struct MeshEmitter {
    /// World-space triangles, wound so that the emitting side is front, in BVH order.
    triangles: Vec<Triangle>,
    /// Each triangle's unit geometric normal, in BVH order (worked out once: a draw needs
    /// it, and its cross product and square root were a fifth of a draw's time).
    normals: Vec<Vec3>,
    /// Area-proportional choice of a triangle.
    choice: AliasTable,
    /// Total area.
    area: f64,
    bvh: CwBvh,
    /// A ball holding every triangle.
    bounds: Ball,
    /// Each triangle's texture coordinates at its vertices, in BVH order (for a textured
    /// radiance).
    texcoords: Option<Vec<[Vec2; 3]>>,
    /// Where all the triangles lie in one plane: a rectangle in it around them all.
    outline: Option<[Vec3; 4]>,
}

/// A point drawn on an emitting mesh, before its direction from the receiver is known.
#[derive(Clone, Copy, Debug, Default)]
struct MeshSpot {
    /// The point.
    point: Vec3,
    /// Its triangle and barycentric coordinates.
    spot: LightSpot,
}

impl MeshEmitter {
    /// The mesh of `triangles` (at least one), with their texture coordinates if a texture
    /// gives the radiance.
    pub fn new(triangles: Vec<Triangle>, texcoords: Option<Vec<[Vec2; 3]>>) -> Self {
        let bvh = obvhs::cwbvh::builder::build_cwbvh(
            &triangles,
            obvhs::BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let texcoords = texcoords.map(|texcoords| {
            (bvh.primitive_indices.iter())
                .map(|&i| texcoords[i as usize])
                .collect()
        });
        let triangles: Vec<Triangle> = bvh
            .primitive_indices
            .iter()
            .map(|&i| triangles[i as usize])
            .collect();
        let areas: Vec<f64> = triangles
            .iter()
            .map(|t| 0.5 * t.normal().length() as f64)
            .collect();
        MeshEmitter {
            normals: triangles.iter().map(|t| t.normal().normalize()).collect(),
            outline: planar_outline(&triangles),
            bounds: Ball::around(&triangles),
            choice: AliasTable::new(&areas),
            area: areas.iter().sum(),
            triangles,
            bvh,
            texcoords,
        }
    }

    /// The texture coordinates at `spot` (zero without them).
    pub fn texcoords(&self, spot: LightSpot) -> Vec2 {
        let Some(texcoords) = &self.texcoords else {
            return Vec2::ZERO;
        };
        let [a, b, c] = texcoords[spot.triangle as usize];
        let (u, v) = (spot.barycentrics.x, spot.barycentrics.y);
        a * (1.0 - u - v) + b * u + c * v
    }

    /// Where the mesh is flat: the corners, in order, of a rectangle in its plane around all
    /// its triangles.
    pub fn outline(&self) -> Option<[Vec3; 4]> {
        self.outline
    }

    /// Total area.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// A direction from `point` toward a uniformly chosen point of the mesh, with the density
    /// in solid angle of drawing that point ([`MeshEmitter::pdf`] sums it over every
    /// crossing of the direction), its distance and the triangle's normal.
    pub fn sample(&self, point: Vec3, u: [f32; 2]) -> Option<AreaSample> {
        self.toward(point, self.spot_on(self.pick(u[0]), u[1]))
    }

    /// [`MeshEmitter::sample`] for each of `squares` (at most a run of sixteen), the points
    /// given to `put` with their index in `squares`: every triangle picked first, then
    /// every point, then every direction. A draw waits on two lookups, the triangle's alias
    /// bin and then its vertices; made in passes, the run's waits overlap (the directions'
    /// square roots and divisions, made with the points, kept too few of the vertices'
    /// loads in flight).
    #[inline(always)]
    pub fn sample_run(
        &self,
        point: Vec3,
        squares: &[[f32; 2]],
        mut put: impl FnMut(usize, &AreaSample),
    ) {
        let mut picks = [(0, 0.0); RUN];
        for (pick, square) in picks.iter_mut().zip(squares) {
            *pick = self.pick(square[0]);
        }
        let mut spots = [MeshSpot::default(); RUN];
        for ((spot, &pick), square) in spots.iter_mut().zip(&picks).zip(squares) {
            *spot = self.spot_on(pick, square[1]);
        }
        for (k, &spot) in spots[..squares.len()].iter().enumerate() {
            if let Some(sample) = self.toward(point, spot) {
                put(k, &sample);
            }
        }
    }

    /// The first step of [`MeshEmitter::sample`]: a triangle drawn from `u0` by area, and
    /// what is left of `u0`.
    #[inline]
    fn pick(&self, u0: f32) -> (usize, f32) {
        self.choice.sample(u0)
    }

    /// The second step of [`MeshEmitter::sample`]: a point of the triangle `picked` (from
    /// [`MeshEmitter::pick`]) drawn with what was left of its number and `u1`.
    #[inline(always)]
    fn spot_on(&self, picked: (usize, f32), u1: f32) -> MeshSpot {
        let (index, u0) = picked;
        let su = u0.sqrt();
        let (b1, b2) = (1.0 - su, u1 * su);
        let [v0, v1, v2] = self.triangles[index].vertices;
        MeshSpot {
            point: v0 * (1.0 - b1 - b2) + v1 * b1 + v2 * b2,
            spot: LightSpot {
                triangle: index as u32,
                barycentrics: Vec2::new(b1, b2),
            },
        }
    }

    /// The last step of [`MeshEmitter::sample`]: the direction from `point` toward `spot`,
    /// and its density (none where the two coincide, or the triangle is seen edge-on).
    #[inline(always)]
    fn toward(&self, point: Vec3, spot: MeshSpot) -> Option<AreaSample> {
        let offset = spot.point - point;
        let distance_squared = offset.length_squared() as f64;
        if distance_squared == 0.0 {
            return None;
        }
        let direction = offset.normalize();
        let normal = self.normals[spot.spot.triangle as usize];
        let distance = distance_squared.sqrt() as f32;
        let pdf = self.density_at(direction, distance, normal);
        (pdf > 0.0).then_some(AreaSample {
            direction,
            pdf,
            distance,
            normal,
            spot: spot.spot,
        })
    }

    /// The density in solid angle of drawing the point at `distance` along `direction`, on
    /// a triangle of geometric normal `normal`: distance² / (|cos| · area).
    #[inline]
    pub fn density_at(&self, direction: Vec3, distance: f32, normal: Vec3) -> f64 {
        let cosine = normal.dot(direction).abs() as f64;
        if cosine > 0.0 {
            (distance as f64).powi(2) / (cosine * self.area)
        } else {
            0.0
        }
    }

    /// The density of [`MeshEmitter::sample`] toward `direction` from `point`: the sum over
    /// every triangle the direction crosses.
    pub fn pdf(&self, point: Vec3, direction: Vec3) -> f64 {
        let ray = Ray::new(point, direction);
        if self.bounds.missed_by(&ray) {
            return 0.0;
        }
        let mut density = 0.0;
        self.bvh.ray_traverse(
            ray.to_bvh(f32::INFINITY),
            &mut obvhs::ray::RayHit::none(),
            |_, id| {
                if let Some((t, _)) = self.triangles[id].intersect(&ray, f32::INFINITY) {
                    density += self.density_at(direction, t, self.normals[id]);
                }
                // Never shorten the ray: every crossing counts.
                f32::INFINITY
            },
        );
        density
    }

    /// Which of the unbounded rays from `origin` along `directions` surely meet no
    /// triangle: those that [`MeshEmitter::intersect`] turns away at its first test (the
    /// ball around the mesh), worked out by the same steps over all the lanes at once.
    #[inline(always)]
    pub fn missed_along<const N: usize>(&self, origin: Vec3, directions: &[Vec3; N]) -> [bool; N] {
        std::array::from_fn(|k| {
            self.bounds
                .missed_from(origin, directions[k], f32::INFINITY)
        })
    }

    /// The nearest point of the mesh along `ray` (within `ray.t_max`).
    pub fn intersect(&self, ray: &Ray) -> Option<AreaHit> {
        if self.bounds.missed_by(ray) {
            return None;
        }
        let mut hit = obvhs::ray::RayHit::none();
        let mut nearest: Option<(f32, usize, Vec2)> = None;
        self.bvh
            .ray_traverse(ray.to_bvh(ray.t_max), &mut hit, |r, id| {
                match self.triangles[id].intersect(ray, r.tmax) {
                    Some((t, barycentrics)) => {
                        nearest = Some((t, id, barycentrics));
                        t
                    }
                    None => f32::INFINITY,
                }
            });
        nearest.map(|(distance, id, barycentrics)| AreaHit {
            distance,
            normal: self.normals[id],
            spot: LightSpot {
                triangle: id as u32,
                barycentrics,
            },
        })
    }
}

/// A ball around a mesh, a little larger than the vertices reach, so that rounding leaves
/// no crossing of the mesh outside it.
#[derive(Clone, Copy, Debug)]
struct Ball {
    centre: Vec3,
    radius: f32,
}

impl Ball {
    /// The ball centred on `triangles`' bounding box, through their farthest vertex.
    fn around(triangles: &[Triangle]) -> Ball {
        let vertices = || triangles.iter().flat_map(|t| t.vertices);
        let (low, high) = vertices().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        let centre = 0.5 * (low + high);
        let reach = vertices().map(|v| v.distance(centre)).fold(0.0, f32::max);
        Ball {
            centre,
            radius: reach * 1.001 + 1e-6 * centre.abs().max_element(),
        }
    }

    /// Whether `ray` (within its `t_max`) surely meets nothing inside the ball. The
    /// distance from the centre to the ray's line is taken as a vector's length, not as a
    /// difference of squares, which cancels for origins far from the ball.
    #[inline]
    fn missed_by(&self, ray: &Ray) -> bool {
        self.missed_from(ray.origin, ray.direction, ray.t_max)
    }

    /// [`Ball::missed_by`] for the ray from `origin` along `direction` up to `t_max`.
    #[inline(always)]
    fn missed_from(&self, origin: Vec3, direction: Vec3, t_max: f32) -> bool {
        let to_centre = self.centre - origin;
        let along = to_centre.dot(direction);
        let beside = to_centre - along * direction;
        // `|`, not `||`: no branch, so that a run of them can go over vector lanes.
        (beside.length_squared() > self.radius * self.radius)
            | (along < -self.radius)
            | (along - self.radius > t_max)
    }
}

/// The corners of a rectangle around `triangles` in their plane, if they all lie in one
/// (each vertex within a millionth of the mesh's size of the first triangle's plane). The
/// rectangle's sides follow the first triangle's edge that makes it smallest: a quad's
/// outline is the quad itself.
fn planar_outline(triangles: &[Triangle]) -> Option<[Vec3; 4]> {
    let first = triangles.first()?;
    let normal = first.normal().try_normalize()?;
    let origin = first.vertices[0];
    let vertices = || triangles.iter().flat_map(|t| t.vertices);
    let size = vertices()
        .map(|v| (v - origin).abs().max_element())
        .fold(0.0, f32::max);
    if !vertices().all(|v| normal.dot(v - origin).abs() <= 1e-6 * size) {
        return None;
    }
    let [a, b, c] = first.vertices;
    let outlines = [b - a, c - b, a - c].into_iter().filter_map(|edge| {
        let u = edge.try_normalize()?;
        Some(outline_along(
            vertices(),
            origin,
            [u, normal.cross(u)],
            size,
        ))
    });
    outlines.min_by(|p, q| area_of(p).total_cmp(&area_of(q)))
}

/// The rectangle around `vertices` with sides along the unit, orthogonal `axes`, a little
/// wider than they reach so that rounding leaves none outside.
fn outline_along(
    vertices: impl Iterator<Item = Vec3>,
    origin: Vec3,
    axes: [Vec3; 2],
    size: f32,
) -> [Vec3; 4] {
    let [u, v] = axes;
    let (mut low, mut high) = (Vec2::splat(f32::INFINITY), Vec2::splat(-f32::INFINITY));
    for vertex in vertices {
        let along = Vec2::new(u.dot(vertex - origin), v.dot(vertex - origin));
        (low, high) = (low.min(along), high.max(along));
    }
    let (low, high) = (low - 1e-5 * size, high + 1e-5 * size);
    let at = |p: Vec2| origin + u * p.x + v * p.y;
    [
        at(low),
        at(Vec2::new(high.x, low.y)),
        at(high),
        at(Vec2::new(low.x, high.y)),
    ]
}

/// The area of a rectangle of `corners` in order.
fn area_of(corners: &[Vec3; 4]) -> f32 {
    (corners[1] - corners[0]).length() * (corners[3] - corners[0]).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle(vertices: [Vec3; 3]) -> Triangle {
        Triangle {
            vertices,
            mesh: 0,
            index: 0,
        }
    }

    #[test]
    fn a_flat_mesh_has_an_outline_around_its_triangles_and_a_bent_one_none() {
        let [a, b, c, d] = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, z)| Vec3::new(0.25 * x, 1.99, 0.25 * z));
        // The first triangle's first edge a diagonal of the quad: the outline still follows
        // the quad's sides.
        let flat = [triangle([a, c, d]), triangle([a, b, c])];
        let outline = planar_outline(&flat).expect("a flat quad");
        for corner in outline {
            assert!((corner.y - 1.99).abs() < 1e-6, "{corner}");
            assert!((corner.x.abs() - 0.25).abs() < 1e-4 && (corner.z.abs() - 0.25).abs() < 1e-4);
        }
        let bent = [triangle([a, b, c]), triangle([a, c, d + Vec3::Y * 0.01])];
        assert!(planar_outline(&bent).is_none());
    }

    #[test]
    fn the_ball_around_a_mesh_lets_through_every_ray_that_crosses_it() {
        let mut rng = ais::rng::Pcg32::new(7, 0);
        let mut point = |scale: f32| {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 * scale
                - Vec3::splat(scale)
        };
        // A thin, off-centre cluster of triangles.
        let centre = Vec3::new(3.0, -1.0, 0.5);
        let triangles: Vec<Triangle> = (0..40)
            .map(|_| triangle([0; 3].map(|_| centre + point(1.0) * Vec3::new(1.0, 0.1, 0.6))))
            .collect();
        let ball = Ball::around(&triangles);
        let (mut crossing, mut missed) = (0, 0);
        for i in 0..20_000 {
            // Origins from a hundredth to ten thousand times the mesh's size away, aimed
            // at a vertex (grazing), a point of a triangle, or anywhere near.
            let origin = centre + point(10f32.powi(i % 7 - 2));
            let t = &triangles[i as usize % triangles.len()];
            let aim = match i % 3 {
                0 => t.vertices[i as usize % 3],
                1 => (t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3.0,
                _ => centre + point(3.0),
            };
            let Some(direction) = (aim - origin).try_normalize() else {
                continue;
            };
            let ray = Ray::new(origin, direction);
            if triangles
                .iter()
                .any(|t| t.intersect(&ray, f32::INFINITY).is_some())
            {
                crossing += 1;
                assert!(
                    !ball.missed_by(&ray),
                    "ray {i} from {origin} crosses the mesh"
                );
            } else if ball.missed_by(&ray) {
                missed += 1;
            }
        }
        assert!(
            crossing > 5_000 && missed > 2_000,
            "{crossing} crossing, {missed} missed"
        );
    }
}
