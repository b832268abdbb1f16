//! Infinite lights: Mitsuba's `envmap` (a lat-long image) and `constant`.
//!
//! Orientation follows Mitsuba 3: in the emitter's local frame (+y up) a direction d maps to
//! u = atan2(d.x, −d.z) / 2π and v = acos(d.y) / π, with (u, v) = (0, 0) at the top-left of
//! the image; `to_world` rotates that frame and `scale` multiplies the radiance. Radiance is
//! looked up at the nearest texel (Mitsuba filters bilinearly; see the README), and sampling
//! is piecewise constant over texels, weighted by luminance · sin θ.

use crate::distribution::Distribution2D;
use crate::geometry::uniform_sphere;
use crate::image_io::RgbImage;
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
    distribution: Distribution2D,
    mean_luminance: f64,
}

impl EnvironmentMap {
    /// An environment from a (sanitised) image already multiplied by the emitter's `scale`,
    /// and the rotation part of its `to_world`.
    pub fn new(image: RgbImage, to_world: DMat3) -> Self {
        let (width, height) = (image.width, image.height);
        let mut weights = Vec::with_capacity(width * height);
        let mut mean = 0.0;
        for row in 0..height {
            let sin_theta = (PI * (row as f64 + 0.5) / height as f64).sin();
            for column in 0..width {
                let l = luminance(Vec3::from(image.pixels[row * width + column])) as f64;
                weights.push(l * sin_theta);
                mean += l * sin_theta;
            }
        }
        // Mean luminance over the sphere: Σ L sinθ ΔθΔφ / 4π with ΔθΔφ = 2π²/(W H).
        let mean_luminance = mean * 2.0 * PI * PI / (width * height) as f64 / (4.0 * PI);
        EnvironmentMap {
            distribution: Distribution2D::new(&weights, width, height),
            to_local: to_world.inverse(),
            to_world,
            image,
            mean_luminance,
        }
    }

    fn uv(&self, direction: Vec3) -> [f64; 2] {
        let d = self.to_local * direction.as_dvec3();
        let mut u = d.x.atan2(-d.z) / (2.0 * PI);
        if u < 0.0 {
            u += 1.0;
        }
        [u.min(1.0 - f64::EPSILON), d.y.clamp(-1.0, 1.0).acos() / PI]
    }

    fn direction(&self, uv: [f64; 2]) -> (Vec3, f64) {
        let (sin_phi, cos_phi) = (2.0 * PI * uv[0]).sin_cos();
        let (sin_theta, cos_theta) = (PI * uv[1]).sin_cos();
        let local = DVec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta);
        ((self.to_world * local).normalize().as_vec3(), sin_theta)
    }

    fn texel(&self, uv: [f64; 2]) -> Vec3 {
        let column = ((uv[0] * self.image.width as f64) as usize).min(self.image.width - 1);
        let row = ((uv[1] * self.image.height as f64) as usize).min(self.image.height - 1);
        Vec3::from(self.image.pixels[row * self.image.width + column])
    }
}

impl Environment {
    /// Radiance arriving from `direction` (unit, world space).
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        match self {
            Environment::Constant(radiance) => *radiance,
            Environment::Map(map) => map.texel(map.uv(direction)),
        }
    }

    /// A direction drawn from `u` and its density in solid angle.
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, f64) {
        match self {
            Environment::Constant(_) => (uniform_sphere(u), 1.0 / (4.0 * PI)),
            Environment::Map(map) => {
                let (uv, pdf_uv) = map.distribution.sample([u[0] as f64, u[1] as f64]);
                let (direction, sin_theta) = map.direction(uv);
                let pdf = if sin_theta > 0.0 {
                    pdf_uv / (2.0 * PI * PI * sin_theta)
                } else {
                    0.0
                };
                (direction, pdf)
            }
        }
    }

    /// Density of [`Environment::sample`] at `direction`, in solid angle.
    pub fn pdf(&self, direction: Vec3) -> f64 {
        match self {
            Environment::Constant(_) => 1.0 / (4.0 * PI),
            Environment::Map(map) => {
                let uv = map.uv(direction);
                let sin_theta = (PI * uv[1]).sin();
                if sin_theta <= 0.0 {
                    0.0
                } else {
                    map.distribution.pdf(uv) / (2.0 * PI * PI * sin_theta)
                }
            }
        }
    }

    /// The `u` that [`Environment::sample`] maps to `direction` (environment maps only).
    pub fn invert(&self, direction: Vec3) -> Option<[f64; 2]> {
        match self {
            Environment::Constant(_) => None,
            Environment::Map(map) => Some(map.distribution.invert(map.uv(direction))),
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
