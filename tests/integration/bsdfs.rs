//! The materials given by a BSDF (src/material/bsdf.rs and its variants): rough conductors,
//! rough dielectrics, rough plastics and plastics. Reciprocity, samples that agree with their
//! pdf, energy (white furnaces), the smooth limits, and Mitsuba 3's images of the same scenes.

use crate::common;

use crate::common::{block, render_scene, scene, scenes_dir};
use glam::Vec3A;
use proptest::prelude::*;
use rtis::material::conductor::{Conductor, Metal};
use rtis::material::microfacet::{Distribution, Microfacet, NormalSampling};
use rtis::material::plastic::Plastic;
use rtis::material::rough_conductor::RoughConductor;
use rtis::material::rough_dielectric::RoughDielectric;
use rtis::material::rough_plastic::RoughPlastic;
use rtis::material::{Bsdf, Coating, fresnel_dielectric};
use rtis::sampling::Sampler;

fn unit() -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, 0.0f32..std::f32::consts::TAU).prop_map(|(z, phi)| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3A::new(r * phi.cos(), r * phi.sin(), z)
    })
}

fn microfacet(beckmann: bool, ax: f32, ay: f32, full: bool) -> Microfacet {
    Microfacet {
        distribution: if beckmann {
            Distribution::Beckmann
        } else {
            Distribution::Ggx
        },
        alpha_x: ax,
        alpha_y: ay,
        sampling: if full {
            NormalSampling::Full
        } else {
            NormalSampling::Visible
        },
    }
}

fn dielectric(m: Microfacet, eta: f32) -> Bsdf {
    Bsdf::RoughDielectric(RoughDielectric {
        microfacet: m,
        eta,
        specular_reflectance: Vec3A::ONE,
        specular_transmittance: Vec3A::ONE,
    })
}

fn plastic(eta: f32, rho: Vec3A, nonlinear: bool) -> Bsdf {
    Bsdf::Plastic(Plastic {
        coating: Coating::smooth(eta, rho, Vec3A::ONE, nonlinear),
    })
}

fn rough_plastic(m: Microfacet, eta: f32, rho: Vec3A, nonlinear: bool) -> Bsdf {
    Bsdf::RoughPlastic(RoughPlastic::new(
        Microfacet {
            alpha_y: m.alpha_x,
            ..m
        },
        eta,
        rho,
        Vec3A::ONE,
        nonlinear,
    ))
}

/// One BSDF of each kind from the strategy's numbers.
fn any_bsdf() -> impl Strategy<Value = Bsdf> {
    (
        0usize..4,
        any::<bool>(),
        any::<bool>(),
        prop_oneof![Just(1e-4f32), Just(1.0f32), 1e-3f32..1.0],
        prop_oneof![Just(1e-4f32), Just(1.0f32), 1e-3f32..1.0],
        prop_oneof![
            Just(1.0001f32),
            Just(4.0f32),
            Just(1.0 / 1.33f32),
            0.3f32..3.0
        ],
        0.0f32..1.0,
    )
        .prop_map(|(kind, beckmann, full, ax, ay, eta, rho)| {
            let m = microfacet(beckmann, ax, ay, full);
            let rho = Vec3A::new(rho, 0.5 * rho, 1.0 - rho);
            match kind {
                0 => {
                    let (eta, k) = Metal::Au.eta_k();
                    Bsdf::RoughConductor(RoughConductor {
                        microfacet: m,
                        metal: Conductor {
                            eta,
                            k,
                            specular_reflectance: Vec3A::ONE,
                        },
                    })
                }
                1 => dielectric(m, eta),
                2 => rough_plastic(m, eta, rho, full),
                _ => plastic(eta, rho, full),
            }
        })
}

/// A BSDF's smallest roughness (1 for the smooth plastic, whose base is diffuse).
fn smallest_alpha(b: &Bsdf) -> f32 {
    b.microfacet().map_or(1.0, |m| m.alpha_x.min(m.alpha_y))
}

