//! Infinite lights: Mitsuba's `envmap` (a lat-long image) and `constant`.
//!
//! Orientation and filtering follow Mitsuba 3 exactly. In the emitter's local frame (+y up)
//! a direction d maps to u = atan2(d.x, −d.z) / 2π and v = acos(d.y) / π, with (u, v) =
//! (0, 0) at the top-left of the image; `to_world` rotates that frame and `scale` multiplies
//! the radiance. Radiance is interpolated bilinearly between texels, whose centres sit at
//! u = (column + ½) / W (periodic in u) and at v = row / (H − 1): the first row is the north
//! pole and the last the south pole ("align corners" in v).
//!
//! Sampling is piecewise constant in solid angle over the cells between four neighbouring
//! texel centres, each weighted by the mean luminance of its corners times its solid angle,
//! so the density is positive wherever the interpolated radiance is. The row and the cell
//! within it are drawn by inversion of their cumulative distributions ([`CdfGrid`]: two
//! binary searches, which keep a gather's stratified numbers stratified over the sky, where
//! alias tables scattered them and cost 24–36% in relMSE), and each cell's density is
//! stored, so that a density and a radiance lookup each cost O(1) whatever the image
//! size. A sample knows its cell and its (u, v), and a [`Toward`] carries them to the
//! density and radiance lookups; a direction from elsewhere (BSDF sampling) is located on the
//! map once. Like Mitsuba's RGB variants, all of it is f32; directions are located with
//! [`fast_trig`], within 4e-7 rad of libm.

use super::Toward;
use super::ONE_BELOW;
use crate::image_io::RgbImage;
use ais::fast_trig;
use ais::sampling::{uniform_sphere, CdfGrid};
use glam::{DMat3, Mat3, Vec3, Vec4};
use std::f32::consts::PI as PI32;
use std::f64::consts::PI;

/// Luminance of linear sRGB / Rec. 709 RGB.
pub fn luminance(rgb: Vec3) -> f32 {
    0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z
}

/// An infinitely distant light around the scene.
#[derive(Clone, Debug)]
pub enum Environment {
    /// The same radiance from every direction.
    Constant(Vec3),
    /// A lat-long image.
    Map(Box<EnvironmentMap>),
}

/// A lat-long environment image with its sampling tables.
#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    /// The image's size in texels.
    width: usize,
    height: usize,
    /// The image's texels (row-major) with a fourth lane, aligned: a texel is one 16-byte
    /// load, and the bilinear lookup's lerps run on all channels at once. The fourth lane
    /// of texel (c, r) holds the sampling density of cell (c, r), in solid angle (0 in the
    /// last row, which starts no cell): a direction's density is read from the cache line
    /// its radiance lookup reads first (the cell's corner is the lookup's first texel).
    texels: Vec<Vec4>,
    to_world: Mat3,
    to_local: Mat3,
    /// The `width × (height − 1)` cells by probability (row-major). Cell (c, r) has texel
    /// centres (c, r) and (c + 1, r + 1) at its corners.
    cells: CdfGrid,
    /// cos θ of each texel row.
    row_cosines: Vec<f32>,
    mean_luminance: f64,
    /// Its cells grouped by map texels, for guided light sampling.
    partitions: super::environment_guide::PartitionCache,
}

/// How many cell points [`EnvironmentMap::towards_at`], or lookups
/// [`EnvironmentMap::look_up_lanes`], works out at once.
pub(crate) const LANES: usize = 16;

/// A point of an environment map's cell: its row and column, and the fractions of its
/// azimuth and cos θ range.
#[derive(Clone, Copy, Debug)]
pub(super) struct CellPoint {
    pub row: usize,
    pub column: usize,
    pub within: [f32; 2],
}

/// Where a direction falls on an environment map: Mitsuba's u, cos θ (v = acos(cos θ) / π,
/// worked out only when the radiance is looked up) and the sampling cell.
#[derive(Clone, Copy, Debug)]
pub struct MapLocation {
    u: f32,
    cos_theta: f32,
    cell: usize,
}

impl MapLocation {
    /// Its sampling cell (row-major).
    #[inline]
    pub(super) fn cell(&self) -> usize {
        self.cell
    }
}

