//! The physically based model and the reference integrator, checked against known answers and
//! an independent renderer (Mitsuba 3).

use crate::common;

use crate::common::{render_str, scene, scenes_dir};
use glam::Vec3A;
use proptest::prelude::*;
use rtis::converge::warptest;
use rtis::material::Phong;
use rtis::sampling::Sampling;
use rtis::sampling::{Sampler, hemisphere};
use rtis::shader::path;
use std::f32::consts::PI;

/// A diffuse sphere filling the view, under a uniform background `b`, seen by the Path shader.
fn furnace(model: &str, kd: f32, sampling: &str, spp: u32) -> rtis::render::Rendered {
    render_str(&format!(
        r#"Scene(
            film: (width: 16, height: 16, spp: {spp}),
            camera: Perspective(position: (0, 0, -3), look_at: (0, 0, 0), fov: 30),
            shader: Path(sampling: {sampling}),
            model: {model},
            background: (1, 1, 1),
            entities: [(shape: Sphere(center: (0, 0, 0), radius: 1.5), material: Phong(kd: ({kd}, {kd}, {kd})))],
        )"#
    ))
}

/// White furnace: under `Physical`, a sphere of albedo 1 under a uniform sky of radiance 1
/// is invisible. A convex sphere's scattered rays all escape, so each path weighs
/// `f cos / pdf = kd` with cosine or BRDF sampling: every pixel is exactly `kd` (zero variance);
/// with uniform sampling the weight is `2 kd cos(theta)`, mean `kd`, variance `kd^2 / 3` per
/// sample; with 64 spp x 256 pixels the image mean is within 5 sigma = 0.0045 kd.
#[test]
fn white_furnace_physical() {
    for kd in [1.0f32, 0.5] {
        for sampling in ["Cosine", "Brdf"] {
            let r = furnace("Physical", kd, sampling, 4);
            for p in &r.image.pixels {
                assert!(
                    (*p - Vec3A::splat(kd)).abs().max_element() < 1e-5,
                    "{sampling} kd {kd}: {p}"
                );
            }
        }
        let r = furnace("Physical", kd, "Uniform", 64);
        let sigma = kd * (1.0f32 / 3.0 / (64.0 * 256.0)).sqrt();
        assert!(
            (r.image.mean().x - kd).abs() < 5.0 * sigma,
            "uniform kd {kd}: {}",
            r.image.mean()
        );
    }
}

/// The Course-model counterpart: each bounce weighs `r / (2 pi)` with uniform sampling, and the
/// course's `r = kd cos`, so a pixel is `b kd cos(theta) / (2 pi)` with `cos` uniform on
/// [0, 1]: mean `b kd / (4 pi)` (the Global shader's D = 1 answer), variance
/// `(b kd / (2 pi))^2 / 12` per sample; tolerance 5 sigma of the image mean.
#[test]
fn white_furnace_course() {
    let kd = 1.0f32;
    let r = furnace("Course", kd, "Uniform", 64);
    let want = kd / (4.0 * PI);
    let sigma = kd / (2.0 * PI) * (1.0f32 / 12.0 / (64.0 * 256.0)).sqrt();
    assert!(
        (r.image.mean().x - want).abs() < 5.0 * sigma,
        "{} vs {want}",
        r.image.mean()
    );
    // Cosine sampling estimates the same integral with another weight: same mean.
    let c = furnace("Course", kd, "Cosine", 64);
    assert!(
        (c.image.mean().x - want).abs() < 0.02 * want,
        "{} vs {want}",
        c.image.mean()
    );
}

fn unit() -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, 0.0f32..1.0)
        .prop_filter("non-degenerate", |(x, y, z)| {
            x * x + y * y + z * z > 1e-3 && *z > 0.01
        })
        .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize())
}

