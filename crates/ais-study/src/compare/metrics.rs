//! Error metrics and image encodings for studies.

use ais_render::image_io::RgbImage;

/// The ε in relMSE's denominator, 0.01: it keeps dark pixels from dominating. (The
/// renderer's race and gather sizes weigh pixels by the same floor.)
pub const RELMSE_EPSILON: f64 = ais_render::integrators::gather::race::RELATIVE_FLOOR;

/// The ε of the relative error with every pixel alike ([`PixelWeight::RelativeAlike`]),
/// 10⁻⁴: small enough that a pixel a tenth as bright as relMSE's floor lets count still
/// counts by its relative error, and black pixels do not divide by zero. (The gather sizes
/// weigh pixels by it too.)
pub const ALIKE_EPSILON: f64 = ais_render::integrators::gather::race::ALIKE_FLOOR;

/// How an error metric weighs a pixel channel's squared error, given the reference's value
/// `r` there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelWeight {
    /// 1 / (r² + ε): relMSE, where every pixel counts by its error relative to its
    /// brightness (and dark pixels do not dominate).
    Relative,
    /// 1 / (r² + 10⁻⁴): every pixel's relative error counts alike, down to pixels a
    /// tenth as bright as relMSE's floor lets count, so that dark pixels are not hidden.
    RelativeAlike,
    /// 1: the plain MSE in radiance, every pixel's absolute error alike (the bright pixels
    /// dominate: emitters and sky seen directly).
    Alike,
}

impl PixelWeight {
    /// The weight of a channel whose reference value is `r`.
    #[inline]
    pub fn of(self, r: f64) -> f64 {
        match self {
            PixelWeight::Relative => 1.0 / (r * r + RELMSE_EPSILON),
            PixelWeight::RelativeAlike => 1.0 / (r * r + ALIKE_EPSILON),
            PixelWeight::Alike => 1.0,
        }
    }
}

/// The mean over pixels and channels of (image − reference)² weighed by `weight`.
pub fn weighted_mse(image: &RgbImage, reference: &RgbImage, weight: PixelWeight) -> f64 {
    let sum: f64 = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| {
            (0..3)
                .map(|c| {
                    let (a, r) = (a[c] as f64, r[c] as f64);
                    (a - r) * (a - r) * weight.of(r)
                })
                .sum::<f64>()
        })
        .sum();
    sum / (3 * image.pixels.len().max(1)) as f64
}

/// Relative MSE of `image` against `reference`: the mean over pixels and channels of
/// (image − reference)² / (reference² + ε), the same definition as `tools/crosscheck.py`.
pub fn rel_mse(image: &RgbImage, reference: &RgbImage) -> f64 {
    weighted_mse(image, reference, PixelWeight::Relative)
}

/// Per-pixel relative error |image − reference| / (reference + 0.01) of the channel mean,
/// as false colour: black (0) through blue, magenta and yellow to white at `saturation`.
pub fn relative_error_colours(
    image: &RgbImage,
    reference: &RgbImage,
    saturation: f32,
) -> Vec<[u8; 3]> {
    image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| {
            let mean = |p: &[f32; 3]| (p[0] + p[1] + p[2]) / 3.0;
            let error = (mean(a) - mean(r)).abs() / (mean(r) + 0.01);
            false_colour((error / saturation).clamp(0.0, 1.0))
        })
        .collect()
}

/// A perceptually ordered ramp over [0, 1]: black, blue, magenta, orange, pale yellow.
fn false_colour(t: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [0.15, 0.1, 0.6],
        [0.7, 0.15, 0.55],
        [0.98, 0.55, 0.15],
        [1.0, 1.0, 0.75],
    ];
    let x = t * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let channel = |c: usize| STOPS[i][c] + f * (STOPS[i + 1][c] - STOPS[i][c]);
    [0, 1, 2].map(|c| (channel(c) * 255.0 + 0.5) as u8)
}

/// Radiance RGBE encoding (4 bytes a pixel): a shared exponent, so a browser can expose
/// and tone-map the HDR image itself.
pub fn rgbe(image: &RgbImage) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(image.pixels.len() * 4);
    for p in &image.pixels {
        let v = p[0].max(p[1]).max(p[2]);
        if v.is_nan() || v <= 1e-32 {
            bytes.extend_from_slice(&[0, 0, 0, 0]);
            continue;
        }
        // v = m · 2^e with m in [0.5, 1).
        let e = v.log2().floor() as i32 + 1;
        let scale = 256.0 / 2f32.powi(e);
        let q = |c: f32| ((c * scale) as i32).clamp(0, 255) as u8;
        bytes.extend_from_slice(&[q(p[0]), q(p[1]), q(p[2]), (e + 128).clamp(0, 255) as u8]);
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: Vec<[f32; 3]>) -> RgbImage {
        RgbImage {
            width: pixels.len(),
            height: 1,
            pixels,
        }
    }

    #[test]
    fn rel_mse_follows_its_definition() {
        let reference = image(vec![[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]);
        let noisy = image(vec![[1.1, 1.0, 1.0], [0.1, 0.0, 0.0]]);
        let expected = (0.01 / 1.01 + 0.01 / 0.01) / 6.0;
        assert!((rel_mse(&noisy, &reference) - expected).abs() < 1e-6);
        assert_eq!(rel_mse(&reference, &reference), 0.0);
        // Weighted alike, the dark pixel's error counts as much as the bright one's.
        let alike = weighted_mse(&noisy, &reference, PixelWeight::Alike);
        assert!((alike - (0.01 + 0.01) / 6.0).abs() < 1e-6);
        // Relative and unfloored, the dark pixel's error counts a hundred times relMSE's.
        let relative = weighted_mse(&noisy, &reference, PixelWeight::RelativeAlike);
        assert!((relative - (0.01 / 1.0001 + 0.01 / 1e-4) / 6.0).abs() < 1e-6);
    }

    #[test]
    fn rgbe_round_trips_within_its_precision() {
        let pixels = vec![[0.25, 3.0, 1000.0], [0.0, 0.0, 0.0], [1e-3, 2e-3, 5e-4]];
        let bytes = rgbe(&image(pixels.clone()));
        for (p, b) in pixels.iter().zip(bytes.chunks(4)) {
            let scale = 2f32.powi(b[3] as i32 - 136);
            for c in 0..3 {
                let decoded = (b[c] as f32 + 0.5) * scale * (b[3] > 0) as u8 as f32;
                assert!(
                    (decoded - p[c]).abs() <= 0.01 * p[0].max(p[1]).max(p[2]) + 1e-30,
                    "{p:?} → {b:?}"
                );
            }
        }
    }
}
