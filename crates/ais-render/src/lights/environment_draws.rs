//! A run of candidates' environment-map draws made together, step by step: every draw's
//! row (or guide texel), then every draw's cell, then every direction.
//!
//! One draw is a chain of dependent table lookups (a guide table, a cumulative table, a
//! division, then the same within the row or texel, then the cell's corners). Made one
//! candidate at a time, with a candidate's other work between two draws, each lookup waits
//! for the one before it. Made step by step over a run, the lookups of different candidates
//! are independent and the core overlaps them. The directions, and so the images, are the
//! same to the bit as one draw at a time ([`super::Lights::sample_toward`]). A constant
//! environment's draws, which look nothing up, are made one at a time here too: held with
//! the run's others, they come back through a closure rather than as returned values,
//! which the core would copy through memory.

use super::draw::{HeldDraws, RUN};
use super::environment::CellPoint;
use super::environment_guide::Pick;
#[cfg(test)]
use super::Draw;
use super::{Environment, EnvironmentGuide, EnvironmentMap, Lights, Receiver, Toward, ONE_BELOW};

/// Where one environment draw stands between steps.
#[derive(Clone, Copy, Debug)]
enum Step {
    /// The environment's own draw: its row found, its column to find from `u`.
    Row { row: usize, fy: f32, u: f32 },
    /// The guide's product: its texel found, its cell to find from `v`.
    Texel { texel: usize, v: f32, w: f32 },
    /// The cell found: its row, column and the fractions within it.
    Cell {
        row: usize,
        column: usize,
        within: [f32; 2],
    },
}

impl Step {
    /// The first step from numbers `[u, w]`: a row of the environment's cells, or a texel
    /// of the guide (when there is one and its mixture picks the product).
    #[inline]
    fn first(map: &EnvironmentMap, guide: Option<&EnvironmentGuide>, [u, w]: [f32; 2]) -> Step {
        let u = match guide.map(|guide| guide.pick(u)) {
            Some(Pick::Texel(texel, v)) => return Step::Texel { texel, v, w },
            Some(Pick::Own(u)) => u,
            None => u,
        };
        let (row, fy) = map.sample_row(w);
        Step::Row { row, fy, u }
    }

    /// The second step: the cell within the row or the texel. (Inlined: returned from a
    /// call, the step went through memory a field at a time and was read back whole, and
    /// the read waited for the writes.)
    #[inline(always)]
    fn second(self, map: &EnvironmentMap, guide: Option<&EnvironmentGuide>) -> Step {
        match self {
            Step::Row { row, fy, u } => {
                let (column, fx) = map.sample_column(row, u);
                Step::Cell {
                    row,
                    column,
                    within: [fx, fy],
                }
            }
            Step::Texel { texel, v, w } => {
                let partition = guide.expect("a texel comes from a guide").partition();
                let (cell, fx) = partition
                    .cell_in_texel(texel, v)
                    .expect("an environment map's guide holds its cells");
                let (row, column) = map.row_column(cell);
                Step::Cell {
                    row,
                    column,
                    within: [fx, w.min(ONE_BELOW)],
                }
            }
            cell => cell,
        }
    }
}

/// Environment draws of a run of candidates, each to be put in its candidate's slot.
#[derive(Debug, Default)]
pub struct EnvironmentDraws {
    /// Each draw's numbers.
    held: HeldDraws<[f32; 2]>,
}

impl EnvironmentDraws {
    /// Adds the draw for the candidate in `slot` from `u` (the numbers of a
    /// [`super::Draw::Environment`]). At most sixteen draws (a run) are held.
    pub fn push(&mut self, slot: usize, u: [f32; 2]) {
        self.held.push(slot, u);
    }