impl EnvironmentMap {
    /// An environment from a (sanitised) image already multiplied by the emitter's `scale`,
    /// and the rotation part of its `to_world`. A one-row image is treated as two equal rows.
    pub fn new(mut image: RgbImage, to_world: DMat3) -> Self {
        if image.height == 1 {
            image.pixels.extend_from_within(..);
            image.height = 2;
        }
        let (width, height) = (image.width, image.height);
        let row_cosines: Vec<f64> = (0..height)
            .map(|row| (PI * row as f64 / (height - 1) as f64).cos())
            .collect();
        let cell_solid_angle =
            |row: usize| 2.0 * PI / width as f64 * (row_cosines[row] - row_cosines[row + 1]);
        let weights = cell_weights(&image, &row_cosines);
        let total: f64 = weights.iter().sum();
        let cell_density = |cell: usize| {
            let Some(&w) = weights.get(cell) else {
                return 0.0; // the last row's texels start no cell
            };
            let probability = if total > 0.0 {
                w / total
            } else {
                1.0 / weights.len() as f64
            };
            (probability / cell_solid_angle(cell / width)) as f32
        };
        EnvironmentMap {
            cells: CdfGrid::new(&weights, width),
            to_local: to_world.inverse().as_mat3(),
            to_world: to_world.as_mat3(),
            width,
            height,
            texels: (image.pixels.iter().enumerate())
                .map(|(texel, &[r, g, b])| Vec4::new(r, g, b, cell_density(texel)))
                .collect(),
            row_cosines: row_cosines.iter().map(|&c| c as f32).collect(),
            mean_luminance: total / (4.0 * PI),
            partitions: Default::default(),
        }
    }

    /// Where `direction` (unit, world space) falls: Mitsuba's u = atan2(x, −z) / 2π ∈ [0, 1)
    /// and v = acos(y) / π ∈ [0, 1] in the emitter's frame, and the sampling cell there.
    // Always inline: once the environment-only shortcut called it too, the compiler kept it
    // out of line, and the general path's lookups waited on it (5% of the open scene).
    #[inline(always)]
    pub(crate) fn locate(&self, direction: Vec3) -> MapLocation {
        let d = self.to_local * direction;
        let u = u_of_azimuth(fast_trig::atan2(d.x, -d.z));
        MapLocation {
            u,
            cos_theta: d.y,
            cell: self.cell_at(u, v_of_polar(fast_trig::acos(d.y))),
        }
    }

    /// The sampling cell at Mitsuba's (u, v).
    #[inline(always)]
    fn cell_at(&self, u: f32, v: f32) -> usize {
        let (width, rows) = (self.width, self.row_cosines.len() - 1);
        // Cells start half a texel after u = 0 (their corners are texel centres).
        let mut x = u * width as f32 - 0.5;
        if x < 0.0 {
            x += width as f32;
        }
        let column = (x as usize).min(width - 1);
        let row = ((v * rows as f32) as usize).min(rows - 1);
        row * width + column
    }

    /// Where each of `directions` falls, or where `known` says (a direction drawn from the
    /// map), and the radiance there: [`EnvironmentMap::locate`] and
    /// [`EnvironmentMap::radiance_at`] for sixteen directions at once, the same numbers to
    /// the bit, in a form that the compiler runs in vector lanes.
    #[inline]
    pub(crate) fn look_up_lanes(
        &self,
        directions: &[Vec3; LANES],
        known: &[Option<MapLocation>; LANES],
    ) -> ([MapLocation; LANES], [Vec3; LANES]) {
        let local = directions.map(|direction| self.to_local * direction);
        let azimuths = fast_trig::atan2_lanes(&local.map(|d| d.x), &local.map(|d| -d.z));
        let mut u = azimuths.map(u_of_azimuth);
        let mut cos_theta = local.map(|d| d.y);
        for (k, known) in known.iter().enumerate() {
            if let Some(location) = known {
                (u[k], cos_theta[k]) = (location.u, location.cos_theta);
            }
        }
        let v = fast_trig::acos_lanes(&cos_theta).map(v_of_polar);
        let locations = std::array::from_fn(|k| MapLocation {
            u: u[k],
            cos_theta: cos_theta[k],
            cell: known[k].map_or_else(|| self.cell_at(u[k], v[k]), |known| known.cell),
        });
        let radiances = std::array::from_fn(|k| self.interpolate_at(u[k], v[k]));
        (locations, radiances)
    }

    /// Bilinear interpolation at a location, in Mitsuba's texel layout.
    #[inline]
    fn interpolate(&self, location: MapLocation) -> Vec3 {
        let v = v_of_polar(fast_trig::acos(location.cos_theta));
        self.interpolate_at(location.u, v)
    }

