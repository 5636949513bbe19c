//! Property tests of the materials: the course reflectance, mirrors and Snell refraction, and
//! the conductors, smooth and rough (Fresnel, furnace, reciprocity, sampling, limits).

use glam::Vec3A;
use proptest::prelude::*;
use rtis::material::{Mirror, Phong, Transmissive};

fn unit() -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-degenerate", |(x, y, z)| x * x + y * y + z * z > 1e-3)
        .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize())
}

fn phong() -> impl Strategy<Value = Phong> {
    (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1000.0).prop_map(|(kd, ks, s)| Phong {
        kd: Vec3A::splat(kd),
        ks: Vec3A::splat(ks),
        shininess: s,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(5000))]

    /// r(wi, wo) >= 0 and finite for all directions, including below the surface and even
    /// exponents (the original's unclamped lobe went negative or lit back faces).
    #[test]
    fn course_reflectance_is_nonnegative_and_finite(p in phong(), wi in unit(), wo in unit(), n in unit()) {
        let r = p.course_reflectance(wi, wo, n);
        prop_assert!(r.is_finite() && r.min_element() >= 0.0, "{r}");
        let f = p.brdf(wi, wo, n);
        prop_assert!(f.is_finite() && f.min_element() >= 0.0, "{f}");
    }

    /// Mirror reflection preserves the angle to the normal and stays in the plane of wo and n.
    #[test]
    fn mirror_preserves_angles(wo in unit(), n in unit()) {
        let m = Mirror { color: Vec3A::ONE };
        let wr = m.reflect(wo, n);
        prop_assert!((wr.length() - 1.0).abs() < 1e-5);
        prop_assert!((wr.dot(n) - wo.dot(n)).abs() < 1e-5);
        prop_assert!((wr + wo).cross(n).length() < 1e-4);
    }

    /// Snell's law, reversibility, and total internal reflection exactly when sin(theta_t) > 1.
    #[test]
    fn refraction_obeys_snell(ior in 0.2f32..3.0, wo in unit(), n in unit()) {
        let g = Transmissive { ior, color: Vec3A::ONE };
        let r = g.refract(wo, n);
        let entering = wo.dot(n) > 0.0;
        let eta = if entering { 1.0 / ior } else { ior };
        prop_assert!((r.eta - eta).abs() < 1e-6);
        let cos_i = wo.dot(n).abs();
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        let sin_t = eta * sin_i;
        prop_assert!(r.wt.is_finite() && (r.wt.length() - 1.0).abs() < 1e-4);
        if sin_t > 1.0 + 1e-5 {
            prop_assert!(r.total_internal_reflection);
            prop_assert!((r.wt.dot(n) - wo.dot(n)).abs() < 1e-4, "TIR reflects");
        } else if sin_t < 1.0 - 1e-5 {
            prop_assert!(!r.total_internal_reflection);
            // The transmitted ray is on the other side, with sin(theta_t) = eta sin(theta_i).
            prop_assert!(r.wt.dot(n) * wo.dot(n) <= 0.0);
            let cos_t = r.wt.dot(n).abs();
            let got = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            prop_assert!((got - sin_t).abs() < 2e-3, "sin_t {got} vs {sin_t}");
            // Reversible: light arriving along -wt from the other side leaves along wo.
            // (`refract` takes the direction pointing away from the surface on the incident
            // side, which for the reverse path is wt.)
            if sin_t < 0.99 && sin_i < 0.99 {
                let back = g.refract(r.wt, n);
                prop_assert!(!back.total_internal_reflection);
                prop_assert!((back.wt - wo).length() < 2e-3, "{} vs {}", back.wt, wo);
            }
        }
    }
}

