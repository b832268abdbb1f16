//! The BSDFs evaluate as Mitsuba 3 does. The expected values were printed by Mitsuba 3.9.1
//! (`scalar_rgb`, `bsdf.eval` with the normal +z, `si.wi` the view direction and `wo` the
//! light direction, so that the value includes cos θ of the light), for the parameters
//! given with each case.

use ais_render::bsdf::{Material, Microfacet, RoughPlastic, Scattering, ShadingFrame};
use glam::Vec3;

/// A direction at polar angle `theta` and azimuth `phi` around +z.
fn direction(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// Checks `material` against Mitsuba's values for (view θ, light θ, light φ).
fn check(material: &Material, cases: &[(f32, f32, f32, [f32; 3])], tolerance: f32) {
    let frame = ShadingFrame::new(material, Vec3::Z, Vec3::Z, Vec3::Z);
    for &(view, light, phi, expected) in cases {
        let ours = material.eval(&frame, direction(view, 0.0), direction(light, phi));
        let expected = Vec3::from(expected);
        let error = (ours - expected).abs().max_element() / expected.max_element().max(1e-3);
        assert!(
            error < tolerance,
            "{material:?} at view {view}, light ({light}, {phi}): ours {ours}, Mitsuba {expected}"
        );
    }
}

fn plastic(microfacet: Microfacet, eta: f32, specular: Vec3, nonlinear: bool) -> Material {
    Material {
        scattering: Scattering::RoughPlastic(RoughPlastic::new(
            microfacet,
            eta,
            Vec3::new(0.6, 0.3, 0.1),
            specular,
            nonlinear,
        )),
        two_sided: false,
    }
}

#[test]
fn rough_plastic_matches_mitsuba() {
    // diffuse_reflectance (0.6, 0.3, 0.1), default int_ior / ext_ior (polypropylene / air),
    // default distribution (Beckmann).
    let eta = 1.49 / 1.000277;
    let pi = std::f32::consts::PI;
    check(
        &plastic(Microfacet::beckmann(0.1), eta, Vec3::ONE, false),
        &[
            (0.2, 0.4, 2.5, [0.223102, 0.1370342, 0.07965565]),
            (1.0, 0.3, 1.0, [0.1714216, 0.08571081, 0.02857027]),
            (0.5, 0.5, pi, [0.5253961, 0.4435823, 0.3890398]),
            (1.3, 1.2, 3.0, [0.09804253, 0.07437735, 0.05860056]),
        ],
        5e-3,
    );
    check(
        &plastic(Microfacet::beckmann(0.3), eta, Vec3::ONE, false),
        &[
            (0.2, 0.4, 2.5, [0.1828879, 0.1062107, 0.05509248]),
            (1.0, 0.3, 1.0, [0.152129, 0.07641926, 0.0259461]),
            (0.5, 0.5, pi, [0.1856237, 0.1129101, 0.06443436]),
            (1.3, 1.2, 3.0, [0.4262889, 0.4034235, 0.3881799]),
        ],
        5e-3,
    );
    check(
        &plastic(Microfacet::beckmann(0.6), eta, Vec3::ONE, false),
        &[
            (0.2, 0.4, 2.5, [0.1266956, 0.0676577, 0.0282991]),
            (1.0, 0.3, 1.0, [0.1261571, 0.06767294, 0.02868346]),
            (0.5, 0.5, pi, [0.1212165, 0.06563279, 0.02857701]),
            (1.3, 1.2, 3.0, [0.1457963, 0.1264183, 0.1134997]),
        ],
        5e-3,
    );
    // int_ior 1.9, nonlinear, specular_reflectance (0.5, 0.8, 1.0).
    check(
        &plastic(
            Microfacet::beckmann(0.3),
            1.9 / 1.000277,
            Vec3::new(0.5, 0.8, 1.0),
            true,
        ),
        &[(0.7, 0.4, 2.0, [0.08538904, 0.05300633, 0.04224096])],
        5e-3,
    );
    // distribution ggx, alpha 0.2.
    check(
        &plastic(Microfacet::ggx(0.2), eta, Vec3::ONE, false),
        &[
            (0.2, 0.4, 2.5, [0.1776691, 0.1078361, 0.0612808]),
            (0.5, 0.45, 3.0, [0.2174533, 0.1495268, 0.1042424]),
            (1.2, 1.0, 2.0, [0.07080705, 0.03612352, 0.01300117]),
        ],
        5e-3,
    );
}

#[test]
fn rough_conductor_matches_mitsuba() {
    let conductor = |microfacet: Microfacet, eta: Vec3, k: Vec3| Material {
        scattering: Scattering::RoughConductor {
            microfacet,
            eta,
            k,
            specular: Vec3::ONE,
        },
        two_sided: false,
    };
    let (gold_eta, gold_k) = ais_render::bsdf::named_conductor("Au").unwrap();
    // material Au, alpha 0.3, default distribution (Beckmann).
    check(
        &conductor(Microfacet::beckmann(0.3), gold_eta, gold_k),
        &[
            (0.2, 0.4, 2.5, [0.7360303, 0.610635, 0.2469236]),
            (0.5, 0.45, 3.0, [0.9566739, 0.7935873, 0.3221662]),
        ],
        2e-3,
    );
    // material Au, alpha 0.3, distribution ggx.
    check(
        &conductor(Microfacet::ggx(0.3), gold_eta, gold_k),
        &[
            (0.2, 0.4, 2.5, [0.6185868, 0.5132, 0.2075236]),
            (0.5, 0.45, 3.0, [0.9256062, 0.7678159, 0.311704]),
            (1.2, 1.0, 2.0, [0.04869451, 0.04042657, 0.01722004]),
        ],
        2e-3,
    );
    check(
        // eta (1.2, 0.9, 0.5), k (3, 2.5, 2), alpha 0.15, Beckmann.
        &conductor(
            Microfacet::beckmann(0.15),
            Vec3::new(1.2, 0.9, 0.5),
            Vec3::new(3.0, 2.5, 2.0),
        ),
        &[
            (0.2, 0.4, 2.5, [1.070749, 1.040833, 1.114907]),
            (0.5, 0.45, 3.0, [2.421625, 2.355049, 2.5245]),
        ],
        2e-3,
    );
}