    /// Bilinear interpolation at Mitsuba's (u, v), in its texel layout.
    #[inline(always)]
    fn interpolate_at(&self, u: f32, v: f32) -> Vec3 {
        let (width, height) = (self.width, self.height);
        let x = u * width as f32 - 0.5;
        let x0 = x.floor();
        let fx = x - x0;
        // x ≥ −½: only the first half texel wraps around to the last column.
        let c0 = if x0 < 0.0 {
            width - 1
        } else {
            (x0 as usize).min(width - 1)
        };
        let c1 = if c0 + 1 == width { 0 } else { c0 + 1 };
        let y = v.clamp(0.0, 1.0) * (height - 1) as f32;
        let r0 = (y as usize).min(height - 2);
        let fy = y - r0 as f32;
        let texel = |c: usize, r: usize| self.texels[r * width + c];
        let top = texel(c0, r0).lerp(texel(c1, r0), fx);
        let bottom = texel(c0, r0 + 1).lerp(texel(c1, r0 + 1), fx);
        top.lerp(bottom, fy).truncate()
    }

    /// A direction drawn from `u`, located: a row of cells, a cell in it, then a point
    /// uniform in φ and cos θ within the cell, so the density is the cell's
    /// ([`EnvironmentMap::density_at`]).
    #[inline]
    pub(crate) fn sample(&self, u: [f32; 2]) -> Toward {
        let (row, column, within) = self.cells.sample_row_column(u);
        self.toward_in_row_column(row, column, within)
    }

    /// The sampling density at a located direction, in solid angle.
    #[inline]
    pub(crate) fn density_at(&self, location: MapLocation) -> f32 {
        self.texels[location.cell].w
    }

    /// The radiance at a located direction.
    #[inline]
    pub(crate) fn radiance_at(&self, location: MapLocation) -> Vec3 {
        self.interpolate(location)
    }

    /// Its cells grouped by the texels of `layout` (built once, then shared).
    pub fn partition(
        &self,
        layout: impl Into<super::GuideLayout>,
    ) -> std::sync::Arc<super::EnvironmentPartition> {
        self.partitions.get(self, layout.into())
    }

    /// The centre of the cell that sampling picks most often (the sun, in a sky).
    pub fn brightest_direction(&self) -> Vec3 {
        let brightest = (0..self.cell_count())
            .max_by(|&a, &b| {
                self.cell_probability(a)
                    .total_cmp(&self.cell_probability(b))
            })
            .unwrap_or(0);
        self.cell_centre(brightest)
    }

    /// Number of sampling cells (`width × (height − 1)`, row-major).
    pub(crate) fn cell_count(&self) -> usize {
        self.width * (self.height - 1)
    }

    /// Probability that sampling picks `cell`.
    pub(crate) fn cell_probability(&self, cell: usize) -> f64 {
        self.cells.probability(cell) as f64
    }

    /// The world direction through the centre of `cell`.
    pub(crate) fn cell_centre(&self, cell: usize) -> Vec3 {
        self.direction_in_cell(cell, [0.5, 0.5])
    }

    /// The direction at fractions (`fx`, `fy`) ∈ [0, 1)² of `cell`'s azimuth and cos θ range:
    /// with uniform fractions, uniform in solid angle over the cell, as sampling draws.
    #[inline]
    pub(crate) fn direction_in_cell(&self, cell: usize, within: [f32; 2]) -> Vec3 {
        self.toward_in_cell(cell, within).direction
    }

    /// [`EnvironmentMap::direction_in_cell`], located: its (u, v) follow from the cell and
    /// the fractions without a second trip through atan2.
    #[inline]
    pub(crate) fn toward_in_cell(&self, cell: usize, within: [f32; 2]) -> Toward {
        let (row, column) = self.row_column(cell);
        self.toward_in_row_column(row, column, within)
    }

    /// The first half of [`EnvironmentMap::sample`]: the row of cells that `u` draws, and
    /// where `u` fell within its bin.
    #[inline]
    pub(super) fn sample_row(&self, u: f32) -> (usize, f32) {
        self.cells.sample_row(u)
    }

    /// The second half: the column of `row` that `u` draws, and where it fell in its bin.
    #[inline]
    pub(super) fn sample_column(&self, row: usize, u: f32) -> (usize, f32) {
        self.cells.sample_column(row, u)
    }