    /// Makes every draw held for `receiver` (by its guide when it has one) and gives each
    /// direction to `put` with its candidate's slot; then holds none.
    pub fn draw(
        &mut self,
        lights: &Lights,
        receiver: &Receiver,
        mut put: impl FnMut(usize, Toward),
    ) {
        let (slots, numbers) = self.held.take();
        let guide = receiver.environment_guide;
        let map = match &lights.environment {
            Some(Environment::Map(map)) if guide.is_none_or(|g| g.partition().holds_cells()) => map,
            Some(environment) => {
                // Nothing to overlap: one draw at a time. (Given as it is drawn: wrapped in
                // an option, it was copied whole before its fields were all written.)
                for (&slot, &u) in slots.iter().zip(numbers.iter()) {
                    put(slot, receiver.sample_environment(environment, u));
                }
                return;
            }
            None => return,
        };
        let mut steps = [Step::Row {
            row: 0,
            fy: 0.0,
            u: 0.0,
        }; RUN];
        let count = numbers.len();
        for (step, &u) in steps.iter_mut().zip(numbers.iter()) {
            *step = Step::first(map, guide, u);
        }
        for step in &mut steps[..count] {
            *step = step.second(map, guide);
        }
        // Last step: the directions, all at once.
        let mut points = [CellPoint {
            row: 0,
            column: 0,
            within: [0.0; 2],
        }; RUN];
        let mut cell_slots = [0; RUN];
        let mut cells = 0;
        for (step, &slot) in steps[..count].iter().zip(slots) {
            if let Step::Cell {
                row,
                column,
                within,
            } = *step
            {
                points[cells] = CellPoint {
                    row,
                    column,
                    within,
                };
                cell_slots[cells] = slot;
                cells += 1;
            }
        }
        map.towards_at(&points[..cells], |k, toward| put(cell_slots[k], toward));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image_io::RgbImage;
    use crate::lights::{Emitters, Lights};
    use crate::lights::{EnvironmentGuide, EnvironmentMap, GuideLayout};
    use ais::rng::Pcg32;
    use glam::{DMat3, Vec3};

    /// A sky with a gradient and a one-texel sun.
    fn sky() -> Environment {
        let (width, height) = (48, 24);
        let mut image = RgbImage::new(width, height);
        for (i, pixel) in image.pixels.iter_mut().enumerate() {
            let v = 0.2 + (i / width) as f32 / height as f32 + 0.01 * (i % width) as f32;
            *pixel = [v, 0.8 * v, 0.6 * v];
        }
        image.pixels[7 * width + 9] = [5_000.0; 3];
        let rotation = DMat3::from_rotation_x(0.4) * DMat3::from_rotation_z(0.2);
        Environment::Map(Box::new(EnvironmentMap::new(image, rotation)))
    }

    /// Runs of draws made together give what one draw at a time gives, to the bit: unguided,
    /// and through a guide's product alone and its mixture (both of its halves).
    #[test]
    fn draws_made_together_are_the_draws_made_one_at_a_time() {
        let lights = Lights::new(
            Emitters {
                environment: Some(sky()),
                ..Default::default()
            },
            0,
            10.0,
        );
        let Some(Environment::Map(map)) = &lights.environment else {
            unreachable!("a map was given")
        };
        let mut guide = EnvironmentGuide::new(map.partition(GuideLayout::Octahedral(8)));
        guide.set_affinities(|t| 0.01 + ((t * 5) % 7) as f32);
        let mut rng = Pcg32::new(17, 0);
        for fraction in [None, Some(1.0), Some(0.5)] {
            let receiver = match fraction {
                Some(fraction) => {
                    guide.set_fraction(fraction);
                    Receiver::guided(Vec3::ZERO, &guide)
                }
                None => Receiver::new(Vec3::ZERO),
            };
            for _ in 0..200 {
                let numbers: Vec<[f32; 2]> =
                    (0..RUN).map(|_| [rng.next_f32(), rng.next_f32()]).collect();
                let mut draws = EnvironmentDraws::default();
                for (slot, &u) in numbers.iter().enumerate() {
                    let Draw::Environment(u) = lights.begin_sample(&receiver, u) else {
                        panic!("only the environment is lit")
                    };
                    draws.push(slot, u);
                }
                let mut made = 0;
                draws.draw(&lights, &receiver, |slot, toward| {
                    let alone = lights.sample_toward(&receiver, numbers[slot]);
                    assert_eq!(format!("{toward:?}"), format!("{:?}", alone.unwrap()));
                    made += 1;
                });
                assert_eq!(made, RUN);
            }
        }
    }
}