/// The Fresnel reflectance against the textbook form in angles (Hecht): with Snell's
/// `sin t = eta sin i`, `R_s = (sin(i - t) / sin(i + t))^2`, `R_p = (tan(i - t) / tan(i + t))^2`
/// and `F = (R_s + R_p) / 2`, at oblique angles into and out of glass (normal incidence alone
/// cannot tell the two polarisations' formulas apart).
#[test]
fn fresnel_matches_the_angle_form_at_oblique_incidence() {
    use rtis::material::fresnel_dielectric;
    for eta in [1.0 / 1.5f64, 1.0 / 2.4, 1.5] {
        for deg in [10.0f64, 30.0, 45.0, 60.0, 80.0] {
            let i = deg.to_radians();
            let sin_t = eta * i.sin();
            if sin_t >= 1.0 {
                assert_eq!(fresnel_dielectric(i.cos() as f32, eta as f32), 1.0);
                continue;
            }
            let t = sin_t.asin();
            let rs = ((i - t).sin() / (i + t).sin()).powi(2);
            let rp = ((i - t).tan() / (i + t).tan()).powi(2);
            let want = 0.5 * (rs + rp);
            let got = fresnel_dielectric(i.cos() as f32, eta as f32) as f64;
            assert!(
                (got - want).abs() < 1e-5,
                "eta {eta}, {deg} deg: {got} vs {want}"
            );
        }
    }
}

// Conductors and rough conductors (src/material/conductor.rs, rough_conductor.rs).

use rtis::material::conductor::{Conductor, Metal, fresnel_conductor};
use rtis::material::microfacet::{Distribution, Microfacet, NormalSampling};
use rtis::material::rough_conductor::RoughConductor;

