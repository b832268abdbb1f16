//! Analytic scenes: a linear sky, an optional sun, and cap occluders.

use super::cap::Cap;
use glam::DVec3;
use std::f64::consts::PI;

/// A sky of radiance `L(w) = constant + gradient · (direction · w)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// Constant term (must exceed |gradient| so that radiance stays positive).
    pub constant: f64,
    /// Linear term.
    pub gradient: f64,
    /// Unit direction of the gradient.
    pub direction: DVec3,
}

/// A small sun: extra radiance `radiance` inside a cap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Where the sun is.
    pub cap: Cap,
    /// Radiance added inside it.
    pub radiance: f64,
}

/// What blocks the sky.
#[derive(Clone, Debug, PartialEq)]
pub enum Occlusion {
    /// Nothing: an open scene.
    None,
    /// These caps (disjoint, above the horizon) are blocked; the rest is visible.
    Blockers(Vec<Cap>),
    /// Only these caps (disjoint, above the horizon) are visible: an interior lit through windows.
    Windows(Vec<Cap>),
}

/// Why a scene was refused: its integral would not be exact.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneError {
    /// The sky radiance could be zero or negative somewhere.
    NonPositiveSky,
    /// A cap reaches below the horizon.
    CapBelowHorizon(usize),
    /// Two occluder caps overlap.
    OverlappingCaps(usize, usize),
    /// The sun is partly inside an occluder cap.
    SunStraddlesCap(usize),
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SceneError::NonPositiveSky => write!(f, "sky constant must exceed |gradient|"),
            SceneError::CapBelowHorizon(i) => {
                write!(f, "occluder cap {i} reaches below the horizon")
            }
            SceneError::OverlappingCaps(i, j) => write!(f, "occluder caps {i} and {j} overlap"),
            SceneError::SunStraddlesCap(i) => {
                write!(
                    f,
                    "the sun is neither fully inside nor fully outside cap {i}"
                )
            }
        }
    }
}

impl std::error::Error for SceneError {}

/// An analytic gather scene (gather point at the origin, normal +z, diffuse albedo 1).
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    name: String,
    sky: Sky,
    sun: Option<Sun>,
    occlusion: Occlusion,
}

impl Scene {
    /// A scene, checked so that its exact integral is valid.
    pub fn new(
        name: &str,
        sky: Sky,
        sun: Option<Sun>,
        occlusion: Occlusion,
    ) -> Result<Self, SceneError> {
        if sky.constant <= sky.gradient.abs() {
            return Err(SceneError::NonPositiveSky);
        }
        let caps = match &occlusion {
            Occlusion::None => &[][..],
            Occlusion::Blockers(caps) | Occlusion::Windows(caps) => &caps[..],
        };
        for (i, cap) in caps.iter().enumerate() {
            if !cap.is_above_horizon() {
                return Err(SceneError::CapBelowHorizon(i));
            }
            for (j, other) in caps.iter().enumerate().skip(i + 1) {
                if cap.axis_angle(other) < cap.half_angle() + other.half_angle() {
                    return Err(SceneError::OverlappingCaps(i, j));
                }
            }
            if let Some(sun) = &sun {
                let distance = cap.axis_angle(&sun.cap);
                let inside = distance + sun.cap.half_angle() <= cap.half_angle();
                let outside = distance >= cap.half_angle() + sun.cap.half_angle();
                if !inside && !outside {
                    return Err(SceneError::SunStraddlesCap(i));
                }
            }
        }
        if let Some(sun) = &sun {
            if !sun.cap.is_above_horizon() {
                return Err(SceneError::CapBelowHorizon(usize::MAX));
            }
        }
        Ok(Scene {
            name: name.to_string(),
            sky,
            sun,
            occlusion,
        })
    }

    fn default_sky() -> Sky {
        Sky {
            constant: 1.0,
            gradient: 0.6,
            direction: DVec3::new(0.2, 0.3, 1.0).normalize(),
        }
    }