/// Monte Carlo directional albedo `rho(wo) = int f(wi, wo) cos dwi` with cosine sampling
/// (weight `f pi`), 20000 samples.
fn albedo(p: &Phong, wo: Vec3A, seed: u64) -> (f32, f32) {
    let n = Vec3A::Z;
    let mut s = Sampler::new(seed, 0, 0);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    let count = 20_000;
    for _ in 0..count {
        let (a, b) = s.next_2d();
        let wi = hemisphere::cosine(a, b);
        let w = (p.brdf(wi, wo, n).x * PI) as f64;
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / count as f64;
    let var = (sum2 / count as f64 - mean * mean).max(0.0);
    (mean as f32, (var / count as f64).sqrt() as f32)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Energy: with kd + ks <= 1 the normalised Phong BRDF reflects at most what arrives, for
    /// every outgoing direction (estimate + 5 standard errors <= 1, and a 1% margin).
    #[test]
    fn physical_phong_conserves_energy(kd in 0.0f32..1.0, frac in 0.0f32..=1.0, s in 0.0f32..200.0, wo in unit(), seed in any::<u64>()) {
        let ks = (1.0 - kd) * frac;
        let p = Phong { kd: Vec3A::splat(kd), ks: Vec3A::splat(ks), shininess: s };
        let (rho, se) = albedo(&p, wo, seed);
        prop_assert!(rho - 5.0 * se <= 1.01, "albedo {rho} +- {se} for kd {kd} ks {ks} s {s}");
    }

    /// Reciprocity: f(wi, wo) = f(wo, wi).
    #[test]
    fn physical_phong_is_reciprocal(kd in 0.0f32..1.0, ks in 0.0f32..1.0, s in 0.0f32..200.0, wi in unit(), wo in unit()) {
        let p = Phong { kd: Vec3A::splat(kd), ks: Vec3A::splat(ks), shininess: s };
        let (a, b) = (p.brdf(wi, wo, Vec3A::Z), p.brdf(wo, wi, Vec3A::Z));
        prop_assert!((a - b).abs().max_element() <= 1e-4 * a.max_element().max(1.0), "{a} vs {b}");
    }
}

/// The pdf of each sampling strategy integrates to 1 over the sphere (midpoint rule on a fine
/// (cos theta, phi) grid over the upper hemisphere; tolerance 1e-2).
#[test]
fn pdfs_integrate_to_one() {
    let n = Vec3A::Z;
    for (s, wo) in [
        (1.0, Vec3A::Z),
        (20.0, Vec3A::new(0.6, 0.0, 0.8)),
        (200.0, Vec3A::new(0.0, 0.8, 0.6)),
    ] {
        let p = Phong {
            kd: Vec3A::splat(0.3),
            ks: Vec3A::splat(0.6),
            shininess: s,
        };
        for sampling in [Sampling::Uniform, Sampling::Cosine, Sampling::Brdf] {
            let (nt, np) = (800, 800);
            let mut total = 0.0f64;
            for i in 0..nt {
                let z = (i as f32 + 0.5) / nt as f32;
                let r = (1.0 - z * z).sqrt();
                for j in 0..np {
                    let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
                    let wi = Vec3A::new(r * phi.cos(), r * phi.sin(), z);
                    total += path::pdf(&p, wo, n, wi, sampling) as f64;
                }
            }
            let integral = total * (1.0 / nt as f64) * (2.0 * std::f64::consts::PI / np as f64);
            // The Phong lobe around a tilted reflection loses its part below the horizon, so
            // the BRDF mixture integrates to at most 1 there; the other strategies to exactly 1.
            match sampling {
                Sampling::Brdf if wo != Vec3A::Z => assert!(
                    integral <= 1.01 && integral > 0.5,
                    "{sampling:?} s {s}: {integral}"
                ),
                _ => assert!(
                    (integral - 1.0).abs() < 1e-2,
                    "{sampling:?} s {s}: {integral}"
                ),
            }
        }
    }
}

/// Upper quantile of chi^2 with k degrees of freedom at z standard normals (Wilson-Hilferty).
fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

/// Chi-squared test of each sampling routine against its pdf, as pbrt and Mitsuba do, through
/// `rtis warptest`'s machinery: histogram 500000 samples on its 20 x 40 (cos theta, phi) grid of
/// the sphere, integrate the pdf over each cell, pool cells expecting fewer than 5, and reject
/// at p = 1e-4 (z = 3.72).
#[test]
fn samplers_match_their_pdfs_chi_squared() {
    let count = 500_000;
    let cases: Vec<(Phong, Vec3A, Sampling)> = vec![
        (
            Phong {
                kd: Vec3A::ONE,
                ks: Vec3A::ZERO,
                shininess: 1.0,
            },
            Vec3A::Z,
            Sampling::Uniform,
        ),
        (
            Phong {
                kd: Vec3A::ONE,
                ks: Vec3A::ZERO,
                shininess: 1.0,
            },
            Vec3A::Z,
            Sampling::Cosine,
        ),
        (
            Phong {
                kd: Vec3A::splat(0.5),
                ks: Vec3A::splat(0.5),
                shininess: 10.0,
            },
            Vec3A::new(0.6, 0.0, 0.8).normalize(),
            Sampling::Brdf,
        ),
        (
            Phong {
                kd: Vec3A::splat(0.1),
                ks: Vec3A::splat(0.8),
                shininess: 60.0,
            },
            Vec3A::new(0.0, -0.5, 0.866).normalize(),
            Sampling::Brdf,
        ),
    ];
    for (phong, wo, sampling) in cases {
        let case = warptest::direction_case("", phong, wo, sampling);
        let o = warptest::run(&case, count, 42);
        let (chi2, dof) = (o.chi2, o.dof);
        let limit = chi2_quantile(dof as f64, 3.72);
        assert!(
            chi2 < limit,
            "{sampling:?} s {}: chi2 {chi2:.1} with {dof} dof, limit {limit:.1}",
            phong.shininess
        );
    }
}

/// The physically based Cornell box against Mitsuba 3's render of the same scene
/// (`tests/data/REFERENCE-README.md`: 4096 spp, per-pixel noise RMSE 0.0069; mirrored
/// left-right). We render it twice with different seeds (A, B) and compare on 4x4 blocks:
/// our block noise is estimated from A - B, the reference's from its stated RMSE. If both
/// estimate the same image, mean((A+B)/2 - R)^2 = var_ours / 2 + var_ref; we allow 1.5 times
/// that. Also the image means agree within 1%.
#[test]
fn cornell_box_matches_mitsuba() {
    let text = std::fs::read_to_string(scenes_dir().join("cornell-physical.ron")).unwrap();
    let mut s = scene(&text);
    s.settings.film.spp = 16;
    let a = common::render_scene(&s);
    s.settings.seed = 1234;
    let b = common::render_scene(&s);
    let reference = common::mitsuba_reference("cornell_rtis_diffuse_360x288_dinf_spp4096.exr");
    let (mse, noise) = common::block_mse(&a.image, &b.image, &reference, 0.0069, &|_, _| false);
    let allowed = 1.5 * noise;
    eprintln!("block MSE vs Mitsuba {mse:.3e}; noise explains {noise:.3e}; allowed {allowed:.3e}");
    assert!(
        mse < allowed,
        "block MSE {mse:.3e} exceeds {allowed:.3e}: the images differ beyond noise"
    );
    let (ma, mr) = (
        (a.image.mean() + b.image.mean()) * 0.5,
        Vec3A::new(0.3403, 0.3254, 0.2880),
    );
    assert!(
        ((ma - mr) / mr).abs().max_element() < 0.01,
        "mean {ma} vs Mitsuba {mr}"
    );
}

/// Physical glass carries radiance across an interface by `(n_wo / n_wi)^2`. A camera in air
/// looks straight down at a glass half-space (an infinite plane of index `n`) under a uniform
/// background of 1: each sample reflects with probability F and sees 1, or refracts and sees
/// `1 / n^2`, so the pixel's expectation is `F + (1 - F) / n^2` with `F = ((n - 1)/(n + 1))^2`
/// (Mitsuba 3 gives 0.468 for n = 1.5). Tolerance: 5 standard errors of the per-pixel means
/// (one sample per pixel, 4096 pixels), which also checks that reflection is chosen with
/// probability F.
#[test]
fn physical_glass_half_space_from_air() {
    for n in [1.2f64, 1.5, 2.4] {
        let r = render_str(&format!(
            r#"Scene(film: (width: 64, height: 64), model: Physical, background: (1, 1, 1),
            camera: Orthographic(position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 0.5),
            shader: Path(),
            entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Transmissive(ior: {n}))])"#
        ));
        let f = ((n - 1.0) / (n + 1.0)).powi(2);
        let expected = f + (1.0 - f) / (n * n);
        let (mean, se) = common::mean_and_se(&r);
        let reflected =
            r.stats.reflection as f64 / (r.stats.reflection + r.stats.refraction) as f64;
        assert!(
            (mean - expected).abs() < 5.0 * se.max(1e-6),
            "n = {n}: {mean} +- {se}, expected {expected}"
        );
        let se_f = (f * (1.0 - f) / 4096.0).sqrt();
        assert!(
            (reflected - f).abs() < 5.0 * se_f,
            "n = {n}: reflected {reflected}, F = {f}"
        );
    }
}

