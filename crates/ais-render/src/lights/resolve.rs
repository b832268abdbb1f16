//! What a direction drawn without the lights (from a BSDF, a guide) meets first among the
//! emitters: the nearest area light along it, else the environment. One direction at a
//! time, or, where the area lights are rectangles, a run's directions together, each
//! light tested against all of them over vector lanes ([`super::Rectangle::distances_along`]);
//! where they are spheres and meshes, the directions that miss them all found over lanes
//! ([`super::AreaLight::missed_along`]). Every way finds the same sources, to the bit.

use super::spherical_rectangle::LANES;
use super::toward::{AreaPoint, Source};
use super::{AreaHit, LightSpot, Lights, Receiver, Toward};
use crate::geometry::Ray;
use glam::Vec3;

/// The nearest area light found along a direction so far: its hit and its index.
type Nearest = Option<(AreaHit, usize)>;

impl Lights {
    /// Finds what `toward` meets first among the emitters, if not known yet.
    pub(super) fn resolve(&self, receiver: &Receiver, toward: &mut Toward) {
        if matches!(toward.source, Source::Unknown) {
            self.write_source_along(receiver, toward.direction, &mut toward.source);
        }
    }

    /// Writes to `out` what `direction` from `receiver` meets first among the emitters
    /// (in place: see [`Lights::write_source_at`]).
    fn write_source_along(&self, receiver: &Receiver, direction: Vec3, out: &mut Source) {
        let ray = Ray::new(receiver.point, direction);
        let nearest = self
            .area
            .iter()
            .enumerate()
            .filter_map(|(index, light)| light.intersect(&ray).map(|hit| (hit, index)))
            .min_by(|a, b| a.0.distance.total_cmp(&b.0.distance));
        self.write_source_at(receiver, direction, nearest, out);
    }

    /// Finds what each candidate of `drawn` (empty slots passed over) meets first among the
    /// emitters, where not known yet, as resolving them one by one would, when the area
    /// lights are all rectangles; when they are all spheres and meshes, only for the
    /// directions that miss them all. The others are left to be resolved when first needed.
    pub fn resolve_run(&self, receiver: &Receiver, drawn: &mut [Option<Toward>]) {
        if !(self.only_rectangles || self.misses_in_lanes) {
            return;
        }
        for run in drawn.chunks_mut(LANES) {
            // Lanes of no unknown direction keep a (harmless) unit one.
            let mut directions = [Vec3::Z; LANES];
            let mut unknown = [false; LANES];
            for (k, toward) in run.iter().enumerate() {
                if let Some(toward) = toward
                    .as_ref()
                    .filter(|t| matches!(t.source, Source::Unknown))
                {
                    (directions[k], unknown[k]) = (toward.direction, true);
                }
            }
            let mut sources = [Source::Unknown; LANES];
            match self.only_rectangles {
                true => self.rectangles_along(receiver, &directions, &unknown, &mut sources),
                false => {
                    let missed = self.all_missed(receiver.point, &directions);
                    for k in (0..LANES).filter(|&k| unknown[k] && missed[k]) {
                        sources[k] = self.past_area_lights();
                    }
                }
            }
            for (toward, source) in run.iter_mut().zip(sources) {
                if let Some(toward) = toward
                    .as_mut()
                    .filter(|_| !matches!(source, Source::Unknown))
                {
                    toward.source = source;
                }
            }
        }
    }

    /// What each of `directions` from `receiver` whose lane is set in `wanted` meets first
    /// among the emitters, written to its lane of `sources`: the sources
    /// [`Lights::write_source_along`] finds one by one, rectangles tested against all the lanes
    /// at once.
    pub(crate) fn sources_along(
        &self,
        receiver: &Receiver,
        directions: &[Vec3; LANES],
        wanted: &[bool; LANES],
        sources: &mut [Source; LANES],
    ) {
        if self.only_rectangles {
            return self.rectangles_along(receiver, directions, wanted, sources);
        }
        let missed = self.all_missed(receiver.point, directions);
        for k in (0..LANES).filter(|&k| wanted[k]) {
            match missed[k] {
                true => sources[k] = self.past_area_lights(),
                false => self.write_source_along(receiver, directions[k], &mut sources[k]),
            }
        }
    }

    /// Which of `directions` from `origin` surely meet no area light: where the lights are
    /// all spheres and meshes, the lanes that miss every one by the first test of its
    /// intersection (so that testing them one by one finds nothing either); else none.
    fn all_missed(&self, origin: Vec3, directions: &[Vec3; LANES]) -> [bool; LANES] {
        let mut missed = [self.misses_in_lanes; LANES];
        if self.misses_in_lanes {
            for light in &self.area {
                let these = light.missed_along(origin, directions);
                missed = std::array::from_fn(|k| missed[k] & these[k]);
            }
        }
        missed
    }

    /// [`Lights::sources_along`] where the area lights are all rectangles.
    fn rectangles_along(
        &self,
        receiver: &Receiver,
        directions: &[Vec3; LANES],
        wanted: &[bool; LANES],
        sources: &mut [Source; LANES],
    ) {
        if !wanted.contains(&true) {
            return;
        }
        let nearest = self.nearest_rectangles(receiver.point, directions);
        for k in (0..LANES).filter(|&k| wanted[k]) {
            self.write_source_at(receiver, directions[k], nearest[k], &mut sources[k]);
        }
    }