/// The index of refraction on the side of `w` for a dielectric of relative index `eta` (1
/// outside, `eta` inside); 1 on both sides for the others.
fn index(b: &Bsdf, w: Vec3A) -> f32 {
    match b {
        Bsdf::RoughDielectric(d) if w.z < 0.0 => d.eta,
        _ => 1.0,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    /// Reciprocity: `f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2` with the cosine taken out (Veach
    /// 1997, eq. 5.14: the indices are 1 except inside a dielectric, whose radiance BTDF
    /// carries `1 / eta'^2`), for every BSDF at roughness 1e-4 to 1 and indices 1.0001 to 4;
    /// `f` is finite and non-negative. Tolerance 1e-3 relative, for directions 3e-2 or more
    /// from the horizon (at `wo.z` = 0.0104 a Beckmann dielectric of index 4 and roughness 1
    /// gave 0.12%: the cosine divided out there is as ill-conditioned) and from the horizon of
    /// their (generalised) half vector's facet, `n_o wo + n_i wi`: a direction grazing the facet is refracted near total internal
    /// reflection, where the transmitted cosine `sqrt(1 - eta^2 sin^2)` is ill-conditioned (its
    /// relative error grows as `1 / cos^2`), so single precision cannot give both directions
    /// 1e-3 (seen: 0.15% at `|wi.wm|` = 0.007, and at 0.0107, where moving `wi` by 1e-6 moved
    /// `f(wo, wi)` by 0.4%).
    #[test]
    fn every_bsdf_is_reciprocal(b in any_bsdf(), wo in unit(), wi in unit()) {
        let (a, c) = (b.eval(wo, wi), b.eval(wi, wo));
        prop_assert!(a.is_finite() && a.min_element() >= 0.0, "{a}");
        let wm = (index(&b, wo) * wo + index(&b, wi) * wi).normalize_or_zero();
        let off_facet_horizon = wo.dot(wm).abs() > 3e-2 && wi.dot(wm).abs() > 3e-2;
        if wo.z.abs() > 3e-2 && wi.z.abs() > 3e-2 && off_facet_horizon {
            let no2 = index(&b, wo).powi(2);
            let ni2 = index(&b, wi).powi(2);
            let (fa, fc) = (a / wi.z.abs() / no2, c / wo.z.abs() / ni2);
            prop_assert!(
                (fa - fc).abs().max_element() <= 1e-3 * fa.max_element().max(fc.max_element()).max(1e-3),
                "{b:?}: {fa} vs {fc}"
            );
        }
    }

    /// Reciprocity where the lobes are: `wi` drawn from the BSDF itself (near the mirror or
    /// refracted direction, where random pairs rarely fall at low roughness), roughness 1e-2
    /// to 1, indices from 5% away from 1. Same tolerance and facet-horizon margin as above.
    #[test]
    fn every_bsdf_is_reciprocal_on_its_lobes(
        b in any_bsdf(), wo in unit(), uc in 0.0f32..1.0, u1 in 0.0f32..1.0, u2 in 0.0f32..1.0,
    ) {
        let Some(s) = b.sample(wo, uc, u1, u2) else { return Ok(()) };
        let wi = s.wi;
        let alpha = smallest_alpha(&b);
        // An index within 5% of 1 refracts almost straight on, where the generalised half
        // vector `wo + eta' wi` cancels to a length near |eta' - 1|: its rounding, about
        // 1e-7 / |eta' - 1| (1e-3 at 1.0001), differs between the two orders.
        let near_one = matches!(b, Bsdf::RoughDielectric(d) if (d.eta - 1.0).abs() < 0.05 || (1.0 / d.eta - 1.0).abs() < 0.05);
        if s.delta || near_one || alpha < 1e-2 || wo.z.abs() <= 1e-2 || wi.z.abs() <= 1e-2 {
            return Ok(());
        }
        // Off the horizon of the (generalised) half vector's facet, as above: 3e-2 or more
        // (seen: 0.14% at `|wo.wm|` = 0.020 for a GGX dielectric of index 2.24).
        let wm = (index(&b, wo) * wo + index(&b, wi) * wi).normalize_or_zero();
        if wo.dot(wm).abs() <= 3e-2 || wi.dot(wm).abs() <= 3e-2 {
            return Ok(());
        }
        let (a, c) = (b.eval(wo, wi), b.eval(wi, wo));
        let (fa, fc) = (a / wi.z.abs() / index(&b, wo).powi(2), c / wo.z.abs() / index(&b, wi).powi(2));
        prop_assert!(
            (fa - fc).abs().max_element() <= 1e-3 * fa.max_element().max(fc.max_element()).max(1e-3),
            "{b:?}: {fa} vs {fc}"
        );
    }

    /// A sample's weight is `eval / pdf` and its density the one `pdf` gives (delta lobes
    /// aside), where single precision tells them apart (roughness 0.01 or more, 0.05 or more
    /// in cosine from the horizon; see `rough_conductor_samples_agree_with_its_pdf`); at every
    /// roughness and angle, nothing is NaN or infinite and the weight is non-negative. Tolerance
/// 2e-3 relative.
    #[test]
    fn samples_agree_with_the_pdf(
        b in any_bsdf(), wo in unit(), uc in 0.0f32..1.0, u1 in 0.0f32..1.0, u2 in 0.0f32..1.0,
    ) {
        let Some(s) = b.sample(wo, uc, u1, u2) else { return Ok(()) };
        prop_assert!(s.pdf > 0.0 && s.weight.is_finite() && s.weight.min_element() >= 0.0, "{s:?}");
        prop_assert!((s.wi.length() - 1.0).abs() < 1e-3, "{s:?}");
        if s.delta {
            return Ok(());
        }
        let (pdf, f) = (b.pdf(wo, s.wi), b.eval(wo, s.wi));
        prop_assert!(pdf.is_finite() && f.is_finite());
        let rough = smallest_alpha(&b);
        // The dielectric's sample takes its value and density from `eval` and `pdf` themselves
        // (MIS needs one density per direction), so they agree at any index.
        let exact = matches!(b, Bsdf::RoughDielectric(_));
        if exact {
            prop_assert_eq!(pdf, s.pdf);
        }
        if rough >= 0.01 && wo.z.abs() >= 0.05 && s.wi.z.abs() >= 0.05 {
            prop_assert!((pdf - s.pdf).abs() <= 2e-3 * s.pdf, "{b:?}: {pdf} vs {}", s.pdf);
            let want = f / s.pdf;
            prop_assert!(
                (want - s.weight).abs().max_element() <= 2e-3 * want.max_element().max(1e-3),
                "{want} vs {}", s.weight
            );
        }
    }
}

/// The mean and standard error of `n` sample weights (0 for a sample that fails), each
/// passed through `g` with the sample's direction.
fn mean_weight(
    b: &Bsdf,
    wo: Vec3A,
    n: usize,
    seed: u64,
    g: impl Fn(Vec3A, Vec3A) -> f64,
) -> (f64, f64) {
    let mut s = Sampler::new(seed, 0, 0);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let uc = s.next_f32();
        let (u1, u2) = s.next_2d();
        if let Some(smp) = b.sample(wo, uc, u1, u2) {
            let w = g(smp.weight, smp.wi);
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    (
        mean,
        ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

/// A unit direction at `theta` degrees from the normal (on the side of `side`), azimuth 0.4.
fn at(theta: f32, side: f32) -> Vec3A {
    let (t, p) = (theta.to_radians(), 0.4f32);
    Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), side * t.cos())
}

/// `F_dr` from inside a smooth coating of relative index `eta`, `2 int F(mu) mu dmu`, by
/// Simpson's rule on 100,000 intervals in double precision (independent of the renderer's
/// quadrature).
fn diffuse_fresnel(eta: f32) -> f64 {
    let n = 100_000;
    let g = |mu: f64| {
        let eta = eta as f64;
        let s2 = eta * eta * (1.0 - mu * mu);
        if s2 >= 1.0 {
            return mu;
        }
        let ct = (1.0 - s2).sqrt();
        let rs = (eta * mu - ct) / (eta * mu + ct);
        let rp = (mu - eta * ct) / (mu + eta * ct);
        0.5 * (rs * rs + rp * rp) * mu
    };
    let h = 1.0 / n as f64;
    let sum: f64 = (0..=n)
        .map(|j| {
            let w = if j == 0 || j == n {
                1.0
            } else if j % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * g(j as f64 * h)
        })
        .sum();
    2.0 * sum * h / 3.0
}

/// White furnace of the smooth plastic: with a white base and coating (`rho = 1`,
/// `specular_reflectance = 1`) it reflects exactly what it receives, `F + (1 - F) (1 - F_dr)
/// / (1 - F_dr) = 1`, linear or not, at every angle and index (the coating's transmittance
/// into the base, `(1 - F_dr_ext) / eta^2`, equals `1 - F_dr_int`: reciprocity). With a grey
/// base and `nonlinear` it reflects `F + (1 - F) rho (1 - F_dr) / (1 - rho F_dr)`, the sum of
/// the bounces under the coating. Tolerance: 5 standard errors of 200,000 samples plus 3e-4
/// (the renderer's quadrature of `F_dr`).
#[test]
fn white_plastic_reflects_everything() {
    for eta in [1.0001f32, 1.33, 1.49, 2.4, 4.0] {
        for theta in [0.0f32, 45.0, 80.0] {
            let wo = at(theta, 1.0);
            for nonlinear in [false, true] {
                let (m, se) = mean_weight(
                    &plastic(eta, Vec3A::ONE, nonlinear),
                    wo,
                    200_000,
                    3,
                    |w, _| w.x as f64,
                );
                assert!(
                    (m - 1.0).abs() < 5.0 * se + 3e-4,
                    "eta {eta} theta {theta}: {m} +- {se}"
                );
            }
            let rho = 0.4;
            let f = fresnel_dielectric(wo.z, 1.0 / eta) as f64;
            let (m, se) = mean_weight(
                &plastic(eta, Vec3A::splat(rho), true),
                wo,
                200_000,
                4,
                |w, _| w.x as f64,
            );
            // The bounces under the coating: rho (1 - F_dr) sum (rho F_dr)^k.
            let fdr = diffuse_fresnel(eta);
            let rho = rho as f64;
            let want = f + (1.0 - f) * rho * (1.0 - fdr) / (1.0 - rho * fdr);
            assert!(
                (m - want).abs() < 5.0 * se + 3e-4,
                "eta {eta} theta {theta}: {m} vs {want}"
            );
        }
    }
}

/// The rough dielectric keeps at most the energy it receives: reflection plus transmission,
/// the radiance scaling `1 / eta'^2` taken back out of the transmitted weights, is at most 1
/// (5 standard errors of 200,000 samples), and loses only what single scattering loses: at
/// alpha 1e-4 it is 1 (to 1e-3), as the smooth interface, and the share reflected is the
/// Fresnel term (5 standard errors). From both sides, past the critical angle inside.
#[test]
fn rough_dielectric_conserves_energy() {
    for beckmann in [false, true] {
        for alpha in [1e-4f32, 0.1, 0.5, 1.0] {
            for eta in [1.0001f32, 1.5, 4.0] {
                let b = dielectric(microfacet(beckmann, alpha, alpha, false), eta);
                for (theta, side) in [
                    (0.0, 1.0),
                    (60.0, 1.0),
                    (85.0, 1.0),
                    (20.0, -1.0),
                    (70.0, -1.0),
                ] {
                    let wo = at(theta, side);
                    let etap = if side > 0.0 { eta } else { 1.0 / eta };
                    let energy = |w: Vec3A, wi: Vec3A| {
                        let scale = if wi.z * wo.z < 0.0 { etap * etap } else { 1.0 };
                        (w.x * scale) as f64
                    };
                    let (e, se) = mean_weight(&b, wo, 200_000, 5, energy);
                    assert!(
                        e <= 1.0 + 5.0 * se + 1e-4,
                        "{beckmann} {alpha} {eta} {theta} {side}: {e}"
                    );
                    if alpha == 1e-4 {
                        assert!(
                            (e - 1.0).abs() < 1e-3,
                            "{beckmann} {eta} {theta} {side}: {e}"
                        );
                        let f = fresnel_dielectric(wo.z.abs(), 1.0 / etap) as f64;
                        let (r, se) =
                            mean_weight(&b, wo, 200_000, 6, |_, wi| f64::from(wi.z * wo.z > 0.0));
                        assert!(
                            (r - f).abs() < 5.0 * se + 1e-4,
                            "{beckmann} {eta} {theta} {side}: reflects {r}, F {f}"
                        );
                    }
                }
            }
        }
    }
}

/// The rough plastic keeps at most what it receives (white base and coating: 5 standard
/// errors of 200,000 samples), and as alpha goes to 0 its albedo becomes the smooth plastic's (to 5e-3: the
/// coating's transmittance is tabulated on 32 cosines, each by quadrature over normals).
#[test]
fn rough_plastic_albedo_is_at_most_one() {
    for beckmann in [false, true] {
        for theta in [0.0f32, 50.0, 80.0] {
            let wo = at(theta, 1.0);
            let smooth = mean_weight(&plastic(1.49, Vec3A::ONE, false), wo, 200_000, 7, |w, _| {
                w.x as f64
            })
            .0;
            for alpha in [1e-4f32, 0.1, 0.5, 1.0] {
                let b = rough_plastic(
                    microfacet(beckmann, alpha, alpha, false),
                    1.49,
                    Vec3A::ONE,
                    false,
                );
                let (e, se) = mean_weight(&b, wo, 200_000, 8, |w, _| w.x as f64);
                assert!(
                    e <= 1.0 + 5.0 * se,
                    "{beckmann} {alpha} {theta}: {e} +- {se}"
                );
                if alpha == 1e-4 {
                    assert!(
                        (e - smooth).abs() < 5e-3 + 5.0 * se,
                        "{beckmann} {theta}: {e} vs smooth {smooth}"
                    );
                }
            }
        }
    }
}

/// The Path shader's image of a scene with `material` in place of `MATERIAL`, at `spp`,
/// seed `seed`.
fn render_with(text: &str, material: &str, spp: u32, seed: u64) -> rtis::render::film::Image {
    let mut s = scene(&text.replace("MATERIAL", material));
    s.settings.film.spp = spp;
    s.settings.seed = seed;
    render_scene(&s).image
}

/// `mean over 4x4 blocks of (block(a) - block(b))^2` and what the noise of the two renders
/// explains of it (each render's noise from two seeds).
fn blocks_agree(
    a: [&rtis::render::film::Image; 2],
    b: [&rtis::render::film::Image; 2],
) -> (f64, f64) {
    let (mut d, mut va, mut vb, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for by in 0..a[0].height / 4 {
        for bx in 0..a[0].width / 4 {
            let [a0, a1] = a.map(|i| block(i, bx, by));
            let [b0, b1] = b.map(|i| block(i, bx, by));
            let m = 0.5 * (a0 + a1) - 0.5 * (b0 + b1);
            d += m.dot(m) as f64 / 3.0;
            va += (a0 - a1).dot(a0 - a1) as f64 / 3.0;
            vb += (b0 - b1).dot(b0 - b1) as f64 / 3.0;
            n += 1.0;
        }
    }
    // Var(mean of two) = Var(one) / 2 = E[(x0 - x1)^2] / 4, for each side.
    (d / n, (va + vb) / n / 4.0)
}

/// The smooth limits in images: at alpha 1e-4 a rough gold sphere renders as the smooth gold
/// `Conductor`, a rough glass sphere as `Transmissive` glass (Physical), and a rough plastic
/// as the smooth `Plastic`, under an area light and a sky, with the Path shader. Block MSE
/// between the two within 1.5 times what their noise explains (each rendered with two seeds).
#[test]
fn rough_materials_converge_to_the_smooth_ones() {
    let text = r#"Scene(
        film: (width: 48, height: 48, spp: 64),
        camera: Perspective(position: (0, 1, -3), look_at: (0, 0.4, 0), fov: 40),
        shader: Path(rr_depth: 5), model: Physical, background: (0.3, 0.4, 0.5),
        entities: [
            (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (0.5, 0.4, 0.3))),
            (shape: Rectangle(corner: (-1, 3, -1), u: (2, 0, 0), v: (0, 0, 2)), emitter: Emitter(radiance: (4, 4, 4))),
            (shape: Sphere(center: (0, 0.6, 0), radius: 0.6), material: MATERIAL),
        ])"#;
    for distribution in ["Ggx", "Beckmann"] {
        for (rough, smooth) in [
            (
                "RoughConductor(alpha: 1e-4, material: \"Au\")",
                "Conductor(material: \"Au\")",
            ),
            (
                "RoughDielectric(alpha: 1e-4, int_ior: 1.5, ext_ior: 1)",
                "Transmissive(ior: 1.5)",
            ),
            (
                "RoughPlastic(alpha: 1e-4, diffuse_reflectance: (0.2, 0.4, 0.8))",
                "Plastic(diffuse_reflectance: (0.2, 0.4, 0.8))",
            ),
        ] {
            let rough = rough.replace("alpha:", &format!("distribution: {distribution}, alpha:"));
            let r = [1, 2].map(|seed| render_with(text, &rough, 64, seed));
            let s = [3, 4].map(|seed| render_with(text, smooth, 64, seed));
            let (mse, noise) = blocks_agree([&r[0], &r[1]], [&s[0], &s[1]]);
            assert!(
                mse < 1.5 * noise,
                "{rough} vs {smooth}: block MSE {mse:.3e}, noise {noise:.3e}"
            );
        }
    }
}

/// Mitsuba 3's images of the material previews (bench/mitsuba_materials_reference.py: 4096
/// spp, llvm_ad_rgb, noise RMSE 0.0049 and 0.0050 per pixel): rough gold, frosted glass and
/// rough plastic at three roughnesses, GGX and Beckmann (with an anisotropic gold sphere and
/// the nonlinear plastic), over a smooth plastic floor. rtis renders each twice (64 spp); on
/// 4x4 blocks, the mean squared difference from Mitsuba is within 1.5 times what the two
/// noises explain (as `cornell_box_matches_mitsuba`), and the image means agree within 1%.
#[test]
fn material_previews_match_mitsuba() {
    for (file, reference, noise, mean) in [
        (
            "materials.ron",
            "mitsuba_materials_192x128_spp4096.exr",
            0.00489,
            Vec3A::new(0.293913, 0.31427, 0.351037),
        ),
        (
            "materials-beckmann.ron",
            "mitsuba_materials_beckmann_192x128_spp4096.exr",
            0.00502,
            Vec3A::new(0.298891, 0.317717, 0.352895),
        ),
    ] {
        let text = std::fs::read_to_string(scenes_dir().join(file)).unwrap();
        let mut s = scene(&text);
        s.settings.film.spp = 64;
        let a = render_scene(&s);
        s.settings.seed = 4321;
        let b = render_scene(&s);
        let r = common::mitsuba_reference(reference);
        let (mse, explained) = common::block_mse(&a.image, &b.image, &r, noise, &|_, _| false);
        eprintln!("{file}: block MSE vs Mitsuba {mse:.3e}; noise explains {explained:.3e}");
        assert!(
            mse < 1.5 * explained,
            "{file}: block MSE {mse:.3e} vs {explained:.3e}"
        );
        let m = (a.image.mean() + b.image.mean()) * 0.5;
        assert!(
            ((m - mean) / mean).abs().max_element() < 0.01,
            "{file}: mean {m} vs {mean}"
        );
    }
}

/// Next-event estimation reads the BSDF in its frame: a `Plastic` floor straight under a point
/// light of intensity `I` at height `d`, seen straight down by an orthographic camera, shows
/// `I / d^2 rho / (1 - F_dr) / pi (1 - F0)^2 / eta^2` in every pixel near the centre (the
/// coating's mirror is a delta that no light sample finds; nothing else is in the scene, the
/// sky is black), in Direct and in Path (whose sampled rays escape). `F0 = ((eta - 1) / (eta +
/// 1))^2`. Tolerance 1e-3 relative (the pixels sit up to 0.02 from the axis: cosines within
/// 2e-4 of 1, distances within 1e-4 of d).
#[test]
fn direct_light_on_a_plastic_is_exact() {
    let (eta, rho, i, d) = (1.5f64, 0.6f64, 10.0f64, 2.0f64);
    let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let want = i / (d * d) * rho / (1.0 - diffuse_fresnel(eta as f32)) / std::f64::consts::PI
        * (1.0 - f0).powi(2)
        / (eta * eta);
    for shader in ["Direct()", "Path()"] {
        let r = common::render_str(&format!(
            r#"Scene(
                film: (width: 8, height: 8, spp: 4),
                camera: Orthographic(position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 0.04),
                shader: {shader}, model: Physical,
                entities: [
                    (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Plastic(int_ior: {eta}, ext_ior: 1, diffuse_reflectance: ({rho}, {rho}, {rho}))),
                    (light: Point(position: (0, {d}, 0), intensity: ({i}, {i}, {i}))),
                ])"#
        ));
        for p in &r.image.pixels {
            let got = p.x as f64;
            assert!(
                (got - want).abs() < 1e-3 * want,
                "{shader}: {got} vs {want}"
            );
        }
    }
}

