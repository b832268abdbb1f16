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

#[test]
fn principled_matches_mitsuba() {
    use ais_render::bsdf::{eta_from_specular, Principled};
    use std::f32::consts::PI;
    let material = |principled: Principled| Material {
        scattering: Scattering::Principled(principled),
        two_sided: false,
    };
    // base_color (0.6, 0.3, 0.1), every other parameter at its default.
    check(
        &material(Principled {
            base_color: Vec3::new(0.6, 0.3, 0.1),
            ..Principled::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.2079291, 0.1199741, 0.06133749]),
            (1.0, 0.3, 1.0, [0.1863843, 0.09454717, 0.03332245]),
            (0.5, 0.5, PI, [0.2268922, 0.143088, 0.08721849]),
            (1.3, 1.2, 3.0, [0.3053569, 0.2749685, 0.2547096]),
            (0.3, 2.5, 0.7, [0.0, 0.0, 0.0]),
            (2.6, 0.8, 1.9, [0.0, 0.0, 0.0]),
            (2.7, 2.2, 2.8, [0.0, 0.0, 0.0]),
            (0.3, 2.9, PI, [0.0, 0.0, 0.0]),
            (0.6, 2.6, PI, [0.0, 0.0, 0.0]),
            (2.8, 0.4, PI, [0.0, 0.0, 0.0]),
        ],
        5e-3,
    );
    // base_color (0.6, 0.3, 0.1), metallic 0.3, specular 0.6, roughness 0.35, spec_tint 0.4, sheen 0.5, sheen_tint 0.3, clearcoat 0.7, clearcoat_gloss 0.4.
    check(
        &material(Principled {
            base_color: Vec3::new(0.6, 0.3, 0.1),
            metallic: 0.3,
            eta: eta_from_specular(0.6),
            roughness: 0.35,
            spec_tint: 0.4,
            sheen: 0.5,
            sheen_tint: 0.3,
            clearcoat: 0.7,
            clearcoat_gloss: 0.4,
            ..Principled::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.3897991, 0.2145333, 0.09768954]),
            (1.0, 0.3, 1.0, [0.1334726, 0.06749994, 0.02351815]),
            (0.5, 0.5, PI, [1.561071, 0.8902137, 0.4429757]),
            (1.3, 1.2, 3.0, [0.4682387, 0.3416775, 0.2573034]),
            (0.3, 2.5, 0.7, [0.0, 0.0, 0.0]),
            (2.6, 0.8, 1.9, [0.0, 0.0, 0.0]),
            (2.7, 2.2, 2.8, [0.0, 0.0, 0.0]),
            (0.3, 2.9, PI, [0.0, 0.0, 0.0]),
            (0.6, 2.6, PI, [0.0, 0.0, 0.0]),
            (2.8, 0.4, PI, [0.0, 0.0, 0.0]),
        ],
        5e-3,
    );
    // base_color (0.2, 0.5, 0.8), anisotropic 0.6, roughness 0.4, metallic 0.8.
    check(
        &material(Principled {
            base_color: Vec3::new(0.2, 0.5, 0.8),
            anisotropic: 0.6,
            roughness: 0.4,
            metallic: 0.8,
            ..Principled::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.1124692, 0.2739572, 0.4354452]),
            (1.0, 0.3, 1.0, [0.02789464, 0.06859773, 0.1093008]),
            (0.5, 0.5, PI, [0.6022916, 1.462149, 2.322005]),
            (1.3, 1.2, 3.0, [0.1328498, 0.2306232, 0.3283966]),
            (0.3, 2.5, 0.7, [0.0, 0.0, 0.0]),
            (2.6, 0.8, 1.9, [0.0, 0.0, 0.0]),
            (2.7, 2.2, 2.8, [0.0, 0.0, 0.0]),
            (0.3, 2.9, PI, [0.0, 0.0, 0.0]),
            (0.6, 2.6, PI, [0.0, 0.0, 0.0]),
            (2.8, 0.4, PI, [0.0, 0.0, 0.0]),
        ],
        5e-3,
    );
    // base_color (0.7, 0.6, 0.2), flatness 0.6, roughness 0.8, spec_tint 0.5, sheen 0.4.
    check(
        &material(Principled {
            base_color: Vec3::new(0.7, 0.6, 0.2),
            flatness: 0.6,
            roughness: 0.8,
            spec_tint: 0.5,
            sheen: 0.4,
            ..Principled::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.1710984, 0.1471833, 0.05152307]),
            (1.0, 0.3, 1.0, [0.1991895, 0.171134, 0.05891198]),
            (0.5, 0.5, PI, [0.171028, 0.1472124, 0.0519496]),
            (1.3, 1.2, 3.0, [0.1740462, 0.1580065, 0.09384782]),
            (0.3, 2.5, 0.7, [0.0, 0.0, 0.0]),
            (2.6, 0.8, 1.9, [0.0, 0.0, 0.0]),
            (2.7, 2.2, 2.8, [0.0, 0.0, 0.0]),
            (0.3, 2.9, PI, [0.0, 0.0, 0.0]),
            (0.6, 2.6, PI, [0.0, 0.0, 0.0]),
            (2.8, 0.4, PI, [0.0, 0.0, 0.0]),
        ],
        5e-3,
    );
    // base_color (0.9, 0.8, 0.5), spec_trans 0.7, eta 1.4, roughness 0.3, sheen 0.2 (views from inside and lights behind: transmission).
    check(
        &material(Principled {
            base_color: Vec3::new(0.9, 0.8, 0.5),
            spec_trans: 0.7,
            eta: 1.4,
            roughness: 0.3,
            sheen: 0.2,
            ..Principled::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.1058668, 0.0970713, 0.07068485]),
            (1.0, 0.3, 1.0, [0.08241094, 0.07328906, 0.0459234]),
            (0.5, 0.5, PI, [0.3976042, 0.3892239, 0.3640831]),
            (1.3, 1.2, 3.0, [0.1725214, 0.1695254, 0.1605373]),
            (0.3, 2.5, 0.7, [0.0, 0.0, 0.0]),
            (2.6, 0.8, 1.9, [3.312875e-07, 3.123408e-07, 2.469271e-07]),
            (2.7, 2.2, 2.8, [0.005697055, 0.005697055, 0.005697055]),
            (0.3, 2.9, PI, [33.61935, 31.69662, 25.05838]),
            (0.6, 2.6, PI, [0.4830512, 0.455425, 0.3600451]),
            (2.8, 0.4, PI, [9.534249, 8.988976, 7.10641]),
        ],
        5e-3,
    );
}

