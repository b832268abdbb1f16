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
//! so the density is positive wherever the interpolated radiance is.

use crate::image_io::RgbImage;
use ais::sampling::uniform_sphere;
use ais::sampling::Distribution2D;
use glam::{DMat3, DVec3, Vec3};
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

/// A lat-long environment image with its sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    image: RgbImage,
    to_world: DMat3,
    to_local: DMat3,
    /// Over `width × (height − 1)` cells; cell (c, r) has texel centres (c, r) and
    /// (c + 1, r + 1) at its corners.
    distribution: Distribution2D,
    /// cos θ of each texel row.
    row_cosines: Vec<f64>,
    mean_luminance: f64,
    /// Its cells grouped by map texels, for guided light sampling.
    partitions: super::environment_guide::PartitionCache,
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
        let texel_luminance = |column: usize, row: usize| {
            luminance(Vec3::from(image.pixels[row * width + column % width])) as f64
        };
        let mut weights = Vec::with_capacity(width * (height - 1));
        let mut integral = 0.0;
        for row in 0..height - 1 {
            let cell_solid_angle =
                2.0 * PI / width as f64 * (row_cosines[row] - row_cosines[row + 1]);
            for column in 0..width {
                let corners = texel_luminance(column, row)
                    + texel_luminance(column + 1, row)
                    + texel_luminance(column, row + 1)
                    + texel_luminance(column + 1, row + 1);
                weights.push(corners / 4.0 * cell_solid_angle);
                integral += corners / 4.0 * cell_solid_angle;
            }
        }
        EnvironmentMap {
            distribution: Distribution2D::new(&weights, width, height - 1),
            to_local: to_world.inverse(),
            to_world,
            image,
            row_cosines,
            mean_luminance: integral / (4.0 * PI),
            partitions: Default::default(),
        }
    }

    /// Mitsuba's (u, v) of a world direction: u ∈ [0, 1), v ∈ [0, 1].
    fn uv(&self, direction: Vec3) -> [f64; 2] {
        let d = self.to_local * direction.as_dvec3();
        let mut u = d.x.atan2(-d.z) / (2.0 * PI);
        if u < 0.0 {
            u += 1.0;
        }
        [u.min(1.0 - f64::EPSILON), d.y.clamp(-1.0, 1.0).acos() / PI]
    }

    /// Bilinear interpolation at (u, v) in Mitsuba's texel layout.
    fn interpolate(&self, [u, v]: [f64; 2]) -> Vec3 {
        let (width, height) = (self.image.width, self.image.height);
        let x = u * width as f64 - 0.5;
        let x0 = x.floor();
        let fx = (x - x0) as f32;
        let c0 = (x0 as i64).rem_euclid(width as i64) as usize;
        let c1 = (c0 + 1) % width;
        let y = v.clamp(0.0, 1.0) * (height - 1) as f64;
        let r0 = (y.floor() as usize).min(height - 2);
        let fy = (y - r0 as f64) as f32;
        let texel = |c: usize, r: usize| Vec3::from(self.image.pixels[r * width + c]);
        let top = texel(c0, r0).lerp(texel(c1, r0), fx);
        let bottom = texel(c0, r0 + 1).lerp(texel(c1, r0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// The distribution's cell coordinates of (u, v), and the cell row's cos θ span.
    fn cell_coordinates(&self, [u, v]: [f64; 2]) -> ([f64; 2], f64) {
        let (width, rows) = (self.image.width as f64, self.row_cosines.len() - 1);
        let x = (u - 0.5 / width).rem_euclid(1.0);
        let row = ((v * rows as f64) as usize).min(rows - 1);
        let (top, bottom) = (self.row_cosines[row], self.row_cosines[row + 1]);
        let cos_theta = (PI * v).cos();
        let t = ((top - cos_theta) / (top - bottom)).clamp(0.0, 1.0);
        (
            [x.min(1.0 - f64::EPSILON), (row as f64 + t) / rows as f64],
            top - bottom,
        )
    }

    /// A direction drawn from `u` and its density in solid angle.
    pub(crate) fn sample(&self, u: [f64; 2]) -> (Vec3, f64) {
        let ([x, y], pdf_cells) = self.distribution.sample(u);
        let (direction, span) = self.direction_at([x, y]);
        // Cells are uniform in φ and cos θ, so the density is constant within each.
        let rows = self.row_cosines.len() - 1;
        (direction, pdf_cells / (rows as f64 * 2.0 * PI * span))
    }

    /// The world direction at the distribution's cell coordinates (x, y) ∈ [0, 1)², and the
    /// cos θ span of its cell row.
    fn direction_at(&self, [x, y]: [f64; 2]) -> (Vec3, f64) {
        let rows = self.row_cosines.len() - 1;
        let row = ((y * rows as f64) as usize).min(rows - 1);
        let t = y * rows as f64 - row as f64;
        let (top, bottom) = (self.row_cosines[row], self.row_cosines[row + 1]);
        let cos_theta = (top + t * (bottom - top)).clamp(-1.0, 1.0);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * (x + 0.5 / self.image.width as f64)).sin_cos();
        let local = DVec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta);
        ((self.to_world * local).normalize().as_vec3(), top - bottom)
    }

    fn pdf(&self, direction: Vec3) -> f64 {
        self.pdf_and_cell(direction).0
    }

    /// Its cells grouped by the texels of `layout` (built once, then shared).
    pub fn partition(
        &self,
        layout: ais::mapping::LatLong,
    ) -> std::sync::Arc<super::EnvironmentPartition> {
        self.partitions.get(self, layout)
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
        self.image.width * (self.row_cosines.len() - 1)
    }

    /// Probability that sampling picks `cell`.
    pub(crate) fn cell_probability(&self, cell: usize) -> f64 {
        let width = self.image.width;
        self.distribution
            .cell_probability(cell % width, cell / width)
    }

    /// The world direction through the centre of `cell`.
    pub(crate) fn cell_centre(&self, cell: usize) -> Vec3 {
        self.direction_in_cell(cell, [0.5, 0.5])
    }

    /// The direction at fractions (`fx`, `fy`) ∈ [0, 1)² of `cell`'s azimuth and cos θ range:
    /// with uniform fractions, uniform in solid angle over the cell, as sampling draws.
    pub(crate) fn direction_in_cell(&self, cell: usize, [fx, fy]: [f64; 2]) -> Vec3 {
        let (width, rows) = (self.image.width, self.row_cosines.len() - 1);
        let x = ((cell % width) as f64 + fx) / width as f64;
        let y = ((cell / width) as f64 + fy) / rows as f64;
        self.direction_at([x.min(1.0 - f64::EPSILON), y.min(1.0 - f64::EPSILON)])
            .0
    }

    /// The sampling density at `direction` (solid angle) and the cell it falls in.
    pub(crate) fn pdf_and_cell(&self, direction: Vec3) -> (f64, usize) {
        let ([x, y], span) = self.cell_coordinates(self.uv(direction));
        let (width, rows) = (self.image.width, self.row_cosines.len() - 1);
        let column = ((x * width as f64) as usize).min(width - 1);
        let row = ((y * rows as f64) as usize).min(rows - 1);
        let density = self.distribution.pdf([x, y]) / (rows as f64 * 2.0 * PI * span);
        (density, row * width + column)
    }
}

impl Environment {
    /// Radiance arriving from `direction` (unit, world space).
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        match self {
            Environment::Constant(radiance) => *radiance,
            Environment::Map(map) => map.interpolate(map.uv(direction)),
        }
    }

    /// A direction drawn from `u` and its density in solid angle.
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, f64) {
        match self {
            Environment::Constant(_) => (uniform_sphere(u), 1.0 / (4.0 * PI)),
            Environment::Map(map) => map.sample([u[0] as f64, u[1] as f64]),
        }
    }

    /// Density of [`Environment::sample`] at `direction`, in solid angle.
    pub fn pdf(&self, direction: Vec3) -> f64 {
        match self {
            Environment::Constant(_) => 1.0 / (4.0 * PI),
            Environment::Map(map) => map.pdf(direction),
        }
    }

    /// The `u` that [`Environment::sample`] maps to `direction` (environment maps only).
    pub fn invert(&self, direction: Vec3) -> Option<[f64; 2]> {
        match self {
            Environment::Constant(_) => None,
            Environment::Map(map) => {
                let (cell, _) = map.cell_coordinates(map.uv(direction));
                Some(map.distribution.invert(cell))
            }
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