/// The pdf integrates to the share of samples that succeed: for a rough dielectric from both
/// sides, a rough plastic and a rough conductor (GGX and Beckmann), the bins' probabilities from
/// `pdf` (the warptest's peaked quadrature over the sphere) sum to the fraction of 200,000
/// samples that return a direction, within 5 standard errors plus 2e-3 (the quadrature).
#[test]
fn the_pdf_integrates_to_the_sampled_share() {
    for beckmann in [false, true] {
        let m = microfacet(beckmann, 0.3, 0.3, false);
        let aniso = microfacet(beckmann, 0.05, 0.6, false);
        for (b, wo) in [
            (dielectric(m, 1.5), at(60.0, 1.0)),
            (dielectric(aniso, 1.33), at(75.0, -1.0)),
            (
                rough_plastic(m, 1.49, Vec3A::splat(0.5), false),
                at(70.0, 1.0),
            ),
            (
                Bsdf::RoughConductor(RoughConductor {
                    microfacet: aniso,
                    metal: Conductor {
                        eta: Vec3A::splat(0.2),
                        k: Vec3A::splat(3.0),
                        specular_reflectance: Vec3A::ONE,
                    },
                }),
                at(80.0, 1.0),
            ),
        ] {
            let mass: f64 =
                rtis::converge::warptest::integrate_pdf_peaked(|wi| b.pdf(wo, wi) as f64)
                    .iter()
                    .sum();
            let (share, se) = mean_weight(&b, wo, 200_000, 11, |_, _| 1.0);
            assert!(
                (mass - share).abs() < 5.0 * se + 2e-3,
                "{b:?}: pdf integrates to {mass}, {share} of samples succeed"
            );
        }
    }
}