    /// The row and column of `cell` (row-major).
    #[inline]
    pub(super) fn row_column(&self, cell: usize) -> (usize, usize) {
        (cell / self.width, cell % self.width)
    }

    /// [`EnvironmentMap::toward_in_cell`] for the cell at `row` and `column`.
    #[inline]
    pub(super) fn toward_in_row_column(
        &self,
        row: usize,
        column: usize,
        within: [f32; 2],
    ) -> Toward {
        let location = self.location_at(&CellPoint {
            row,
            column,
            within,
        });
        let direction = self.direction_from(location.cos_theta, location.u);
        Toward::from_environment(direction, Some(location))
    }

    /// [`EnvironmentMap::toward_in_row_column`] for each of `points`, given to `put` with
    /// its index: worked out in runs of [`LANES`], the directions over a run's lanes at once.
    pub(super) fn towards_at(&self, points: &[CellPoint], mut put: impl FnMut(usize, Toward)) {
        for (run, points) in points.chunks(LANES).enumerate() {
            // Lanes past the run's points keep (harmless) zeros.
            let mut cos_theta = [0.0; LANES];
            let mut u = [0.0; LANES];
            for (k, point) in points.iter().enumerate() {
                let location = self.location_at(point);
                (cos_theta[k], u[k]) = (location.cos_theta, location.u);
            }
            let directions: [Vec3; LANES] =
                std::array::from_fn(|k| self.direction_from(cos_theta[k], u[k]));
            for (k, point) in points.iter().enumerate() {
                let location = MapLocation {
                    u: u[k],
                    cos_theta: cos_theta[k],
                    cell: point.row * self.width + point.column,
                };
                put(
                    run * LANES + k,
                    Toward::from_environment(directions[k], Some(location)),
                );
            }
        }
    }

    /// Where a cell point falls on the map: its u, cos θ and cell.
    #[inline(always)]
    fn location_at(&self, point: &CellPoint) -> MapLocation {
        let [fx, fy] = point.within;
        let (top, bottom) = (self.row_cosines[point.row], self.row_cosines[point.row + 1]);
        let phi = (point.column as f32 + 0.5 + fx) / self.width as f32;
        MapLocation {
            u: if phi >= 1.0 { phi - 1.0 } else { phi }.min(ONE_BELOW),
            cos_theta: (top + fy * (bottom - top)).clamp(-1.0, 1.0),
            cell: point.row * self.width + point.column,
        }
    }

    /// The world direction at (cos θ, u) of the map. Inline, without a branch, so that a
    /// loop of them runs in lanes.
    #[inline(always)]
    fn direction_from(&self, cos_theta: f32, u: f32) -> Vec3 {
        let [x, y, z] = self.to_world.to_cols_array_2d();
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (sin_phi, cos_phi) = fast_trig::sin_cos(2.0 * PI32 * u);
        let local = [sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta];
        let world = [0, 1, 2].map(|i| x[i] * local[0] + y[i] * local[1] + z[i] * local[2]);
        let length = (world[0] * world[0] + world[1] * world[1] + world[2] * world[2]).sqrt();
        Vec3::from(world) / length
    }
}

/// Mitsuba's u ∈ [0, 1) of an azimuth `angle` = atan2(x, −z) ∈ [−π, π].
#[inline(always)]
fn u_of_azimuth(angle: f32) -> f32 {
    let mut u = angle * (0.5 / PI32);
    if u < 0.0 {
        u += 1.0;
    }
    u.min(ONE_BELOW)
}

/// Mitsuba's v = θ / π of a polar angle θ.
#[inline(always)]
fn v_of_polar(theta: f32) -> f32 {
    theta * (1.0 / PI32)
}

/// Each cell's sampling weight: the mean luminance of its four corner texels times its
/// solid angle, so the density is positive wherever the interpolated radiance is.
fn cell_weights(image: &RgbImage, row_cosines: &[f64]) -> Vec<f64> {
    let (width, height) = (image.width, image.height);
    let texel_luminance = |column: usize, row: usize| {
        luminance(Vec3::from(image.pixels[row * width + column % width])) as f64
    };
    let mut weights = Vec::with_capacity(width * (height - 1));
    for row in 0..height - 1 {
        let cell_solid_angle = 2.0 * PI / width as f64 * (row_cosines[row] - row_cosines[row + 1]);
        for column in 0..width {
            let corners = texel_luminance(column, row)
                + texel_luminance(column + 1, row)
                + texel_luminance(column, row + 1)
                + texel_luminance(column + 1, row + 1);
            weights.push(corners / 4.0 * cell_solid_angle);
        }
    }
    weights
}