/// A camera at the centre of a glass ball of index `n` under a uniform background of 1: every
/// path leaves the ball through one refraction (after any number of reflections inside), so
/// every sample is `n^2` (Mitsuba 3 gives 2.25 for n = 1.5). Paths that Russian roulette ends
/// are rare (normal incidence, F = 0.04): tolerance 1e-3 relative.
#[test]
fn physical_glass_ball_from_inside() {
    for n in [1.2f64, 1.5, 2.4] {
        let r = render_str(&format!(
            r#"Scene(film: (width: 32, height: 32), model: Physical, background: (1, 1, 1),
            camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), fov: 90),
            shader: Path(),
            entities: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: Transmissive(ior: {n}))])"#
        ));
        let (mean, _) = common::mean_and_se(&r);
        assert!(
            (mean / (n * n) - 1.0).abs() < 1e-3,
            "n = {n}: {mean}, expected {}",
            n * n
        );
    }
}

/// Albedo above one: under the Physical model a Phong surface with `kd + ks > 1` would create
/// energy and a path tracer would diverge in a closed scene; extraction scales it so that
/// `kd + ks = 1` (with a warning), and the render equals the scaled material's exactly. Under
/// the Course model the material stays as written.
#[test]
fn physical_albedo_above_one_is_scaled() {
    let text = |model: &str, kd: f32, ks: f32| {
        format!(
            r#"Scene(film: (width: 16, height: 16), model: {model}, background: (1, 1, 1),
            camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1)), shader: Path(),
            entities: [(shape: Sphere(center: (0, 0, 0), radius: 3), material: Phong(kd: ({kd}, {kd}, {kd}), ks: ({ks}, {ks}, {ks}), shininess: 10))])"#
        )
    };
    let over = scene(&text("Physical", 1.0, 0.6));
    let p = rtis::extract(&over);
    assert!(
        p.warnings.iter().any(|w| w.contains("scaled")),
        "{:?}",
        p.warnings
    );
    let rtis::material::Material::Phong(m) = p.materials[0] else {
        panic!("a Phong material")
    };
    assert!(((m.kd + m.ks) - Vec3A::ONE).abs().max_element() < 1e-6);
    let a = common::render_scene(&over);
    let b = render_str(&text("Physical", 0.625, 0.375));
    let worst = a
        .image
        .pixels
        .iter()
        .zip(&b.image.pixels)
        .map(|(x, y)| (*x - *y).abs().max_element())
        .fold(0.0, f32::max);
    assert!(worst < 1e-5, "{worst}");
    let course = rtis::extract(&scene(&text("Course", 1.0, 0.6)));
    assert!(course.warnings.is_empty(), "{:?}", course.warnings);
}