/// Rays cross a rough glass plane: a camera in air looks straight down at a half-space of
/// rough glass (an infinite plane, `RoughDielectric` of index `n`, GGX and Beckmann at alpha
/// 1e-4 and 0.3) under a uniform sky of 1. At alpha 1e-4 a sample reflects with probability
/// `F` and sees 1, or refracts and sees `1 / n^2`: the pixel's expectation is `F + (1 - F) /
/// n^2`, as for smooth glass (`physical_glass_half_space_from_air`); at alpha 0.3 the same
/// energy less what single scattering loses, between `1 / n^2` and that value. A plane taken
/// for one that no ray crosses would send the refracted rays back into it. Tolerance: 5
/// standard errors of the pixels' mean (4096 pixels, one sample each).
#[test]
fn rough_glass_planes_let_light_through() {
    for distribution in ["Ggx", "Beckmann"] {
        for n in [1.2f64, 1.5, 2.4] {
            let f = ((n - 1.0) / (n + 1.0)).powi(2);
            let smooth = f + (1.0 - f) / (n * n);
            for alpha in [1e-4, 0.3] {
                let r = common::render_str(&format!(
                    r#"Scene(film: (width: 64, height: 64), model: Physical, background: (1, 1, 1),
                    camera: Orthographic(position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 0.5),
                    shader: Path(),
                    entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: RoughDielectric(distribution: {distribution}, alpha: {alpha}, int_ior: {n}, ext_ior: 1))])"#
                ));
                let (mean, se) = common::mean_and_se(&r);
                let tol = 5.0 * se.max(1e-6);
                if alpha < 1e-3 {
                    assert!(
                        (mean - smooth).abs() < tol,
                        "{distribution} n {n}: {mean} +- {se}, expected {smooth}"
                    );
                } else {
                    assert!(
                        mean > 1.0 / (n * n) - tol && mean < smooth + tol,
                        "{distribution} n {n} alpha {alpha}: {mean} +- {se}, not in [{}, {smooth}]",
                        1.0 / (n * n)
                    );
                }
            }
        }
    }
}