/// The Fresnel reflectance of a conductor from the complex amplitudes, in double precision:
/// `r_s = (cos - w) / (cos + w)`, `r_p = (n^2 cos - w) / (n^2 cos + w)`, `w = sqrt(n^2 - sin^2)`
/// with `n = eta + i k` (Born and Wolf, section 14.2), an independent form of the formula the
/// renderer uses.
fn fresnel_complex(cos: f64, eta: f64, k: f64) -> f64 {
    type C = (f64, f64);
    let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: C, b: C| {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let sqrt = |a: C| {
        let r = (a.0 * a.0 + a.1 * a.1).sqrt();
        let re = ((r + a.0) / 2.0).sqrt();
        let im = ((r - a.0) / 2.0).sqrt().copysign(a.1);
        (re, im)
    };
    let n2 = mul((eta, k), (eta, k));
    let w = sqrt((n2.0 - (1.0 - cos * cos), n2.1));
    let rs = div((cos - w.0, -w.1), (cos + w.0, w.1));
    let n2c = (n2.0 * cos, n2.1 * cos);
    let rp = div((n2c.0 - w.0, n2c.1 - w.1), (n2c.0 + w.0, n2c.1 + w.1));
    0.5 * (rs.0 * rs.0 + rs.1 * rs.1 + rp.0 * rp.0 + rp.1 * rp.1)
}

/// The conductor Fresnel term against the complex-amplitude form for every named metal from
/// normal to grazing incidence (1e-5: single precision), its normal-incidence closed form
/// `((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2)`, `none` reflecting everything, and `k = 0`
/// reducing to the dielectric's Fresnel term.
#[test]
fn conductor_fresnel_matches_the_complex_amplitudes() {
    for metal in Metal::ALL {
        let name = metal.name();
        let (eta, k) = metal.eta_k();
        for c in 0..3 {
            let (e, kk) = (eta[c], k[c]);
            for i in 0..=100 {
                let cos = i as f32 / 100.0;
                let got = fresnel_conductor(cos, e, kk);
                let want = if name == "none" {
                    1.0
                } else {
                    fresnel_complex(cos as f64, e as f64, kk as f64)
                };
                assert!(
                    (got as f64 - want).abs() < 1e-5,
                    "{name} channel {c} cos {cos}: {got} vs {want}"
                );
            }
            let normal = ((e - 1.0).powi(2) + kk * kk) / ((e + 1.0).powi(2) + kk * kk);
            assert!(
                (fresnel_conductor(1.0, e, kk) - normal).abs() < 1e-6,
                "{name}"
            );
        }
    }
    assert_eq!(Metal::from_name("unobtainium"), None);
    assert!(
        Metal::ALL
            .iter()
            .all(|&m| Metal::from_name(m.name()) == Some(m))
    );
    for cos in [0.05f32, 0.3, 0.7, 1.0] {
        let d = rtis::material::fresnel_dielectric(cos, 1.0 / 1.5);
        assert!(
            (fresnel_conductor(cos, 1.5, 0.0) - d).abs() < 1e-6,
            "cos {cos}"
        );
    }
}

/// A rough conductor of the given distribution and roughness, of a named metal.
fn rough(distribution: Distribution, ax: f32, ay: f32, metal: &str) -> RoughConductor {
    let (eta, k) = Metal::from_name(metal).unwrap().eta_k();
    RoughConductor {
        microfacet: Microfacet {
            distribution,
            alpha_x: ax,
            alpha_y: ay,
            sampling: NormalSampling::Visible,
        },
        metal: Conductor {
            eta,
            k,
            specular_reflectance: Vec3A::ONE,
        },
    }
}

/// A unit direction at `theta` degrees from the normal, azimuth 0.4 rad.
fn at(theta: f32) -> Vec3A {
    let (t, p) = (theta.to_radians(), 0.4f32);
    Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// `int g(wm) dwm` over the normals (`Microfacet::integrate_over_normals`, 1500 x 256 points).
fn over_normals(m: &Microfacet, g: impl Fn(Vec3A) -> f64) -> f64 {
    m.integrate_over_normals(1500, 256, g)
}

/// The single-scattering albedo of a rough mirror from `wo`, `int D_wo(wm) G1(wi, wm) dwm` with
/// `wi` the mirror of `wo` about `wm`, by quadrature.
fn single_scattering(m: &Microfacet, wo: Vec3A) -> f64 {
    over_normals(m, |wm| {
        (m.d_visible(wo, wm) * m.g1(2.0 * wo.dot(wm) * wm - wo, wm)) as f64
    })
}

/// The white furnace of a rough mirror (`none`: Fresnel 1). Its albedo from `wo` is the energy
/// single scattering keeps, `int D_wo(wm) G1(wi, wm) dwm`. Three ways agree: that integral by
/// quadrature; `int f cos dwi` by quadrature of `eval` (over normals, `dwi = 4 |wo.wm| dwm`,
/// to 2e-3); and the mean weight of 400,000 samples (a z-test at 5 standard errors, the
/// weights being `G1` in [0, 1]). The albedo is at most 1, above 0.99 at alpha 0.01, and falls
/// with roughness and towards grazing.
#[test]
fn rough_mirror_keeps_its_single_scattering_energy() {
    let mut s = rtis::sampling::Sampler::new(5, 0, 0);
    for d in [Distribution::Ggx, Distribution::Beckmann] {
        for (ax, ay) in [(0.01, 0.01), (0.3, 0.3), (1.0, 1.0), (0.1, 0.6)] {
            let b = rough(d, ax, ay, "none");
            let m = b.microfacet;
            for theta in [0.0f32, 45.0, 80.0] {
                let wo = at(theta);
                let single = single_scattering(&m, wo);
                let by_eval = over_normals(&m, |wm| {
                    let wi = 2.0 * wo.dot(wm) * wm - wo;
                    (b.eval(wo, wi).x * 4.0 * wo.dot(wm).abs()) as f64
                });
                assert!(
                    (single - by_eval).abs() < 2e-3,
                    "{d:?} {ax}x{ay} {theta}: {single} vs {by_eval}"
                );
                assert!(
                    single <= 1.0 + 1e-3,
                    "{d:?} {ax}x{ay} {theta}: albedo {single}"
                );
                if ax == 0.01 {
                    assert!(single > 0.99, "{d:?} {theta}: albedo {single}");
                }
                let n = 400_000;
                let (mut sum, mut sum2) = (0.0f64, 0.0f64);
                for _ in 0..n {
                    let (u1, u2) = s.next_2d();
                    if let Some(smp) = b.sample(wo, u1, u2) {
                        let w = smp.weight.x as f64;
                        // G1 of the sampled direction, to rounding.
                        assert!((0.0..=1.0 + 1e-4).contains(&w), "weight {w}");
                        sum += w;
                        sum2 += w * w;
                    }
                }
                let mean = sum / n as f64;
                let se = ((sum2 / n as f64 - mean * mean) / n as f64)
                    .sqrt()
                    .max(1e-6);
                assert!(
                    (mean - single).abs() < 5.0 * se + 1e-3,
                    "{d:?} {ax}x{ay} {theta}: sampled {mean} +- {se}, quadrature {single}"
                );
            }
        }
    }
    // Rougher keeps less, and grazing less than normal.
    let albedo = |a: f32, theta: f32| {
        single_scattering(&Microfacet::isotropic(Distribution::Ggx, a), at(theta))
    };
    assert!(albedo(1.0, 0.0) < albedo(0.3, 0.0) && albedo(0.3, 0.0) < albedo(0.01, 0.0));
    assert!(albedo(0.3, 80.0) < albedo(0.3, 0.0));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Reciprocity: `f(wo, wi) = f(wi, wo)` (the cosine taken out), for every distribution,
    /// roughness from 1e-3 to 1 and metal; `f >= 0` and finite.
    #[test]
    fn rough_conductor_is_reciprocal(
        wo in unit(), wi in unit(), ax in 0.001f32..1.0, ay in 0.001f32..1.0,
        beckmann in any::<bool>(), metal in 0usize..6,
    ) {
        let d = if beckmann { Distribution::Beckmann } else { Distribution::Ggx };
        let b = rough(d, ax, ay, Metal::ALL[metal].name());
        let (a, c) = (b.eval(wo, wi), b.eval(wi, wo));
        prop_assert!(a.is_finite() && a.min_element() >= 0.0, "{a}");
        if wo.z > 1e-3 && wi.z > 1e-3 {
            let (fa, fc) = (a / wi.z, c / wo.z);
            prop_assert!(
                (fa - fc).abs().max_element() <= 1e-4 * fa.max_element().max(1e-3),
                "{fa} vs {fc}"
            );
        }
    }

    /// The density a sample reports is the one `pdf` gives its direction, and the weight is
    /// `eval / pdf`, where single precision can tell them apart: for alpha from 0.01 and the
    /// viewer at least 0.05 in cosine from the horizon, to 1e-3. (Below that the sampled
    /// direction, rounded to `f32`, carries a half-vector error near `u / (2 wo.wm)` rad, which
    /// a lobe as narrow as alpha turns into a different density; the sample keeps the density
    /// of the normal it drew, as pbrt-v4 and Mitsuba 3 do.) At every alpha from 1e-4 (the
    /// smallest) to 1 and from the normal to grazing (cos 1e-4), nothing is NaN or infinite.
    #[test]
    fn rough_conductor_samples_agree_with_its_pdf(
        wo in unit(), u1 in 0.0f32..1.0, u2 in 0.0f32..1.0,
        alpha in prop_oneof![Just(1e-4f32), Just(1.0f32), 1e-3f32..1.0],
        beckmann in any::<bool>(), full in any::<bool>(),
    ) {
        let wo = Vec3A::new(wo.x, wo.y, wo.z.abs().max(1e-4)).normalize();
        let d = if beckmann { Distribution::Beckmann } else { Distribution::Ggx };
        let mut b = rough(d, alpha, alpha, "Au");
        if full {
            b.microfacet.sampling = NormalSampling::Full;
        }
        if let Some(s) = b.sample(wo, u1, u2) {
            prop_assert!(s.wi.z > 0.0 && s.pdf > 0.0 && s.weight.is_finite(), "{s:?}");
            let pdf = b.pdf(wo, s.wi);
            prop_assert!(pdf.is_finite() && b.eval(wo, s.wi).is_finite());
            if alpha >= 0.01 && wo.z >= 0.05 {
                prop_assert!((pdf - s.pdf).abs() <= 1e-3 * s.pdf, "{pdf} vs {}", s.pdf);
            }
            let want = b.eval(wo, s.wi) / s.pdf;
            prop_assert!(
                (want - s.weight).abs().max_element() <= 1e-5 * want.max_element().max(1.0)
            );
        }
    }
}

/// As alpha goes to 0 the rough mirror becomes the mirror: at alpha 1e-4, of 100,000 sampled
/// directions, GGX sends fewer than 0.1% farther than 0.01 rad from the mirror direction (its
/// long tails: a normal tilted past 0.005 rad has probability near (alpha / 0.005)^2 = 4e-4) and
/// Beckmann none; the mean weight is the smooth conductor's Fresnel term (to 1e-3).
#[test]
fn rough_conductor_converges_to_the_smooth_one() {
    let mut s = rtis::sampling::Sampler::new(9, 0, 0);
    for d in [Distribution::Ggx, Distribution::Beckmann] {
        let b = rough(d, 1e-4, 1e-4, "Cu");
        for theta in [0.0f32, 40.0, 80.0] {
            let wo = at(theta);
            let (wr, f) = b.metal.reflect(wo, Vec3A::Z);
            let (n, mut far, mut sum) = (100_000, 0, Vec3A::ZERO);
            for _ in 0..n {
                let (u1, u2) = s.next_2d();
                let Some(smp) = b.sample(wo, u1, u2) else {
                    continue;
                };
                far += usize::from(smp.wi.angle_between(wr) > 0.01);
                sum += smp.weight;
            }
            let limit = if d == Distribution::Ggx { n / 1000 } else { 0 };
            assert!(far <= limit, "{d:?} {theta}: {far} of {n} beyond 0.01 rad");
            let mean = sum / n as f32;
            assert!(
                (mean - f).abs().max_element() < 1e-3,
                "{d:?} {theta}: {mean} vs {f}"
            );
        }
    }
}

/// The single-scattering albedo of GGX rough mirrors, printed for docs/transport.md: what
/// multiple scattering would add back (`cargo test --release --test materials albedo_table --
/// --ignored --nocapture`).
#[test]
#[ignore = "prints a table"]
fn albedo_table() {
    for d in [Distribution::Ggx, Distribution::Beckmann] {
        for a in [0.1f32, 0.3, 0.6, 1.0] {
            let m = Microfacet::isotropic(d, a);
            let row: Vec<String> = [0.0f32, 45.0, 70.0, 85.0]
                .iter()
                .map(|&t| format!("{:.3}", single_scattering(&m, at(t))))
                .collect();
            println!("{d:?} alpha {a}: {}", row.join(" "));
        }
    }
}

/// A smooth conductor renders its Fresnel term exactly: under a uniform sky `b`, an
/// orthographic view of a metal plane turned `theta` from the view shows `F(cos(theta)) *
/// specular_reflectance * b` in every pixel, in Direct, Global and Path under both models
/// (the reflected ray escapes to the sky), for named metals and for `eta` and `k` given
/// directly. Tolerance: single-precision rounding (1e-5 relative). `none` is the mirror.
#[test]
fn a_conductor_reflects_its_fresnel_term_of_the_sky() {
    let b = Vec3A::new(0.5, 1.0, 2.0);
    for (material, eta, k) in [
        ("material: \"Au\"", Metal::Au.eta_k().0, Metal::Au.eta_k().1),
        ("material: \"Cr\"", Metal::Cr.eta_k().0, Metal::Cr.eta_k().1),
        (
            "eta: (1.5, 0.4, 0.2), k: (3, 2, 1)",
            Vec3A::new(1.5, 0.4, 0.2),
            Vec3A::new(3.0, 2.0, 1.0),
        ),
        ("", Vec3A::ZERO, Vec3A::ONE),
    ] {
        for theta in [0.0f32, 60.0] {
            let t = theta.to_radians();
            for (shader, model) in [
                ("Direct()", "Course"),
                ("Global(samples: 2, max_depth: 1)", "Course"),
                ("Path(max_depth: 3)", "Physical"),
            ] {
                let text = format!(
                    "Scene(film: (width: 3, height: 2), model: {model}, shader: {shader},
                       camera: Orthographic(position: (0, 0, -5), look_at: (0, 0, 0), height: 1),
                       background: (0.5, 1, 2),
                       entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: ({}, 0, {})),
                                   material: Conductor({material}{}specular_reflectance: (1, 0.5, 0.25)))])",
                    t.sin(),
                    -t.cos(),
                    if material.is_empty() { "" } else { ", " }
                );
                let s = rtis::scene::load_str(&text, "test.ron", None)
                    .unwrap_or_else(|e| panic!("{e}"));
                let r = rtis::render(&rtis::extract(&s), &|| {});
                let f = |c: usize| fresnel_conductor(t.cos(), eta[c], k[c]);
                let want = Vec3A::new(f(0), f(1), f(2)) * Vec3A::new(1.0, 0.5, 0.25) * b;
                for p in &r.image.pixels {
                    assert!(
                        (*p - want).abs().max_element() <= 1e-5 * want.max_element(),
                        "{material} {theta} {shader}: {p} vs {want}"
                    );
                }
            }
        }
    }
}