/// The normalised Phong lobe integrates to its coefficient: at normal incidence the lobe about
/// the mirror direction lies wholly above the surface, and `int (s + 2) / (2 pi) cos^s cos dw`
/// is exactly 1, so the albedo is `kd + ks` (midpoint quadrature in `cos theta`, 20000 steps,
/// several exponents; an exponent off by one gives `(s + 1) / (s + 2)` instead).
#[test]
fn phong_lobe_albedo_at_normal_incidence_is_exact() {
    let n = Vec3A::Z;
    for s in [0.0f32, 1.0, 10.0, 100.0, 1000.0] {
        for (kd, ks) in [(0.0f32, 1.0f32), (0.3, 0.6)] {
            let p = Phong {
                kd: Vec3A::splat(kd),
                ks: Vec3A::splat(ks),
                shininess: s,
            };
            // Rotationally symmetric about n: int over phi is 2 pi; midpoint rule in mu.
            let steps = 20_000;
            let mut albedo = 0.0f64;
            for i in 0..steps {
                let mu = (i as f64 + 0.5) / steps as f64;
                let wi = Vec3A::new((1.0 - mu * mu).sqrt() as f32, 0.0, mu as f32);
                albedo += p.brdf(wi, n, n).x as f64 * mu / steps as f64;
            }
            albedo *= 2.0 * std::f64::consts::PI;
            let exact = (kd + ks) as f64;
            assert!(
                (albedo - exact).abs() < 2e-3 * exact.max(1.0),
                "s {s}: {albedo} vs {exact}"
            );
        }
    }
}