/// Point lights behind rough glass are chosen too: a rough glass sphere between two point
/// lights, seen by the camera, renders the same expectation with every light at every vertex
/// (`All`) as with one light chosen by importance at each vertex (`Importance`, which must
/// weigh a light behind a transmitting surface by `|cos|`). Image means within 5 standard
/// errors (from two seeds each) plus 0.5%.
#[test]
fn importance_sees_lights_behind_rough_glass() {
    let render = |per_vertex: &str, seed: u64| {
        let mut s = scene(&format!(
            r#"Scene(
                film: (width: 32, height: 32, spp: 64),
                camera: Perspective(position: (0, 0, -3), look_at: (0, 0, 0), fov: 40),
                shader: Path(lights_per_vertex: {per_vertex}), model: Physical,
                entities: [
                    (shape: Sphere(center: (0, 0, 0), radius: 0.8), material: RoughDielectric(alpha: 0.3, int_ior: 1.5, ext_ior: 1)),
                    (light: Point(position: (0.5, 0.5, 2), intensity: (20, 20, 20))),
                    (light: Point(position: (-1, 1, -2), intensity: (5, 5, 5))),
                ])"#
        ));
        s.settings.seed = seed;
        render_scene(&s).image.mean().x as f64
    };
    let all = [render("All", 1), render("All", 2)];
    let imp = [render("Importance", 3), render("Importance", 4)];
    let (ma, mi) = ((all[0] + all[1]) / 2.0, (imp[0] + imp[1]) / 2.0);
    let spread = ((all[0] - all[1]).powi(2) + (imp[0] - imp[1]).powi(2)).sqrt() / 2.0;
    assert!(
        (ma - mi).abs() < 5.0 * spread + 5e-3 * ma,
        "All {all:?} vs Importance {imp:?}"
    );
}

