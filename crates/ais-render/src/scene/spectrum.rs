//! Spectra as Mitsuba 3's RGB variants read them: a `<spectrum>` of one value, of
//! wavelength:value pairs, or from a `.spd` file, turned into linear sRGB by integrating it
//! against the CIE 1931 colour matching functions.
//!
//! How a spectrum becomes a colour depends on what it describes ([`ColourRole`]):
//! - a reflectance is seen under D65 (sRGB's white) and clipped to [0, 1];
//! - an emitter's spectrum is integrated alone, and only negative channels are clipped;
//! - other unbounded quantities (an index of refraction) are seen under D65 and only
//!   negative channels are clipped.
//!
//! A uniform spectrum is that value in every channel, except for an emitter: a flat
//! emission spectrum is not white in sRGB (whose white is D65), so it becomes the value
//! times the sRGB colour of the equal-energy spectrum, as Mitsuba's RGB variants do, so
//! that they match its spectral variants.

use super::cie1931::{D65, FIRST, LAST, SAMPLES, STEP, XYZ, XYZ_TO_LINEAR_SRGB};
use std::path::Path;

/// Mitsuba's scale of D65 in its RGB conversion: D65 / 98.9974, under which a perfect white
/// reflector has Y ≈ 0.999.
const D65_SCALE: f64 = 1.0 / 98.997_422_8;

/// Integration steps over [`FIRST`, `LAST`] (Mitsuba's midpoint-free rule: `STEPS` points
/// from the first to the last wavelength inclusive, each weighing the range / `STEPS`).
const STEPS: usize = 1000;

/// What a spectrum describes, which decides how it becomes a colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColourRole {
    /// A reflectance or another quantity in [0, 1]: seen under D65, clipped to [0, 1].
    Reflectance,
    /// A non-emitted quantity without an upper bound (an index of refraction): seen under
    /// D65, negative channels clipped.
    Unbounded,
    /// Emitted radiance, intensity or irradiance: integrated alone, negative channels
    /// clipped.
    Emission,
}

/// A `<spectrum>` property.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Uniform(f64),
    /// Values at increasing wavelengths (nm), linearly interpolated, zero outside.
    Sampled(SampledSpectrum),
}

impl Spectrum {
    /// The spectrum as linear sRGB, for a property of `role`.
    pub fn to_rgb(&self, role: ColourRole) -> [f64; 3] {
        match (self, role) {
            (Spectrum::Uniform(value), ColourRole::Emission) => {
                multiply(&XYZ_TO_LINEAR_SRGB, [1.0; 3]).map(|c| c * value)
            }
            (Spectrum::Uniform(value), _) => [*value; 3],
            (Spectrum::Sampled(sampled), role) => sampled.to_rgb(role),
        }
    }
}

/// Values given at increasing wavelengths.
#[derive(Clone, Debug, PartialEq)]
pub struct SampledSpectrum {
    wavelengths: Vec<f64>,
    values: Vec<f64>,
}

impl SampledSpectrum {
    /// The spectrum of these (wavelength, value) pairs: at least two, finite, at strictly
    /// increasing wavelengths.
    pub fn new(pairs: Vec<(f64, f64)>) -> Result<Self, String> {
        if pairs.len() < 2 {
            return Err("a spectrum needs at least two wavelength:value pairs".into());
        }
        if let Some((w, v)) = pairs.iter().find(|(w, v)| !w.is_finite() || !v.is_finite()) {
            return Err(format!("the pair {w}:{v} is not finite"));
        }
        if let Some(pair) = pairs.windows(2).find(|pair| pair[1].0 <= pair[0].0) {
            return Err(format!(
                "wavelengths must increase, but {} follows {}",
                pair[1].0, pair[0].0
            ));
        }
        let (wavelengths, values) = pairs.into_iter().unzip();
        Ok(SampledSpectrum {
            wavelengths,
            values,
        })
    }

    /// Parses `"400:0.1, 500:0.2, …"` (pairs separated by commas or white space).
    pub fn parse_pairs(text: &str) -> Result<Self, String> {
        let pairs = text
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|token| !token.is_empty())
            .map(|token| {
                let (w, v) = token
                    .split_once(':')
                    .ok_or_else(|| format!("\"{token}\" is not a wavelength:value pair"))?;
                let number = |s: &str| {
                    s.trim()
                        .parse::<f64>()
                        .map_err(|_| format!("\"{s}\" in \"{token}\" is not a number"))
                };
                Ok((number(w)?, number(v)?))
            })
            .collect::<Result<Vec<_>, String>>()?;
        SampledSpectrum::new(pairs)
    }

    /// Reads a `.spd` file: one "wavelength value" pair per line; lines starting with `#`
    /// and empty lines are skipped. Errors name the file and line.
    pub fn read_file(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read the spectrum file {}: {e}", path.display()))?;
        let mut pairs = Vec::new();
        for (index, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let numbers: Vec<Option<f64>> = line
                .split_whitespace()
                .take(2)
                .map(|s| s.parse().ok())
                .collect();
            match numbers.as_slice() {
                [Some(w), Some(v)] => pairs.push((*w, *v)),
                _ => {
                    return Err(format!(
                        "{}:{}: expected \"wavelength value\", got \"{line}\"",
                        path.display(),
                        index + 1
                    ))
                }
            }
        }
        SampledSpectrum::new(pairs).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// The value at `wavelength`, linearly interpolated (`None` outside the given range).
    fn at(&self, wavelength: f64) -> Option<f64> {
        let (first, last) = (self.wavelengths[0], *self.wavelengths.last()?);
        if !(first..=last).contains(&wavelength) {
            return None;
        }
        let upper = self
            .wavelengths
            .partition_point(|&w| w <= wavelength)
            .clamp(1, self.wavelengths.len() - 1);
        let (w0, w1) = (self.wavelengths[upper - 1], self.wavelengths[upper]);
        let (v0, v1) = (self.values[upper - 1], self.values[upper]);
        Some(v0 + (v1 - v0) * (wavelength - w0) / (w1 - w0))
    }

    /// Linear sRGB for a property of `role` (see the module's doc).
    fn to_rgb(&self, role: ColourRole) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for wavelength in integration_points() {
            let Some(value) = self.at(wavelength) else {
                continue;
            };
            let seen_under = match role {
                ColourRole::Emission => 1.0,
                _ => table_at(wavelength, |i| D65[i]) * D65_SCALE,
            };
            for (axis, sum) in xyz.iter_mut().enumerate() {
                *sum += table_at(wavelength, |i| XYZ[i][axis]) * value * seen_under;
            }
        }
        let normalisation = integration_points()
            .map(|w| table_at(w, |i| XYZ[i][1]))
            .sum::<f64>();
        let rgb = multiply(&XYZ_TO_LINEAR_SRGB, xyz.map(|c| c / normalisation));
        match role {
            ColourRole::Reflectance => rgb.map(|c| c.clamp(0.0, 1.0)),
            _ => rgb.map(|c| c.max(0.0)),
        }
    }
}