/// Russian roulette from the first bounce stays unbiased: the white furnace (albedo 0.8 under
/// a sky of 1, cosine sampling) with `rr_depth: 0` converges to 0.8, 5 standard errors.
#[test]
fn furnace_with_russian_roulette_from_the_first_bounce() {
    let r = render_str(
        r#"Scene(
            film: (width: 16, height: 16, spp: 64),
            camera: Perspective(position: (0, 0, -3), look_at: (0, 0, 0), fov: 30),
            shader: Path(rr_depth: 0, sampling: Cosine),
            model: Physical,
            background: (1, 1, 1),
            entities: [(shape: Sphere(center: (0, 0, 0), radius: 1.5), material: Phong(kd: (0.8, 0.8, 0.8)))],
        )"#,
    );
    // Each path survives its bounce with q = 0.8 and weighs 0.8 / 0.8 = 1 then, 0 otherwise:
    // a Bernoulli(0.8) per sample, variance 0.16; 64 x 256 samples.
    let mean = r.image.mean().x as f64;
    let se = (0.16f64 / (64.0 * 256.0)).sqrt();
    assert!(
        (mean - 0.8).abs() < 5.0 * se,
        "mean {mean}, 5 se = {}",
        5.0 * se
    );
}

/// BRDF sampling picks the diffuse lobe with probability kd / (kd + ks) (channel sums), and
/// always for a black material: exact values (a wrong choice would still be unbiased, since
/// the pdf uses the same probability, but noisier; the warptest cannot see it).
#[test]
fn brdf_sampling_picks_lobes_by_their_share() {
    let p = |kd: f32, ks: f32| Phong {
        kd: Vec3A::splat(kd),
        ks: Vec3A::splat(ks),
        shininess: 10.0,
    };
    assert!((path::diffuse_probability(&p(0.1, 0.8)) - 1.0 / 9.0).abs() < 1e-7);
    assert_eq!(path::diffuse_probability(&p(0.5, 0.5)), 0.5);
    assert_eq!(path::diffuse_probability(&p(0.0, 0.7)), 0.0);
    assert_eq!(path::diffuse_probability(&p(0.0, 0.0)), 1.0);
}