#[test]
fn principled_thin_matches_mitsuba() {
    use ais_render::bsdf::PrincipledThin;
    use std::f32::consts::PI;
    let material = |thin: PrincipledThin| Material {
        scattering: Scattering::PrincipledThin(thin),
        two_sided: true,
    };
    // base_color (0.6, 0.3, 0.1), every other parameter at its default (no specular lobe without spec_trans, as in Mitsuba).
    check(
        &material(PrincipledThin {
            base_color: Vec3::new(0.6, 0.3, 0.1),
            ..PrincipledThin::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.1759099, 0.08795496, 0.02931832]),
            (1.0, 0.3, 1.0, [0.1836742, 0.09183709, 0.03061236]),
            (0.5, 0.5, PI, [0.1676084, 0.08380421, 0.02793473]),
            (1.3, 1.2, 3.0, [0.06077674, 0.03038837, 0.01012946]),
            (0.3, 2.5, 0.7, [0.0, 0.0, 0.0]),
            (0.3, 2.9, PI, [0.0, 0.0, 0.0]),
            (0.6, 2.6, 0.0, [0.0, 0.0, 0.0]),
            (1.1, 2.0, 0.2, [0.0, 0.0, 0.0]),
        ],
        5e-3,
    );
    // base_color (0.3, 0.6, 0.1), diff_trans 0.8, roughness 0.6, sheen 0.4, sheen_tint 0.5, flatness 0.5.
    check(
        &material(PrincipledThin {
            base_color: Vec3::new(0.3, 0.6, 0.1),
            diffuse_transmission: 0.4,
            roughness: 0.6,
            sheen: 0.4,
            sheen_tint: 0.5,
            flatness: 0.5,
            ..PrincipledThin::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.04373574, 0.08747146, 0.01457859]),
            (1.0, 0.3, 1.0, [0.05045874, 0.1009167, 0.01682007]),
            (0.5, 0.5, PI, [0.04305097, 0.08609906, 0.01435225]),
            (1.3, 1.2, 3.0, [0.03581226, 0.06541177, 0.01607926]),
            (0.3, 2.5, 0.7, [0.03060143, 0.06120286, 0.01020048]),
            (0.3, 2.9, PI, [0.03708787, 0.07417574, 0.01236262]),
            (0.6, 2.6, 0.0, [0.03273074, 0.06546148, 0.01091025]),
            (1.1, 2.0, 0.2, [0.01589564, 0.03179128, 0.005298547]),
        ],
        5e-3,
    );
    // base_color (0.9, 0.8, 0.5), spec_trans 0.6, eta 1.33, roughness 0.3, spec_tint 0.4, diff_trans 0.5, anisotropic 0.5.
    check(
        &material(PrincipledThin {
            base_color: Vec3::new(0.9, 0.8, 0.5),
            spec_trans: 0.6,
            eta: 1.33,
            roughness: 0.3,
            spec_tint: 0.4,
            diffuse_transmission: 0.25,
            anisotropic: 0.5,
            ..PrincipledThin::default()
        }),
        &[
            (0.2, 0.4, 2.5, [0.08534282, 0.07625346, 0.04898539]),
            (1.0, 0.3, 1.0, [0.08245177, 0.0733132, 0.04589748]),
            (0.5, 0.5, PI, [0.2201284, 0.2050231, 0.159707]),
            (1.3, 1.2, 3.0, [0.05527527, 0.05212072, 0.04265706]),
            (0.3, 2.5, 0.7, [0.02401054, 0.02134271, 0.01333919]),
            (0.3, 2.9, PI, [23.33352, 20.74091, 12.96307]),
            (0.6, 2.6, 0.0, [0.02566554, 0.02281381, 0.01425863]),
            (1.1, 2.0, 0.2, [0.01192173, 0.01059709, 0.006623182]),
        ],
        5e-3,
    );
}