    /// An open scene: sky and sun, nothing blocked.
    pub fn open() -> Self {
        let sun = Sun {
            cap: Cap::at(40f64.to_radians(), 0.8, 3f64.to_radians()),
            radiance: 60.0,
        };
        Scene::new("open", Self::default_sky(), Some(sun), Occlusion::None).expect("valid preset")
    }

    /// An interior lit through one window that shows `visible` of the cosine-weighted
    /// hemisphere (0 < visible ≤ 0.8); the sun shines through the window.
    pub fn window(visible: f64) -> Self {
        let elevation = 60f64.to_radians();
        let half_angle = (visible / elevation.sin()).sqrt().asin();
        let window = Cap::at(elevation, 0.6, half_angle);
        let sun_half_angle = (0.2 * half_angle).min(3f64.to_radians());
        let sun = Sun {
            cap: Cap::at(elevation + 0.4 * half_angle, 0.6, sun_half_angle),
            radiance: 60.0,
        };
        let name = format!("window{:.0}", visible * 100.0);
        Scene::new(
            &name,
            Self::default_sky(),
            Some(sun),
            Occlusion::Windows(vec![window]),
        )
        .expect("valid preset")
    }

    /// A courtyard: walls block three caps low in the sky, one of them hiding the sun; 62.5%
    /// of the cosine-weighted hemisphere stays visible.
    pub fn courtyard() -> Self {
        let walls = vec![
            Cap::at(30f64.to_radians(), 0.0, 30f64.to_radians()),
            Cap::at(30f64.to_radians(), 2.1, 30f64.to_radians()),
            Cap::at(30f64.to_radians(), 4.2, 30f64.to_radians()),
        ];
        let sun = Sun {
            cap: Cap::at(30f64.to_radians(), 0.1, 3f64.to_radians()),
            radiance: 60.0,
        };
        Scene::new(
            "courtyard",
            Self::default_sky(),
            Some(sun),
            Occlusion::Blockers(walls),
        )
        .expect("valid preset")
    }

    /// The scene's name, for tables.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Unoccluded radiance arriving from `direction`.
    pub fn unoccluded_radiance(&self, direction: DVec3) -> f64 {
        let sky = self.sky.constant + self.sky.gradient * self.sky.direction.dot(direction);
        match &self.sun {
            Some(sun) if sun.cap.contains(direction) => sky + sun.radiance,
            _ => sky,
        }
    }

    /// Whether `direction` (above the horizon) reaches the sky.
    pub fn visible(&self, direction: DVec3) -> bool {
        match &self.occlusion {
            Occlusion::None => true,
            Occlusion::Blockers(caps) => !caps.iter().any(|c| c.contains(direction)),
            Occlusion::Windows(caps) => caps.iter().any(|c| c.contains(direction)),
        }
    }

    /// The BSDF factor times cosine, `max(0, w_z) / π` (diffuse, albedo 1).
    pub fn cosine_bsdf(&self, direction: DVec3) -> f64 {
        direction.z.max(0.0) / PI
    }

    /// (1/π) ∫_cap L_sky(w) w_z dω for a cap above the horizon.
    fn sky_over_cap(&self, cap: &Cap) -> f64 {
        let sky = &self.sky;
        (sky.constant * cap.first_moment().z
            + sky.gradient * cap.second_moment(sky.direction, DVec3::Z))
            / PI
    }

    /// The exact integral ∫ L(w) V(w) max(0, w_z) / π dω.
    pub fn exact(&self) -> f64 {
        let sky = &self.sky;
        // Over the hemisphere: ∫ w_z = π and ∫ (d·w) w_z = 2π d_z / 3.
        let hemisphere = sky.constant + sky.gradient * sky.direction.z * 2.0 / 3.0;
        let sky_part = match &self.occlusion {
            Occlusion::None => hemisphere,
            Occlusion::Blockers(caps) => {
                hemisphere - caps.iter().map(|c| self.sky_over_cap(c)).sum::<f64>()
            }
            Occlusion::Windows(caps) => caps.iter().map(|c| self.sky_over_cap(c)).sum(),
        };
        let sun_part = match &self.sun {
            Some(sun) if self.visible(sun.cap.axis()) => sun.radiance * sun.cap.cosine_mass(),
            _ => 0.0,
        };
        sky_part + sun_part
    }