    /// The nearest area light (all rectangles) along each of `directions` from `origin`,
    /// each light's distances over the lanes at once. A tie goes to the light first in
    /// order, as in [`Lights::resolve`].
    fn nearest_rectangles(&self, origin: Vec3, directions: &[Vec3; LANES]) -> [Nearest; LANES] {
        let mut nearest: [Nearest; LANES] = [None; LANES];
        for (index, light) in self.area.iter().enumerate() {
            let rectangle = light.rectangle().expect("the area lights are rectangles");
            let distances = rectangle.distances_along(origin, directions);
            for (nearest, &distance) in nearest.iter_mut().zip(&distances) {
                if distance != f32::INFINITY
                    && nearest.is_none_or(|(held, _)| distance < held.distance)
                {
                    let hit = AreaHit {
                        distance,
                        normal: rectangle.normal,
                        spot: LightSpot::default(),
                    };
                    *nearest = Some((hit, index));
                }
            }
        }
        nearest
    }

    /// Writes to `out` the source of `direction` from `receiver` whose nearest area light
    /// is `nearest`. (Written in place, a candidate's source is not copied: returned from a
    /// call, it was written a field at a time and copied whole, and the copy waited for the
    /// writes.)
    fn write_source_at(
        &self,
        receiver: &Receiver,
        direction: Vec3,
        nearest: Nearest,
        out: &mut Source,
    ) {
        *out = match nearest {
            Some((hit, index)) => {
                let light = &self.area[index];
                let density = light.density_at(receiver, direction, hit.distance, hit.normal);
                let target = receiver.point + direction * hit.distance;
                let (factor, region) = self.region_factor(receiver, index, direction, Some(target));
                Source::Area(AreaPoint {
                    light: index,
                    target,
                    radiance: light.emitted(hit.normal, direction, target, hit.spot),
                    density: self.choice_probability(receiver, index) * density * factor,
                    region,
                })
            }
            None => self.past_area_lights(),
        };
    }

