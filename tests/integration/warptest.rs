//! `rtis warptest` (src/converge/warptest.rs): every sampler passes its chi-squared test, a
//! sampler with the wrong pdf fails it, and the p-values are right where tables give them.

use crate::common;

use glam::Vec3A;
use rtis::converge::warptest::{self, Case, direction_bin, gamma_q, integrate_pdf};
use rtis::sampling::hemisphere;
use std::process::Command;

#[test]
fn p_values_match_the_tables() {
    // chi^2 upper 5% points: 3.841 (1 dof), 18.307 (10 dof), 124.342 (100 dof).
    for (k, x) in [(1.0, 3.841_459), (10.0, 18.307_04), (100.0, 124.342_1)] {
        let p = gamma_q(k / 2.0, x / 2.0);
        assert!((p - 0.05).abs() < 1e-5, "k {k}: p {p}");
    }
    assert!((gamma_q(1.0, 1.0) - (-1f64).exp()).abs() < 1e-12);
}

#[test]
fn every_sampler_follows_its_pdf() {
    let cases = warptest::cases();
    let alpha = warptest::per_test_alpha(cases.len());
    for case in &cases {
        let o = warptest::run(case, 200_000, 7);
        assert!(
            o.p_value >= alpha,
            "{}: chi2 {} dof {} p {}",
            o.name,
            o.chi2,
            o.dof,
            o.p_value
        );
    }
}

/// The test has power: cosine samples against the uniform pdf, and the Phong lobe of exponent
/// 10 against the pdf of exponent 11 (a plausible bug), are both rejected.
#[test]
fn a_wrong_pdf_is_rejected() {
    let wrong = [
        Case {
            name: "cosine samples, uniform pdf".into(),
            draw: Box::new(|s| {
                let (u1, u2) = s.next_2d();
                Some(direction_bin(hemisphere::cosine(u1, u2)))
            }),
            expected: integrate_pdf(|w| {
                if w.z > 0.0 {
                    1.0 / (2.0 * std::f64::consts::PI)
                } else {
                    0.0
                }
            }),
            columns: warptest::BINS_PHI,
        },
        Case {
            name: "lobe s = 10, pdf of s = 11".into(),
            draw: Box::new(|s| {
                let (u1, u2) = s.next_2d();
                Some(direction_bin(hemisphere::phong_lobe(u1, u2, 10.0)))
            }),
            expected: integrate_pdf(|w: Vec3A| hemisphere::phong_lobe_pdf(w.z, 11.0) as f64),
            columns: warptest::BINS_PHI,
        },
    ];
    for case in &wrong {
        let o = warptest::run(case, 200_000, 7);
        assert!(o.p_value < 1e-6, "{}: p {}", o.name, o.p_value);
    }
    let page = warptest::html(&[warptest::run(&wrong[0], 10_000, 1)], 10_000);
    assert!(page.contains("rejected") && page.contains("<svg"));
}