/// Russian roulette reads the throughput without glass's radiance scaling: a camera in air
/// looks straight down at a half-space of glass of index 2.4 (smooth `Transmissive`, and
/// `RoughDielectric` at alpha 1e-4) under a sky of 1, with roulette from the first bounce
/// (`rr_depth: 0`). A refracted path carries `1 / n^2 = 0.17`; roulette on that would end 83%
/// of them, on the throughput without it (1) only 5%. So of 4096 one-sample pixels, those
/// that see nothing are `(1 - F) 0.05` of them (F = 0.17): at most 8%, where roulette on the
/// scaled throughput would leave 69% black. The mean stays `F + (1 - F) / n^2` (5 standard
/// errors).
#[test]
fn roulette_ignores_the_radiance_scaling_of_glass() {
    let n = 2.4f64;
    for material in [
        format!("Transmissive(ior: {n})"),
        format!("RoughDielectric(alpha: 1e-4, int_ior: {n}, ext_ior: 1)"),
    ] {
        let r = common::render_str(&format!(
            r#"Scene(film: (width: 64, height: 64), model: Physical, background: (1, 1, 1),
            camera: Orthographic(position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 0.5),
            shader: Path(rr_depth: 0),
            entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: {material})])"#
        ));
        let black = r.image.pixels.iter().filter(|p| p.x == 0.0).count() as f64
            / r.image.pixels.len() as f64;
        assert!(black < 0.08, "{material}: {black} of the pixels black");
        let f = ((n - 1.0) / (n + 1.0)).powi(2);
        let want = f + (1.0 - f) / (n * n);
        let (mean, se) = common::mean_and_se(&r);
        assert!(
            (mean - want).abs() < 5.0 * se,
            "{material}: {mean} +- {se} vs {want}"
        );
    }
}
