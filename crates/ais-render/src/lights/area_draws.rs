//! A run of candidates' draws toward area lights, made together, light by light
//! ([`super::AreaLight::sample_run`]), so that their waits overlap: a rectangle's view (its
//! spherical rectangle as the receiver sees it) read once and its draws worked out over
//! vector lanes, where one draw is a chain of square roots and divisions that waits on
//! itself; a sphere's view worked out once; a mesh's triangles all picked before any point
//! is drawn, where each draw waits on two lookups. The draws come back through a closure
//! rather than as returned values, which the core would copy through memory. The
//! directions, and so the images, are the same to the bit as one draw at a time
//! ([`super::Lights::sample_toward`]).

use super::draw::{HeldDraws, RUN};
use super::{Lights, Receiver, Toward};

/// An area light chosen by light sampling, and what weighs the points drawn from it.
#[derive(Clone, Copy, Debug)]
pub struct AreaChoice {
    /// The light (its index among the scene's area lights).
    pub(super) light: usize,
    /// The probability of choosing it.
    pub(super) probability: f64,
    /// The factor the receiver's weighing of the light's regions puts on the density.
    pub(super) factor: f64,
    /// The region of the sample square the point is drawn from.
    pub(super) region: u8,
}

/// A point of an area light, still to be drawn from a point of its sample square.
#[derive(Clone, Copy, Debug)]
pub struct AreaDraw {
    /// The light and its weighing.
    pub(super) choice: AreaChoice,
    /// The point of the sample square.
    pub(super) square: [f32; 2],
}

/// Area-light draws of a run of candidates, each to be put in its candidate's slot.
#[derive(Debug, Default)]
pub struct AreaDraws {
    /// Each draw (`None` once taken to be made).
    held: HeldDraws<Option<AreaDraw>>,
}

impl AreaDraws {
    /// Adds `draw` (of a [`super::Draw::Area`]) for the candidate in `slot`. At most
    /// sixteen draws (a run) are held.
    pub fn push(&mut self, slot: usize, draw: AreaDraw) {
        self.held.push(slot, Some(draw));
    }