#[test]
fn the_command_prints_and_writes_its_page() {
    let d = std::env::temp_dir().join(format!("rtis-warp-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let page = d.join("w.html");
    let o = common::output_within(
        Command::new(env!("CARGO_BIN_EXE_rtis")).args([
            "warptest",
            "--samples",
            "100000",
            "-o",
            page.to_str().unwrap(),
        ]),
        600,
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        out.matches("accepted").count(),
        warptest::cases().len(),
        "{out}"
    );
    assert!(
        std::fs::read_to_string(&page)
            .unwrap()
            .matches("<svg")
            .count()
            >= 20
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// The microfacet tests have power: visible normals drawn at alpha 0.4 against the pdf of
/// alpha 0.42 (5% off), the same with an anisotropic pair (alpha_y 5% off), and visible normals
/// against the full sampler's pdf, each from 45 degrees, are rejected (p below 1e-6 at 200,000
/// samples).
#[test]
fn a_wrong_microfacet_pdf_is_rejected() {
    use rtis::material::microfacet::{Distribution, Microfacet, NormalSampling};
    // 45 degrees from the normal, at azimuth 30 degrees.
    let (t, p) = (45f32.to_radians(), 30f32.to_radians());
    let wo = Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    let case = |name: &str, drawn: Microfacet, claimed: Microfacet| Case {
        name: name.into(),
        draw: Box::new(move |s| {
            let (u1, u2) = s.next_2d();
            Some(direction_bin(drawn.sample_reflection(wo, u1, u2)?.0))
        }),
        expected: warptest::integrate_pdf_peaked(|wi| claimed.pdf_reflection(wo, wi) as f64),
        columns: warptest::BINS_PHI,
    };
    for d in [Distribution::Ggx, Distribution::Beckmann] {
        let m = Microfacet::isotropic(d, 0.4);
        let aniso = Microfacet {
            alpha_x: 0.2,
            alpha_y: 0.5,
            ..m
        };
        let wrong = [
            case(
                "alpha 0.4, pdf of 0.42",
                m,
                Microfacet {
                    alpha_x: 0.42,
                    alpha_y: 0.42,
                    ..m
                },
            ),
            case(
                "alpha 0.2 x 0.5, pdf of 0.2 x 0.525",
                aniso,
                Microfacet {
                    alpha_y: 0.525,
                    ..aniso
                },
            ),
            case(
                "visible normals, full pdf",
                m,
                Microfacet {
                    sampling: NormalSampling::Full,
                    ..m
                },
            ),
        ];
        for c in &wrong {
            let o = warptest::run(c, 200_000, 7);
            assert!(o.p_value < 1e-6, "{d:?} {}: p {}", o.name, o.p_value);
        }
    }
}

/// The peaked integration misses no lobe: for every microfacet configuration `rtis warptest`
/// tests, the expected probabilities over all bins sum to the sampler's whole mass (the share
/// of reflected directions above the surface), found independently by quadrature over normals
/// in slope space, to 2e-3. A lobe that the bins' coarse grids never saw would be missing from
/// the sum.
#[test]
fn peaked_integration_keeps_every_lobe() {
    use rtis::material::microfacet::{Distribution, Microfacet, NormalSampling};
    for distribution in [Distribution::Ggx, Distribution::Beckmann] {
        for (ax, ay, sampling) in [
            (0.01, 0.01, NormalSampling::Visible),
            (0.1, 0.1, NormalSampling::Visible),
            (1.0, 1.0, NormalSampling::Visible),
            (0.1, 0.5, NormalSampling::Visible),
            (0.1, 0.1, NormalSampling::Full),
        ] {
            let m = Microfacet {
                distribution,
                alpha_x: ax,
                alpha_y: ay,
                sampling,
            };
            for theta in [0.0f32, 45.0, 85.0] {
                let (t, p) = (theta.to_radians(), 30f32.to_radians());
                let wo = Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
                let bins: f64 =
                    warptest::integrate_pdf_peaked(|wi| m.pdf_reflection(wo, wi) as f64)
                        .iter()
                        .sum();
                let mass = m.integrate_over_normals(1500, 256, |wm| {
                    let wi = 2.0 * wo.dot(wm) * wm - wo;
                    if wo.dot(wm) > 0.0 && wi.z > 0.0 {
                        m.pdf_normal(wo, wm) as f64
                    } else {
                        0.0
                    }
                });
                assert!(
                    (bins - mass).abs() < 2e-3,
                    "{distribution:?} {sampling:?} {ax}x{ay} {theta}: bins {bins}, mass {mass}"
                );
            }
        }
    }
}

/// The BSDF tests have power: a rough dielectric (GGX, alpha 0.3, eta 1.5, from 45 degrees
/// outside and 40 inside) drawn against the pdf of alpha 0.315 (5% off), of eta 1.55, and of
/// full-normal sampling; and a rough plastic against the pdf of another base colour (which
/// moves the choice between coating and base) are each rejected (p below 1e-6 at 200,000
/// samples).
#[test]
fn a_wrong_bsdf_pdf_is_rejected() {
    use rtis::material::Bsdf;
    use rtis::material::microfacet::{Distribution, Microfacet, NormalSampling};
    use rtis::material::rough_dielectric::RoughDielectric;
    use rtis::material::rough_plastic::RoughPlastic;
    let case = |wo: Vec3A, drawn: Bsdf, claimed: Bsdf| Case {
        name: String::new(),
        draw: Box::new(move |s| {
            let uc = s.next_f32();
            let (u1, u2) = s.next_2d();
            Some(direction_bin(drawn.sample(wo, uc, u1, u2)?.wi))
        }),
        expected: warptest::integrate_pdf_peaked(|wi| claimed.pdf(wo, wi) as f64),
        columns: warptest::BINS_PHI,
    };
    let m = Microfacet::isotropic(Distribution::Ggx, 0.3);
    let glass = |m: Microfacet, eta: f32| {
        Bsdf::RoughDielectric(RoughDielectric {
            microfacet: m,
            eta,
            specular_reflectance: Vec3A::ONE,
            specular_transmittance: Vec3A::ONE,
        })
    };
    let plastic =
        |rho: Vec3A| Bsdf::RoughPlastic(RoughPlastic::new(m, 1.49, rho, Vec3A::ONE, false));
    let (t, p) = (45f32.to_radians(), 30f32.to_radians());
    let outside = Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    let inside = Vec3A::new(0.6428 * p.cos(), 0.6428 * p.sin(), -0.766);
    let full = Microfacet {
        sampling: NormalSampling::Full,
        ..m
    };
    let wrong = [
        (
            "alpha 5% off, outside",
            case(
                outside,
                glass(m, 1.5),
                glass(Microfacet::isotropic(Distribution::Ggx, 0.315), 1.5),
            ),
        ),
        (
            "alpha 5% off, inside",
            case(
                inside,
                glass(m, 1.5),
                glass(Microfacet::isotropic(Distribution::Ggx, 0.315), 1.5),
            ),
        ),
        ("eta 1.55", case(outside, glass(m, 1.5), glass(m, 1.55))),
        ("full pdf", case(outside, glass(m, 1.5), glass(full, 1.5))),
        (
            "plastic base colour",
            case(
                outside,
                plastic(Vec3A::splat(0.2)),
                plastic(Vec3A::splat(0.8)),
            ),
        ),
    ];
    for (name, c) in &wrong {
        let o = warptest::run(c, 200_000, 7);
        assert!(o.p_value < 1e-6, "{name}: p {}", o.p_value);
    }
}

/// The thin lens's sampler has power against the classic mistake: the polar map with
/// `r = u1` (not `sqrt(u1)`) crowds the centre and is rejected; the concentric map passes.
#[test]
fn a_lens_sampler_crowding_the_centre_is_rejected() {
    fn naive_polar(u1: f32, u2: f32) -> (f32, f32) {
        let (sin_p, cos_p) = (std::f32::consts::TAU * u2).sin_cos();
        (u1 * cos_p, u1 * sin_p)
    }
    let wrong = warptest::run(&warptest::disk_case("r = u1", naive_polar), 200_000, 3);
    assert!(wrong.p_value < 1e-6, "p {}", wrong.p_value);
    let right = warptest::run(
        &warptest::disk_case("concentric", rtis::sampling::warp::concentric_disk),
        200_000,
        3,
    );
    assert!(right.p_value > 1e-3, "p {}", right.p_value);
}

/// The environment sampler has power against a missing `sin(theta)`: on a constant map,
/// drawing `(u, v)` uniformly (the cells' weights without their solid angle) crowds the poles
/// and is rejected against the density the light claims; the light's own sampler passes.
#[test]
fn an_environment_sampler_missing_sin_theta_is_rejected() {
    let light = warptest::environment(warptest::grey_map(16, 8, |_, _| 1.0));
    let claimed = warptest::environment_case("claimed", light.clone()).expected;
    // (u, v) uniform, mapped to directions as the light maps them (its zenith on +z).
    let wrong = Case {
        name: "uniform in (u, v)".into(),
        draw: Box::new(|s: &mut rtis::sampling::Sampler| {
            let (u, v) = s.next_2d();
            let (theta, phi) = (v * std::f32::consts::PI, u * std::f32::consts::TAU);
            let w = glam::Vec3A::new(
                phi.sin() * theta.sin(),
                phi.cos() * theta.sin(),
                theta.cos(),
            );
            Some(direction_bin(w))
        }),
        expected: claimed,
        columns: warptest::BINS_PHI,
    };
    let o = warptest::run(&wrong, 200_000, 5);
    assert!(o.p_value < 1e-6, "p {}", o.p_value);
    let right = warptest::run(&warptest::environment_case("map", light), 200_000, 5);
    assert!(right.p_value > 1e-3, "p {}", right.p_value);
}