impl Environment {
    /// Radiance arriving from `direction` (unit, world space).
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        self.radiance_toward(&mut Toward::new(direction))
    }

    /// [`Environment::radiance`] at a direction that may already be located on the map.
    #[inline]
    pub fn radiance_toward(&self, toward: &mut Toward) -> Vec3 {
        match self {
            Environment::Constant(radiance) => *radiance,
            Environment::Map(map) => map.radiance_at(toward.location(map)),
        }
    }

    /// A direction drawn from `u` and its density in solid angle.
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, f64) {
        let mut toward = self.sample_toward(u);
        let density = self.pdf_toward(&mut toward);
        (toward.direction, density)
    }

    /// A direction drawn from `u`, located on the map.
    #[inline]
    pub fn sample_toward(&self, u: [f32; 2]) -> Toward {
        match self {
            Environment::Constant(_) => Toward::from_environment(uniform_sphere(u), None),
            Environment::Map(map) => map.sample(u),
        }
    }

    /// Density of [`Environment::sample`] at `direction`, in solid angle.
    pub fn pdf(&self, direction: Vec3) -> f64 {
        self.pdf_toward(&mut Toward::new(direction))
    }

    /// [`Environment::pdf`] at a direction that may already be located on the map.
    #[inline]
    pub fn pdf_toward(&self, toward: &mut Toward) -> f64 {
        match self {
            Environment::Constant(_) => 1.0 / (4.0 * PI),
            Environment::Map(map) => map.density_at(toward.location(map)) as f64,
        }
    }

    /// Mean luminance over the sphere of directions.
    pub fn mean_luminance(&self) -> f64 {
        match self {
            Environment::Constant(radiance) => luminance(*radiance) as f64,
            Environment::Map(map) => map.mean_luminance,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ais::rng::Pcg32;

    /// A rotated map of 24 × 12 texels whose radiance varies across it.
    fn map() -> EnvironmentMap {
        let mut image = RgbImage::new(24, 12);
        for (i, pixel) in image.pixels.iter_mut().enumerate() {
            let v = 0.1 + (i / 24) as f32 * 0.3 + (i % 24) as f32 * 0.05;
            *pixel = [v, 0.5 * v, 2.0 - 0.05 * v];
        }
        EnvironmentMap::new(
            image,
            DMat3::from_rotation_x(0.7) * DMat3::from_rotation_y(0.3),
        )
    }

    #[test]
    fn looking_up_in_lanes_gives_the_numbers_of_one_at_a_time() {
        let map = map();
        let mut rng = Pcg32::new(4, 2);
        let mut compared = 0;
        for round in 0..400 {
            let directions: [Vec3; LANES] = std::array::from_fn(|k| match (round + k) % 5 {
                // The poles and the seam (u = 0) of the map's frame, and axes.
                0 => map.to_world * Vec3::Y,
                1 => map.to_world * Vec3::new(0.0, 0.3, -1.0).normalize(),
                2 => Vec3::X,
                _ => Vec3::new(
                    rng.next_f32() - 0.5,
                    rng.next_f32() - 0.5,
                    rng.next_f32() - 0.5,
                )
                .normalize(),
            });
            // Every other lane drawn from the map: its location known.
            let drawn: [Option<Toward>; LANES] = std::array::from_fn(|k| {
                (k % 2 == 0).then(|| map.sample([rng.next_f32(), rng.next_f32()]))
            });
            let directions: [Vec3; LANES] =
                std::array::from_fn(|k| drawn[k].map_or(directions[k], |t| t.direction));
            let known = drawn.map(|toward| toward.and_then(|t| t.map_location()));
            let (locations, radiances) = map.look_up_lanes(&directions, &known);
            for k in 0..LANES {
                let location = known[k].unwrap_or_else(|| map.locate(directions[k]));
                assert_eq!(
                    locations[k].cell, location.cell,
                    "lane {k} of round {round}"
                );
                assert_eq!(locations[k].u.to_bits(), location.u.to_bits());
                let radiance = map.radiance_at(location);
                assert_eq!(
                    radiances[k].to_array().map(f32::to_bits),
                    radiance.to_array().map(f32::to_bits)
                );
                compared += 1;
            }
        }
        assert_eq!(compared, 400 * LANES);
    }
}
