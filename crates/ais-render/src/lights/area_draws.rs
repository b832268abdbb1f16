//! A run of candidates' draws toward rectangle lights and emitting meshes, made together,
//! light by light. A rectangle's view (its spherical rectangle as the receiver sees it) is
//! read once, then its draws are worked out over vector lanes
//! ([`Rectangle::sample_view_run`]): one draw is a chain of square roots and divisions that
//! waits on itself, and over lanes sixteen such chains run at once. A mesh's triangles are
//! all picked first, then its points drawn: each draw waits on two lookups (the triangle's
//! alias bin, then its vertices), and made one after another those waits overlap. The
//! directions, and so the images, are the same to the bit as one draw at a time
//! ([`super::Lights::sample_toward`]).

use super::area::AreaSample;
use super::draw::{HeldDraws, RUN};
use super::mesh_emitter::MeshEmitter;
use super::{Lights, Receiver, Rectangle, Toward};

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

/// A point of a rectangle light or an emitting mesh, still to be drawn from a point of its
/// sample square.
#[derive(Clone, Copy, Debug)]
pub struct AreaDraw {
    /// The light and its weighing.
    pub(super) choice: AreaChoice,
    /// The point of the sample square.
    pub(super) square: [f32; 2],
}

/// Rectangle-light and mesh-light draws of a run of candidates, each to be put in its
/// candidate's slot.
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
    /// `put` with its candidate's slot (none where the light is seen edge-on); then holds
    /// none.
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
            let squares = &squares[..n];
            let mut put_sample = |k: usize, sample: &AreaSample| {
                let (slot, choice) = taken[k];
                put(slot, lights.area_toward(receiver, choice, sample));
            };
            match (lights.area[light].mesh(), lights.area[light].rectangle()) {
                (Some(mesh), _) => draw_on_mesh(mesh, receiver, squares, put_sample),
                (_, Some(rectangle)) => {
                    let Some(view) = receiver.with_rectangle_view(rectangle, |view| *view) else {
                        continue;
                    };
                    Rectangle::sample_view_run(&view, squares, |k, direction, pdf, distance| {
                        put_sample(
                            k,
                            &AreaSample::on_rectangle(rectangle, direction, pdf, distance),
                        )
                    });
                }
                _ => unreachable!("only rectangles' and meshes' draws are held"),
            }
        }
    }
}

/// The points of `mesh` drawn from `squares` for `receiver`, each given to `put` with its
/// index in `squares` (none where the point drawn brings no density): every triangle
/// picked first, then every point.
#[inline(always)]
fn draw_on_mesh(
    mesh: &MeshEmitter,
    receiver: &Receiver,
    squares: &[[f32; 2]],
    mut put: impl FnMut(usize, &AreaSample),
) {
    let mut picks = [(0, 0.0); RUN];
    for (pick, square) in picks.iter_mut().zip(squares) {
        *pick = mesh.pick(square[0]);
    }
    for (k, (&pick, square)) in picks.iter().zip(squares).enumerate() {
        if let Some(sample) = mesh.sample_on(receiver.point, pick, square[1]) {
            put(k, &sample);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Triangle;
    use crate::lights::{AreaLight, AreaShape, Draw, Emitters, RegionChoice, Source, REGIONS};
    use ais::rng::Pcg32;
    use glam::Vec3;

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
    /// behind) and a mesh, with the regions of one rectangle weighed, and with lights behind
    /// the receiver's support left undrawn.
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
                ],
                ..Default::default()
            },
            4,
            10.0,
        );
        let weights: [f64; REGIONS] = std::array::from_fn(|r| 0.2 + (r % 5) as f64);
        let regions = [None, RegionChoice::new(&weights), None, None];
        let mut rng = Pcg32::new(29, 0);
        for support_side in [None, Some(Vec3::Z)] {
            let mut receiver = Receiver::new(Vec3::new(0.1, -0.2, 0.0));
            (receiver.region_choices, receiver.support_side) = (&regions, support_side);
            let (mut deferred, mut made, mut on_mesh) = (0, 0, 0);
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
                    on_mesh += matches!(toward.source, Source::Area(p) if p.light == 3) as usize;
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
            assert!(on_mesh > 100, "the mesh's draws must be made: {on_mesh}");
        }
    }
}