    /// Makes every draw held for `receiver`, light by light, and gives each direction to
    /// `put` with its candidate's slot (none where no point is drawn: a rectangle seen
    /// edge-on, a sphere seen from inside); then holds none.
    pub fn draw(
        &mut self,
        lights: &Lights,
        receiver: &Receiver,
        mut put: impl FnMut(usize, Toward),
    ) {
        let (slots, draws) = self.held.take();
        // Each pass takes the draws of the first light left.
        while let Some(first) = draws.iter().flatten().next() {
            let light = first.choice.light;
            let mut squares = [[0.0; 2]; RUN];
            let mut taken = [(0, first.choice); RUN];
            let mut n = 0;
            for (&slot, held) in slots.iter().zip(draws.iter_mut()) {
                if let Some(draw) = held.take_if(|draw| draw.choice.light == light) {
                    (squares[n], taken[n]) = (draw.square, (slot, draw.choice));
                    n += 1;
                }
            }
            lights.area[light].sample_run(receiver, &squares[..n], |k, sample| {
                let (slot, choice) = taken[k];
                put(slot, lights.area_toward(receiver, choice, sample));
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Quadric, Sphere, Triangle};
    use crate::lights::{
        AreaLight, AreaShape, Draw, Emitters, Rectangle, RegionChoice, Source, REGIONS,
    };
    use ais::rng::Pcg32;
    use glam::{DMat4, DVec3, Vec3};

    /// A rectangle light with corner `corner` and edges `x`, `y`, of shape `shape_index`.
    fn light(corner: Vec3, x: Vec3, y: Vec3, shape_index: u32, radiance: f32) -> AreaLight {
        AreaLight {
            shape: AreaShape::Rectangle(Rectangle::new(corner, x, y, false).expect("orthogonal")),
            radiance: Vec3::splat(radiance),
            texture: None,
            shape_index,
        }
    }

    /// A mesh light of triangles of uneven sizes over the receiver, some facing it and some
    /// facing away.
    fn mesh_light(shape_index: u32) -> AreaLight {
        let triangles = (0..12u32)
            .map(|index| {
                let (x, size) = (index as f32 * 0.3 - 1.8, 0.1 + 0.05 * (index % 5) as f32);
                let v0 = Vec3::new(x, 0.5, 1.5 + 0.1 * (index % 3) as f32);
                let (e1, e2) = (Vec3::X * size, Vec3::new(0.0, size, 0.2 * size));
                let vertices = match index % 4 {
                    0 => [v0, v0 + e2, v0 + e1],
                    _ => [v0, v0 + e1, v0 + e2],
                };
                Triangle {
                    vertices,
                    mesh: 0,
                    index,
                }
            })
            .collect();
        AreaLight::from_triangles(triangles, Vec3::splat(4.0), shape_index)
    }

    /// Runs of draws made together give what one draw at a time gives, to the bit: over
    /// three rectangles (a near one drawn in f32, a small far one drawn in f64, one seen from
    /// behind), a mesh, a sphere and a disk, with the regions of one rectangle weighed, and
    /// with lights behind the receiver's support left undrawn.
    #[test]
    fn draws_made_together_are_the_draws_made_one_at_a_time() {
        let lights = Lights::new(
            Emitters {
                area: vec![
                    light(Vec3::new(-0.5, -0.5, 2.0), Vec3::X, Vec3::Y, 0, 1.0),
                    light(
                        Vec3::new(3.0, 1.0, 300.0),
                        Vec3::X * 0.1,
                        Vec3::Y * 0.2,
                        1,
                        50.0,
                    ),
                    light(Vec3::new(-2.0, 0.0, -1.0), Vec3::Y, Vec3::X, 2, 1.0),
                    mesh_light(3),
                    AreaLight {
                        shape: AreaShape::Sphere {
                            sphere: Sphere {
                                center: Vec3::new(1.0, 1.0, 2.5),
                                radius: 0.4,
                            },
                            flipped: false,
                        },
                        radiance: Vec3::splat(3.0),
                        texture: None,
                        shape_index: 4,
                    },
                    AreaLight {
                        shape: AreaShape::Quadric {
                            quadric: Quadric::disk(DMat4::from_translation(DVec3::new(
                                -1.0, 0.0, 3.0,
                            )))
                            .expect("a disk"),
                            flipped: true,
                        },
                        radiance: Vec3::splat(3.0),
                        texture: None,
                        shape_index: 5,
                    },
                ],
                ..Default::default()
            },
            6,
            10.0,
        );
        let weights: [f64; REGIONS] = std::array::from_fn(|r| 0.2 + (r % 5) as f64);
        let regions = [None, RegionChoice::new(&weights), None, None, None, None];
        let mut rng = Pcg32::new(29, 0);
        for support_side in [None, Some(Vec3::Z)] {
            let mut receiver = Receiver::new(Vec3::new(0.1, -0.2, 0.0));
            (receiver.region_choices, receiver.support_side) = (&regions, support_side);
            let (mut deferred, mut made) = (0, 0);
            let mut per_light = [0; 6];
            for _ in 0..100 {
                let numbers: Vec<[f32; 2]> =
                    (0..RUN).map(|_| [rng.next_f32(), rng.next_f32()]).collect();
                let mut draws = AreaDraws::default();
                for (slot, &u) in numbers.iter().enumerate() {
                    match lights.begin_sample(&receiver, u) {
                        Draw::Area(draw) => draws.push(slot, draw),
                        Draw::Made(toward) => {
                            assert!(toward.is_none(), "only lights behind are not deferred")
                        }
                        Draw::Environment(_) => panic!("no environment"),
                    }
                }
                draws.draw(&lights, &receiver, |slot, toward| {
                    let alone = lights.sample_toward(&receiver, numbers[slot]);
                    assert_eq!(format!("{toward:?}"), format!("{:?}", alone.unwrap()));
                    deferred += 1;
                    if let Source::Area(point) = toward.source {
                        per_light[point.light] += 1;
                    }
                });
                made += numbers
                    .iter()
                    .filter(|&&u| lights.sample_toward(&receiver, u).is_some())
                    .count();
            }
            assert_eq!(
                deferred, made,
                "every direction drawn alone is drawn in the run"
            );
            assert!(deferred > 600, "the draws must be made: {deferred}");
            // (The rectangle seen from behind, light 2, gives no point.)
            assert!(
                [0, 1, 3, 4, 5].iter().all(|&light| per_light[light] > 50),
                "every light's draws must be made: {per_light:?}"
            );
        }
    }
}