/// The wavelengths the conversion integrates over.
fn integration_points() -> impl Iterator<Item = f64> {
    (0..STEPS).map(|i| FIRST + (LAST - FIRST) * i as f64 / (STEPS - 1) as f64)
}

/// A table's value at `wavelength` in [`FIRST`, `LAST`], linearly interpolated.
fn table_at(wavelength: f64, entry: impl Fn(usize) -> f64) -> f64 {
    let position = ((wavelength - FIRST) / STEP).clamp(0.0, (SAMPLES - 1) as f64);
    let index = (position as usize).min(SAMPLES - 2);
    let t = position - index as f64;
    entry(index) * (1.0 - t) + entry(index + 1) * t
}

fn multiply(matrix: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    matrix.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampled(text: &str) -> Spectrum {
        Spectrum::Sampled(SampledSpectrum::parse_pairs(text).unwrap())
    }

    fn assert_close(actual: [f64; 3], expected: [f64; 3]) {
        for (a, e) in actual.iter().zip(expected) {
            assert!(
                (a - e).abs() <= 5e-6 * e.abs() + 1e-6,
                "{actual:?} != {expected:?}"
            );
        }
    }

    /// Expected colours are Mitsuba 3.9.1's `spectrum_list_to_srgb` on the same spectra
    /// (scalar_rgb), the conversion its XML reader applies in RGB variants.
    #[test]
    fn spectra_become_the_colours_mitsuba_gives_them() {
        let flat = sampled("400:0.5, 700:0.5");
        assert_close(
            flat.to_rgb(ColourRole::Reflectance),
            [0.497671, 0.499878, 0.497455],
        );
        assert_close(
            flat.to_rgb(ColourRole::Emission),
            [0.599846, 0.474761, 0.451722],
        );
        let white_paint = sampled("400:0.343, 500:0.747, 600:0.74, 700:0.737");
        assert_close(
            white_paint.to_rgb(ColourRole::Reflectance),
            [0.722754, 0.759588, 0.535498],
        );
        let light = sampled("400:0, 500:8, 600:15.6, 700:18.4");
        assert_close(
            light.to_rgb(ColourRole::Emission),
            [20.7108, 10.8546, 2.77115],
        );
        assert_close(
            light.to_rgb(ColourRole::Unbounded),
            [17.7147, 11.3544, 3.30451],
        );
        assert_close(
            Spectrum::Uniform(1.0).to_rgb(ColourRole::Emission),
            [1.204794, 0.948291, 0.908916],
        );
        assert_eq!(
            Spectrum::Uniform(0.3).to_rgb(ColourRole::Reflectance),
            [0.3; 3]
        );
    }

    #[test]
    fn reflectances_are_clipped_to_one_and_emission_is_not() {
        let bright = sampled("400:0.2, 700:2");
        let reflectance = bright.to_rgb(ColourRole::Reflectance);
        assert_eq!(reflectance[0], 1.0);
        assert!(bright.to_rgb(ColourRole::Emission)[0] > 1.5);
    }

    #[test]
    fn malformed_spectra_are_refused_with_the_reason() {
        let refused = |text: &str| SampledSpectrum::parse_pairs(text).unwrap_err();
        assert!(refused("400:0.5").contains("at least two"));
        assert!(refused("500:0.5, 400:0.5").contains("must increase"));
        assert!(refused("400:0.5, 500:x").contains("not a number"));
        assert!(refused("400:0.5, 500").contains("not a wavelength:value pair"));
        assert!(refused("400:0.5, 500:NaN").contains("not finite"));
    }

    #[test]
    fn spectrum_files_are_read_and_their_errors_name_the_line() {
        let folder = std::env::temp_dir().join(format!("ais-spd-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let good = folder.join("good.spd");
        std::fs::write(&good, "# a comment\n400 0.5\n\n700 0.5\n").unwrap();
        let read = SampledSpectrum::read_file(&good).unwrap();
        assert_eq!(
            read,
            SampledSpectrum::parse_pairs("400:0.5, 700:0.5").unwrap()
        );
        let bad = folder.join("bad.spd");
        std::fs::write(&bad, "400 0.5\n500 oops\n").unwrap();
        let message = SampledSpectrum::read_file(&bad).unwrap_err();
        assert!(message.contains("bad.spd:2"), "{message}");
        let missing = SampledSpectrum::read_file(&folder.join("missing.spd")).unwrap_err();
        assert!(missing.contains("missing.spd"), "{missing}");
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
