//! The converge sweep: rungs, metrics and outputs.

use crate::common::scene;
use rtis::RenderScene;
use rtis::converge::{self, metrics};
use rtis::render::{film::Image, render};
use rtis::sampling::SamplerKind;

fn small_box() -> RenderScene {
    let mut s = rtis::scene::load_default();
    s.settings.film.width = 24;
    s.settings.film.height = 20;
    rtis::extract(&s)
}

#[test]
fn metrics_are_exact_on_known_images() {
    let a = Image::new(2, 1);
    let mut b = Image::new(2, 1);
    b.pixels[0] = glam::Vec3A::splat(0.3);
    // Half the pixels off by 0.3 in every channel: RMSE = sqrt(0.09 / 2).
    assert!((metrics::rmse(&a, &b) - (0.045f64).sqrt()).abs() < 1e-7);
    assert_eq!(metrics::rmse(&b, &b), 0.0);
    // relMSE: pixel 0 is (0 - 0.3)^2 / (0.09 + 0.01) = 0.9 per channel; mean over 2 pixels.
    assert!((metrics::rel_mse(&a, &b) - 0.45).abs() < 1e-6);
}

/// The course ladder has the cheap rungs first and every Global setting; the Path curve's error
/// falls with spp (64 spp at least 3x below 1 spp against a 256-spp reference: the expected
/// ratio is sqrt(64) = 8 for the noise part); the Global curve's error stops falling (bias).
#[test]
fn course_ladder_sweeps_and_path_converges() {
    let s = small_box();
    let rungs = converge::ladder(&s);
    let labels: Vec<_> = rungs
        .iter()
        .map(|r| format!("{} {}", r.family, r.label))
        .collect();
    assert_eq!(labels[0], "Direct direct");
    assert_eq!(labels[1], "Ambient (D=0) D=0");
    assert!(labels.contains(&"Global D=3 n=64".to_string()));
    assert_eq!(rungs.len(), 2 + 9 + 4);
    let reference = render(
        &converge::with_settings(&s, converge::reference_shader(), 256),
        &|| {},
    )
    .image;
    let measured = converge::sweep(&s, &reference, 0.0, &rungs, 1, 4, &mut |_| true);
    let rows: Vec<converge::Row> = measured.iter().map(|m| m.row.clone()).collect();
    let err = |fam: &str, label: &str| {
        rows.iter()
            .find(|r| r.family == fam && r.label == label)
            .unwrap()
            .rmse
    };
    assert!(
        err("Path", "spp=64") * 3.0 < err("Path", "spp=1"),
        "{rows:#?}"
    );
    // More hemisphere samples cannot remove the Global shader's bias: n = 64 is within a
    // factor 2 of n = 16 while Path gains a factor 2 from 16 to 64 spp.
    assert!(err("Global D=2", "n=64") > 0.5 * err("Global D=2", "n=16"));
    let csv = converge::to_csv(&rows);
    assert!(
        csv.starts_with("family,setting,seconds,rays,rmse,rel_mse,flip,seeds,variance,bias2\n")
    );
    // Bias and variance: Path is unbiased, so at 64 spp its bias^2 is within noise of zero
    // (below a tenth of the Global shader's); the Global shader's error is mostly bias.
    let row = |fam: &str, label: &str| {
        rows.iter()
            .find(|r| r.family == fam && r.label == label)
            .unwrap()
    };
    let (g, p) = (row("Global D=2", "n=64"), row("Path", "spp=64"));
    assert!(g.bias2 > 2.0 * g.variance, "{g:?}");
    assert!(p.bias2.abs() < 0.1 * g.bias2, "{p:?} {g:?}");
    // The report holds every rung, the plot and the reference.
    let effects = converge::effect_prices(&s, &reference, 1);
    assert_eq!(effects[0].effect, "");
    assert!(effects.iter().any(|e| e.effect == "shadows"));
    let html = converge::report::html(&converge::report::Report {
        title: "test".into(),
        reference: &reference,
        reference_note: "a note".into(),
        rungs: &measured,
        effects: &effects,
        transfer: Default::default(),
    });
    assert_eq!(html.matches("<circle class=\"pt\"").count(), rows.len());
    assert!(html.contains("id=\"slider\"") && html.contains("a note"));
    assert!(!html.contains("src=\"http") && !html.contains("href=\"http"));
    assert_eq!(csv.lines().count(), rows.len() + 1);
    let dir = std::env::temp_dir().join(format!("rtis-conv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    converge::plot::plot(&rows, "test", &dir.join("c.png")).unwrap();
    let png = image::open(dir.join("c.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1100, 720));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn path_ladder_for_path_scenes() {
    let s = scene("Scene(film: (width: 8, height: 8), shader: Path(), entities: [])");
    let rungs = converge::ladder(&rtis::extract(&s));
    assert!(rungs.iter().all(|r| r.family.starts_with("Path")));
    // An spp curve, the same with the Sobol' sampler, and a depth curve.
    assert_eq!(rungs.len(), 5 + 5 + 4);
    let sobol: Vec<_> = rungs.iter().filter(|r| r.family == "Path Sobol'").collect();
    assert_eq!(sobol.len(), 5);
    assert!(sobol.iter().all(|r| r.sampler == Some(SamplerKind::Sobol)));
    // A film of Sobol' points gets an independent curve instead.
    let s =
        scene("Scene(film: (width: 8, height: 8, sampler: Sobol), shader: Path(), entities: [])");
    let rungs = converge::ladder(&rtis::extract(&s));
    let independent = rungs.iter().filter(|r| r.family == "Path independent");
    assert!(
        independent
            .map(|r| r.sampler)
            .eq([Some(SamplerKind::Independent); 5])
    );
}

#[test]
fn reference_key_tracks_the_scene() {
    let a = small_box();
    let mut b = a.clone();
    assert_eq!(
        converge::reference_key(&a, 64),
        converge::reference_key(&b, 64)
    );
    assert_ne!(
        converge::reference_key(&a, 64),
        converge::reference_key(&a, 128)
    );
    b.background = glam::Vec3A::splat(0.1);
    assert_ne!(
        converge::reference_key(&a, 64),
        converge::reference_key(&b, 64)
    );
    let mut c = a.clone();
    c.film.sampler = SamplerKind::Sobol;
    assert_ne!(
        converge::reference_key(&a, 64),
        converge::reference_key(&c, 64)
    );
}

/// The reference draws from streams independent of every rung: a Path rung with as many
/// samples as the reference differs from it in nearly every pixel, and its error is its noise.
#[test]
fn reference_streams_are_independent_of_the_rungs() {
    let s = small_box();
    let reference = render(&converge::reference_scene(&s, 16), &|| {}).image;
    let rung = render(
        &converge::with_settings(&s, converge::reference_shader(), 16),
        &|| {},
    )
    .image;
    let same = rung
        .pixels
        .iter()
        .zip(&reference.pixels)
        .filter(|(a, b)| a == b)
        .count();
    // Pixels that see only the black background agree whatever the streams.
    assert!(
        same * 10 < rung.pixels.len(),
        "{same} of {} pixels identical",
        rung.pixels.len()
    );
    assert!(converge::metrics::rmse(&rung, &reference) > 0.0);
}

/// Variance and bias of known images: 0.5 and 0.7 against 0.5 have per-pixel variance 0.02
/// (with K - 1 = 1) and a mean 0.1 away from the reference.
#[test]
fn variance_and_bias_of_known_images() {
    let img = |v: f32| Image {
        width: 2,
        height: 1,
        pixels: vec![glam::Vec3A::splat(v); 2],
    };
    let (var, mse) = converge::metrics::variance_and_mse_of_mean(&[img(0.5), img(0.7)], &img(0.5));
    assert!((var - 0.02).abs() < 1e-7, "{var}");
    assert!((mse - 0.01).abs() < 1e-7, "{mse}");
}

/// Each pixel's variance across seeds, for the report's variance x time map: the unbiased one,
/// the mean over channels; three seeds of 0.5, 0.7 and 0.9 in every channel give 0.04, a
/// pixel equal in every seed gives 0.
#[test]
fn pixel_variance_of_known_images() {
    let img = |v: f32| Image {
        width: 2,
        height: 1,
        pixels: vec![glam::Vec3A::splat(v), glam::Vec3A::new(0.25, 0.5, 1.0)],
    };
    let v = converge::pixel_variance(&[img(0.5), img(0.7), img(0.9)]);
    assert!((v[0] - 0.04).abs() < 1e-7, "{v:?}");
    assert_eq!(v[1], 0.0);
}

/// The decomposition's formula, exactly: two seeds at `mu + b + d` and `mu + b - d` against a
/// reference `mu` give a per-pixel variance of `2 d^2` (the unbiased one, over K - 1 = 1), a mean
/// `b` off the reference, and so `bias2 = b^2 - 2 d^2 / 2 - v_r` with the given reference noise
/// `v_r`: the seeds' variance enters divided by their count and the reference's noise is taken
/// off whole. Tolerance: rounding of f32 pixels read in f64 (1e-12).
#[test]
fn bias_and_variance_enter_as_documented() {
    let img = |f: &dyn Fn(usize) -> f32| Image {
        width: 4,
        height: 3,
        pixels: (0..12).map(|i| glam::Vec3A::splat(f(i))).collect(),
    };
    let mu = |i: usize| 0.25 + 0.0625 * i as f32;
    let (b, d, v_r) = (0.125f32, 0.0625f32, 0.001f64);
    let seeds = [img(&|i| mu(i) + b + d), img(&|i| mu(i) + b - d)];
    let parts = converge::metrics::bias_and_variance(&seeds, &img(&mu), v_r);
    let (b, d) = (b as f64, d as f64);
    assert!((parts.variance - 2.0 * d * d).abs() < 1e-12, "{parts:?}");
    assert!(
        (parts.bias2 - (b * b - d * d - v_r)).abs() < 1e-12,
        "{parts:?}: want {}",
        b * b - d * d - v_r
    );
}

/// Gaussian noise of standard deviation `sigma` (Box-Muller), added to `base`.
fn noisy(base: &Image, offset: f32, sigma: f32, s: &mut rtis::sampling::Sampler) -> Image {
    let mut normal = || {
        let (u1, u2) = s.next_2d();
        let r = (-2.0 * (1.0 - u1 as f64).ln()).sqrt();
        (r * (2.0 * std::f64::consts::PI * u2 as f64).cos()) as f32
    };
    Image {
        width: base.width,
        height: base.height,
        pixels: base
            .pixels
            .iter()
            .map(|p| {
                *p + glam::Vec3A::splat(offset)
                    + sigma * glam::Vec3A::new(normal(), normal(), normal())
            })
            .collect(),
    }
}

/// The decomposition recovers a known bias and a known noise. Synthetic images of N = 3 x
/// 160 x 160 values: a rung of k = 4 seeds at `mu + b + N(0, s^2)` (b = 0.05, s = 0.1), and a
/// reference made as `rtis converge` makes it, the pooled mean of two independent halves of
/// 8 and 24 samples of per-sample noise S = 0.4 (so its own noise is S^2 / 32 = 0.005, which
/// `pooled_noise` must find from the halves alone).
///
/// Tolerances, 5 standard errors each: the variance estimate has SE s^2 sqrt(2 / ((k - 1) N))
/// = 2.9e-5; the halves' noise estimate S^2 / 32 sqrt(2 / N) = 2.6e-5; the squared bias is a
/// mean of `(m - r)^2` with `v = s^2 / k + S^2 / 32 = 0.0075`, SE sqrt((2 v^2 + 4 b^2 v) / N)
/// = 4.9e-5, plus the other two estimates' shares (8.2e-5 in all, against b^2 = 0.0025). A
/// reference noise left in (+0.005), a variance not divided by k (-0.0075), or the halves'
/// noise taken as if they were of equal size (their mean squared difference over 4, 0.0067
/// instead of 0.005) each miss by far more.
#[test]
fn bias_and_variance_are_recovered_from_known_noise() {
    let (w, h) = (160u32, 160u32);
    let n = (3 * w * h) as f64;
    let mut s = rtis::sampling::Sampler::new(11, 0, 0);
    let mu = Image {
        width: w,
        height: h,
        pixels: (0..w * h)
            .map(|_| glam::Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()))
            .collect(),
    };
    let (b, sigma, s_sample, na, nb, k) = (0.05f32, 0.1f32, 0.4f32, 8u64, 24u64, 4usize);
    let ha = noisy(&mu, 0.0, s_sample / (na as f32).sqrt(), &mut s);
    let hb = noisy(&mu, 0.0, s_sample / (nb as f32).sqrt(), &mut s);
    let noise = converge::metrics::pooled_noise(&ha, na, &hb, nb);
    let want_noise = (s_sample * s_sample) as f64 / (na + nb) as f64;
    let se_noise = want_noise * (2.0 / n).sqrt();
    assert!(
        (noise - want_noise).abs() < 5.0 * se_noise,
        "reference noise {noise}, want {want_noise} +- 5 x {se_noise}"
    );
    // The reference: the halves' pooled mean, weighted by their samples.
    let reference = Image {
        width: w,
        height: h,
        pixels: ha
            .pixels
            .iter()
            .zip(&hb.pixels)
            .map(|(a, b)| (*a * na as f32 + *b * nb as f32) / (na + nb) as f32)
            .collect(),
    };
    let seeds: Vec<Image> = (0..k).map(|_| noisy(&mu, b, sigma, &mut s)).collect();
    let parts = converge::metrics::bias_and_variance(&seeds, &reference, noise);
    let s2 = (sigma * sigma) as f64;
    let se_var = s2 * (2.0 / ((k - 1) as f64 * n)).sqrt();
    assert!(
        (parts.variance - s2).abs() < 5.0 * se_var,
        "variance {}, want {s2} +- 5 x {se_var}",
        parts.variance
    );
    let (b, v) = (b as f64, s2 / k as f64 + want_noise);
    let se_bias = ((2.0 * v * v + 4.0 * b * b * v) / n).sqrt() + se_var / k as f64 + se_noise;
    assert!(
        (parts.bias2 - b * b).abs() < 5.0 * se_bias,
        "bias^2 {}, want {} +- 5 x {se_bias}",
        parts.bias2,
        b * b
    );
}

#[test]
fn base64_matches_the_standard() {
    use converge::report::base64;
    assert_eq!(base64(b""), "");
    assert_eq!(base64(b"f"), "Zg==");
    assert_eq!(base64(b"fo"), "Zm8=");
    assert_eq!(base64(b"foo"), "Zm9v");
    assert_eq!(base64(b"foobar"), "Zm9vYmFy");
}

/// Under the Physical model with several point lights and no emitter, a Path scene gets one
/// curve per light choice. At equal spp, choosing the light by importance has well under the
/// error of choosing it by power: on a floor under three lights at different distances, with
/// a sphere's shadow, only visibility is left to vary once the light is chosen by importance.
#[test]
fn light_choice_curves_for_point_lit_path_scenes() {
    let s = rtis::extract(&scene(
        "Scene(film: (width: 24, height: 20), model: Physical, shader: Path(max_depth: 2),
           camera: Perspective(position: (0, 4, -4), look_at: (0, 0, 0), fov: 60),
           entities: [
             (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (0.7, 0.7, 0.7))),
             (shape: Sphere(center: (0, 0.7, 0), radius: 0.7), material: Phong(kd: (0.5, 0.5, 0.5))),
             (light: Point(position: (-1.5, 1.5, 0.5), intensity: (2, 2, 2))),
             (light: Point(position: (1, 3, -1), intensity: (6, 6, 6))),
             (light: Point(position: (4, 6, 5), intensity: (40, 40, 40))),
           ])",
    ));
    let rungs = converge::ladder(&s);
    let families: Vec<&str> = rungs.iter().map(|r| r.family.as_str()).collect();
    for f in [
        "Path all lights",
        "Path one light",
        "Path by importance",
        "Path all lights Sobol'",
    ] {
        assert_eq!(families.iter().filter(|&&x| x == f).count(), 5, "{f}");
    }
    assert_eq!(rungs.len(), 4 * 5 + 4);
    let reference = render(
        &converge::with_settings(&s, converge::reference_shader(), 1024),
        &|| {},
    )
    .image;
    let at_16: Vec<converge::Rung> = rungs
        .into_iter()
        .filter(|r| r.label == "spp=16" && r.family != "Path 16 spp")
        .collect();
    let rows: Vec<converge::Row> =
        converge::sweep(&s, &reference, 0.0, &at_16, 1, 4, &mut |_| true)
            .into_iter()
            .map(|m| m.row)
            .collect();
    let err = |fam: &str| rows.iter().find(|r| r.family == fam).unwrap().rmse;
    let (all, one, importance) = (
        err("Path all lights"),
        err("Path one light"),
        err("Path by importance"),
    );
    let sobol = err("Path all lights Sobol'");
    eprintln!(
        "RMSE at 16 spp: all {all:.5}, one {one:.5}, importance {importance:.5}, all with Sobol' points {sobol:.5}"
    );
    assert!(importance < 0.5 * one, "{rows:#?}");
    // The Sobol' rung renders every light at every vertex from other numbers (the sweep sets
    // its sampler): not the independent rung's image.
    assert_ne!(sobol, all, "{rows:#?}");
}