    /// What a direction that meets no area light meets: the environment, or nothing.
    /// (Inlined: returned from a call, the source's copy waits for the write of its tag.)
    #[inline(always)]
    fn past_area_lights(&self) -> Source {
        match self.environment {
            Some(_) => Source::Environment,
            None => Source::Dark,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lights::{
        AreaLight, AreaShape, Emitters, MeshEmitter, Rectangle, RegionChoice, REGIONS,
    };
    use ais::rng::Pcg32;
    use ais::sampling::uniform_sphere;

    /// A rectangle light of shape `shape_index`, corner `corner`, edges `x`, `y`.
    fn light(corner: Vec3, x: Vec3, y: Vec3, shape_index: u32) -> AreaLight {
        AreaLight {
            shape: AreaShape::Rectangle(Rectangle::new(corner, x, y, false).expect("orthogonal")),
            radiance: Vec3::splat(1.0 + shape_index as f32),
            texture: None,
            shape_index,
        }
    }

    /// A run's directions resolved together meet what each meets resolved alone, to the
    /// bit: rectangles in front of one another (the nearer first), one of them with its regions weighed, and
    /// directions that meet none (drawn over the whole sphere), with empty slots and known
    /// sources among them.
    #[test]
    fn a_run_resolved_together_meets_what_each_meets_alone() {
        let lights = Lights::new(
            Emitters {
                area: vec![
                    light(Vec3::new(-0.5, -0.5, 1.0), Vec3::X, Vec3::Y, 0),
                    light(Vec3::new(-1.0, -1.0, 2.0), Vec3::X * 2.0, Vec3::Y * 2.0, 1),
                    light(Vec3::new(1.0, -1.0, -1.0), Vec3::Y, Vec3::Z * 2.0, 2),
                ],
                ..Default::default()
            },
            3,
            10.0,
        );
        let weights: [f64; REGIONS] = std::array::from_fn(|r| 0.5 + (r % 3) as f64);
        let regions = [None, RegionChoice::new(&weights), None];
        let mut receiver = Receiver::new(Vec3::new(0.1, 0.05, 0.0));
        receiver.region_choices = &regions;
        let mut rng = Pcg32::new(3, 1);
        let mut met = [0; 4];
        for _ in 0..300 {
            let mut drawn: Vec<Option<Toward>> = (0..LANES + 5)
                .map(|k| match k % 7 {
                    3 => None,
                    5 => lights.sample_toward(&receiver, [rng.next_f32(), rng.next_f32()]),
                    _ => Some(Toward::new(uniform_sphere([
                        rng.next_f32(),
                        rng.next_f32(),
                    ]))),
                })
                .collect();
            let mut alone = drawn.clone();
            lights.resolve_run(&receiver, &mut drawn);
            for (together, alone) in drawn.iter().zip(&mut alone) {
                if let Some(alone) = alone {
                    lights.resolve(&receiver, alone);
                    met[match alone.source {
                        Source::Area(point) => point.light,
                        _ => 3,
                    }] += 1;
                }
                assert_eq!(format!("{together:?}"), format!("{alone:?}"));
            }
        }
        assert!(
            met.iter().all(|&m| m > 100),
            "every light and none are met: {met:?}"
        );
    }

    /// Where the area lights are all spheres and meshes, a run's directions that miss them
    /// all are found together, the others left, and each meets what it meets resolved
    /// alone, to the bit, also found lane by lane ([`Lights::sources_along`]): directions
    /// drawn over the whole sphere, directions that graze a sphere's rim from either side,
    /// and directions close to a mesh's corners.
    #[test]
    fn a_run_among_spheres_and_meshes_meets_what_each_meets_alone() {
        let sphere = |center: Vec3, radius: f32, shape_index: u32| AreaLight {
            shape: AreaShape::Sphere {
                sphere: crate::geometry::Sphere { center, radius },
                flipped: false,
            },
            radiance: Vec3::splat(1.0 + shape_index as f32),
            texture: None,
            shape_index,
        };
        let lights = Lights::new(
            Emitters {
                area: vec![
                    sphere(Vec3::new(0.0, 0.0, 2.0), 0.5, 0),
                    sphere(Vec3::new(3.0, 1.0, 0.0), 1.0, 1),
                    AreaLight {
                        shape: AreaShape::Triangles(Box::new(MeshEmitter::new(
                            tetrahedron(),
                            None,
                        ))),
                        radiance: Vec3::ONE,
                        texture: None,
                        shape_index: 2,
                    },
                ],
                ..Default::default()
            },
            3,
            10.0,
        );
        let receiver = Receiver::new(Vec3::new(0.1, 0.05, 0.0));
        let mut rng = Pcg32::new(5, 2);
        let grazing = |light: &AreaLight, rng: &mut Pcg32| {
            let AreaShape::Sphere { sphere, .. } = light.shape else {
                unreachable!("a sphere")
            };
            let to_center = sphere.center - receiver.point;
            let rim = (sphere.radius / to_center.length()).asin();
            let angle = rim * (1.0 + 2e-4 * (2.0 * rng.next_f32() - 1.0));
            let toward = to_center.normalize();
            let across = glam::Quat::from_axis_angle(toward, 6.3 * rng.next_f32())
                * toward.any_orthonormal_vector();
            (toward * angle.cos() + across * angle.sin()).normalize()
        };
        let corners: Vec<Vec3> = tetrahedron().iter().map(|t| t.vertices[0]).collect();
        let (mut found_together, mut left, mut met) = (0, 0, [0; 4]);
        for round in 0..300 {
            let directions: [Vec3; LANES] = std::array::from_fn(|k| match k % 4 {
                0 => grazing(&lights.area[round % 2], &mut rng),
                1 => {
                    let corner = corners[k / 4 % corners.len()] - receiver.point;
                    let jitter = 0.02 * (uniform_sphere([rng.next_f32(), rng.next_f32()]));
                    (corner.normalize() + jitter).normalize()
                }
                _ => uniform_sphere([rng.next_f32(), rng.next_f32()]),
            });
            let mut drawn: Vec<Option<Toward>> =
                directions.iter().map(|&d| Some(Toward::new(d))).collect();
            lights.resolve_run(&receiver, &mut drawn);
            let wanted = [true; LANES];
            let mut along = [Source::Unknown; LANES];
            lights.sources_along(&receiver, &directions, &wanted, &mut along);
            for (k, together) in drawn.iter_mut().flatten().enumerate() {
                match together.source {
                    Source::Unknown => left += 1,
                    _ => found_together += 1,
                }
                lights.resolve(&receiver, together);
                let mut alone = Source::Unknown;
                lights.write_source_along(&receiver, directions[k], &mut alone);
                assert_eq!(format!("{:?}", together.source), format!("{alone:?}"));
                assert_eq!(format!("{:?}", along[k]), format!("{alone:?}"));
                met[match alone {
                    Source::Area(point) => point.light,
                    _ => 3,
                }] += 1;
            }
        }
        assert!(
            found_together > 1000 && left > 500,
            "misses found together: {found_together}, others left: {left}"
        );
        assert!(
            met.iter().all(|&m| m > 200),
            "each sphere, the mesh and none: {met:?}"
        );
    }

    /// A small tetrahedron's four faces, away from the other lights.
    fn tetrahedron() -> Vec<crate::geometry::Triangle> {
        let corner = |x: f32, y: f32, z: f32| Vec3::new(-2.0, 0.5, -1.0) + 0.3 * Vec3::new(x, y, z);
        let [a, b, c, d] = [
            corner(1.0, 1.0, 1.0),
            corner(1.0, -1.0, -1.0),
            corner(-1.0, 1.0, -1.0),
            corner(-1.0, -1.0, 1.0),
        ];
        [[a, b, c], [b, d, c], [c, d, a], [d, b, a]]
            .into_iter()
            .enumerate()
            .map(|(index, vertices)| crate::geometry::Triangle {
                vertices,
                mesh: 0,
                index: index as u32,
            })
            .collect()
    }
}