    /// Fraction of the cosine-weighted hemisphere that is visible.
    pub fn visible_cosine_fraction(&self) -> f64 {
        match &self.occlusion {
            Occlusion::None => 1.0,
            Occlusion::Blockers(caps) => 1.0 - caps.iter().map(Cap::cosine_mass).sum::<f64>(),
            Occlusion::Windows(caps) => caps.iter().map(Cap::cosine_mass).sum(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    /// Plain Monte Carlo with uniform hemisphere sampling.
    fn brute_force(scene: &Scene) -> (f64, f64) {
        let mut rng = Pcg32::new(2024, 1);
        let n = 2_000_000;
        let (mut sum, mut sum_sq) = (0.0, 0.0);
        for _ in 0..n {
            let z = rng.next_f64();
            let phi = 2.0 * PI * rng.next_f64();
            let r = (1.0 - z * z).sqrt();
            let w = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let value = if scene.visible(w) {
                scene.unoccluded_radiance(w) * scene.cosine_bsdf(w) * 2.0 * PI
            } else {
                0.0
            };
            sum += value;
            sum_sq += value * value;
        }
        let mean = sum / n as f64;
        let variance = (sum_sq / n as f64 - mean * mean) / n as f64;
        (mean, variance.sqrt())
    }

    #[test]
    fn exact_integrals_agree_with_brute_force() {
        for scene in [
            Scene::open(),
            Scene::window(0.35),
            Scene::window(0.10),
            Scene::courtyard(),
        ] {
            let (mean, standard_error) = brute_force(&scene);
            let z = (mean - scene.exact()) / standard_error;
            assert!(
                z.abs() < 4.0,
                "{}: exact {} vs {mean} ± {standard_error}",
                scene.name(),
                scene.exact()
            );
        }
    }

    #[test]
    fn window_presets_have_the_requested_visible_fraction() {
        assert!((Scene::window(0.35).visible_cosine_fraction() - 0.35).abs() < 1e-9);
        assert!((Scene::window(0.10).visible_cosine_fraction() - 0.10).abs() < 1e-9);
        let courtyard = Scene::courtyard().visible_cosine_fraction();
        assert!((courtyard - 0.625).abs() < 1e-9, "{courtyard}");
    }

    #[test]
    fn invalid_scenes_are_refused() {
        let sky = Scene::default_sky();
        let low = Occlusion::Blockers(vec![Cap::at(0.1, 0.0, 0.3)]);
        assert_eq!(
            Scene::new("x", sky, None, low),
            Err(SceneError::CapBelowHorizon(0))
        );
        let overlapping = Occlusion::Windows(vec![Cap::at(1.0, 0.0, 0.3), Cap::at(1.0, 0.2, 0.3)]);
        assert_eq!(
            Scene::new("x", sky, None, overlapping),
            Err(SceneError::OverlappingCaps(0, 1))
        );
        let bad_sky = Sky {
            gradient: 2.0,
            ..sky
        };
        assert_eq!(
            Scene::new("x", bad_sky, None, Occlusion::None),
            Err(SceneError::NonPositiveSky)
        );
        let sun = Sun {
            cap: Cap::at(1.0, 0.5, 0.1),
            radiance: 1.0,
        };
        let straddled = Occlusion::Blockers(vec![Cap::at(1.0, 0.0, 0.3)]);
        assert_eq!(
            Scene::new("x", sky, Some(sun), straddled),
            Err(SceneError::SunStraddlesCap(0))
        );
    }
}
