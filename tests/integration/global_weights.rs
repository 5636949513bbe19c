//! The Global shader's weights, checked a second way (`tests/integration/transport.rs` is the first): Eq. 4's
//! `1 / (2 pi n)` and the n-bounce rule's `1 / (4 pi)` over both of its rays, in configurations
//! other than that file's, exact where the answer is a constant and statistical where it is an
//! expectation, each through every order of tracing: the trees in waves, by the kernel of
//! packed scenes and by that of scenes with a BVH, and the depth-first walk (which the scene
//! is made to take by 65 point lights that add nothing).

use crate::common;

use crate::common::{render_scene, scene};
use glam::Vec3A;
use rtis::render::Rendered;
use rtis::sampling::Sampler;
use rtis::shader::Shader;
use rtis::shader::global::Order;
use rtis::stats::RayStats;
use std::f32::consts::PI;

/// 65 point lights under the floor `y = 0`: more than the waves take (64), so the render walks
/// each tree depth first. They add exactly nothing: a floor point does not face them (the
/// light term needs `wi.n > 0`), and every ray from above towards them crosses the floor, so
/// their shadow rays are blocked.
fn walk_lights() -> String {
    (0..65)
        .map(|i| {
            format!(
                "(light: Point(position: ({}, -2, {}), intensity: (5, 5, 5))),",
                i % 9,
                i / 9
            )
        })
        .collect()
}

/// A triangle far under the floor, which no ray reaches: with it the scene has a BVH, and the
/// waves run the kernel for such scenes (`waves.rs`) instead of the packed one (`lanes.rs`).
const BVH: &str = "(shape: Triangle(a: (0, -50, 0), b: (1, -50, 0), c: (0, -50, 1)), material: Phong(kd: (1, 1, 1))),";

/// Render `text` (a scene whose entities end with `LIGHTS`) in the three orders of tracing:
/// the waves in lanes (every primitive packed), the waves of a scene with a BVH ([`BVH`]
/// added), and the depth-first walk ([`walk_lights`] added). Checks that each is the one meant.
fn every_order(text: &str) -> [(&'static str, Rendered); 3] {
    ["lanes", "bvh", "walk"].map(|order| {
        let extra = match order {
            "lanes" => String::new(),
            "bvh" => BVH.to_string(),
            _ => walk_lights(),
        };
        let s = scene(&text.replace("LIGHTS", &extra));
        let rs = rtis::extract(&s);
        let Shader::Global(g) = rs.shader else {
            panic!("not a Global scene")
        };
        let mut stats = RayStats::default();
        let tr = rs.tracer(Sampler::new(0, 0, 0), &mut stats);
        assert_eq!(Order::Waves.applies(&tr, &g), order != "walk", "{order}");
        assert_eq!(rs.geometry.bvh.is_empty(), order != "bvh", "{order}");
        (order, render_scene(&s))
    })
}

/// Eq. 4's weight alone. A floor with `kd = 0` and `ks` at shininess 0 reflects `r = ks` in
/// every direction (the lobe `(wo.wr)^0` is 1), under a uniform sky `b`, no lights, D = 1:
/// every hemisphere ray escapes, so each pixel is `1/(2 pi n) sum_j b ks = b ks / (2 pi)`,
/// whatever the directions drawn. Tolerance: the rounding of n = 16 equal terms (1e-6
/// relative). A weight of `2 pi / n`, `1 / n` or `1 / (pi n)` misses by a factor 2 or more.
#[test]
fn eq4_weight_is_one_over_two_pi_n_exactly() {
    let text = r#"Scene(
        film: (width: 5, height: 4),
        camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 6),
        shader: Global(samples: 16, max_depth: 1, ambient: (9, 9, 9)),
        background: (2, 1, 0.5),
        entities: [
            (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
             material: Phong(kd: (0, 0, 0), ks: (0.5, 0.25, 0.75), shininess: 0)),
            LIGHTS
        ],
    )"#;
    let want = Vec3A::new(2.0, 1.0, 0.5) * Vec3A::new(0.5, 0.25, 0.75) / (2.0 * PI);
    for (order, r) in every_order(text) {
        for (i, p) in r.image.pixels.iter().enumerate() {
            assert!(
                common::close(*p, want, 1e-6),
                "{order}: pixel {i}: {p} vs {want}"
            );
        }
        assert_eq!(r.stats.indirect, 5 * 4 * 16, "{order}");
    }
}

/// A floor (`kd_f`, no `ks`) under a ceiling 1 above, no lights, ambient `a`, as `D = 1` and
/// `D = 2` scenes that draw the same directions at the floor (no hit below draws a random
/// number), so each pixel's ratio is exact:
/// - D = 1, ceiling `kd_1` (no `ks`): each hemisphere ray meets the ceiling at depth D, which
///   returns `a kd_1`.
/// - D = 2, ceiling `kd = 0` and `ks_c` at shininess 0: at depth 1 it sends `w_n` and `w_r`
///   down; both meet the floor at depth 2 = D, which returns `a kd_f`; with `r = ks_c` for both,
///   the ceiling returns `1/(4 pi) (a kd_f ks_c + a kd_f ks_c) = a kd_f ks_c / (2 pi)`.
///
/// So every pixel of the D = 2 image is the D = 1 pixel times `kd_f ks_c / (2 pi kd_1)`.
/// Tolerance: rounding (2e-6 relative). A `1 / (2 pi)` weight in the n-bounce rule, or one of
/// its two rays dropped, misses by a factor 2.
#[test]
fn n_bounce_weight_is_one_over_four_pi_over_both_rays_exactly() {
    let room = |depth: u32, ceiling: &str| {
        format!(
            r#"Scene(
            film: (width: 6, height: 5),
            camera: Orthographic(position: (0, 0.5, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 2),
            shader: Global(samples: 32, max_depth: {depth}, ambient: (1, 2, 3)),
            seed: 5,
            entities: [
                (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (0.8, 0.6, 0.4))),
                (shape: InfinitePlane(point: (0, 1, 0), normal: (0, -1, 0)), material: {ceiling}),
                LIGHTS
            ],
        )"#
        )
    };
    let d1 = every_order(&room(1, "Phong(kd: (0.5, 0.25, 0.125))"));
    let d2 = every_order(&room(
        2,
        "Phong(kd: (0, 0, 0), ks: (0.3, 0.6, 0.9), shininess: 0)",
    ));
    let ratio = Vec3A::new(0.8, 0.6, 0.4) * Vec3A::new(0.3, 0.6, 0.9)
        / (2.0 * PI * Vec3A::new(0.5, 0.25, 0.125));
    for ((order, one), (_, two)) in d1.iter().zip(&d2) {
        for (i, (a, b)) in one.image.pixels.iter().zip(&two.image.pixels).enumerate() {
            assert!(a.min_element() > 0.0, "{order}: pixel {i} is black");
            let want = *a * ratio;
            assert!(
                common::close(*b, want, 2e-6),
                "{order}: pixel {i}: {b} vs {want}"
            );
        }
        // Rays: n per pixel at depth 0, and two per ceiling hit at D = 2.
        assert_eq!(one.stats.indirect, 6 * 5 * 32, "{order}");
        assert_eq!(two.stats.indirect, 6 * 5 * 32 * 3, "{order}");
    }
}

/// The n-bounce terms with a specular lobe, statistically. Floor `kd_f` (no `ks`), ceiling
/// `kd_c`, `ks_c`, shininess `s`, no lights, ambient `a`, D = 2. A floor ray with `u = cos` to
/// the normal (uniform on [0, 1] under uniform hemisphere sampling) meets the ceiling, where
/// `wo.n = u`; there `r(w_n) = kd_c + ks_c u^s` (the reflection of `w_n` is `w_n`) and
/// `r(w_r) = kd_c u + ks_c` (the reflection of `w_r` is `wo`), and both rays return `a kd_f`.
/// So a pixel is `1/(2 pi n) sum_j L_c(u_j) kd_f u_j` with
/// `L_c(u) = a kd_f / (4 pi) (kd_c (1 + u) + ks_c (1 + u^s))`, of expectation
/// `a kd_f^2 / (8 pi^2) (kd_c (1/2 + 1/3) + ks_c (1/2 + 1/(s + 2)))`.
/// The image mean over P pixels of n samples has standard deviation
/// `a kd_f^2 / (8 pi^2) sqrt(Var[g(u)] / (P n))` with `g(u) = (kd_c (1 + u) + ks_c (1 + u^s)) u`,
/// its variance integrated here by Simpson's rule; the test allows 5 of them.
#[test]
fn n_bounce_terms_with_a_specular_lobe_match_their_expectation() {
    // With the lobe, and without it (the kernels' diffuse path: `ks = 0`).
    for ks_c in [Vec3A::new(0.6, 0.2, 0.7), Vec3A::ZERO] {
        n_bounce_statistics(ks_c);
    }
}

/// [`n_bounce_terms_with_a_specular_lobe_match_their_expectation`] with the ceiling's `ks_c`.
fn n_bounce_statistics(ks_c: Vec3A) {
    let (w, h, n, s) = (24u32, 20u32, 64u32, 20.0f64);
    let kd_c = Vec3A::new(0.3, 0.5, 0.2);
    let (a, kd_f) = (Vec3A::new(1.0, 2.0, 3.0), 0.8f32);
    let text = format!(
        r#"Scene(
            film: (width: {w}, height: {h}),
            camera: Orthographic(position: (0, 0.5, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 3),
            shader: Global(samples: {n}, max_depth: 2, ambient: (1, 2, 3)),
            seed: 9,
            entities: [
                (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: ({kd_f}, {kd_f}, {kd_f}))),
                (shape: InfinitePlane(point: (0, 1, 0), normal: (0, -1, 0)),
                 material: Phong(kd: (0.3, 0.5, 0.2), ks: ({}, {}, {}), shininess: {s})),
                LIGHTS
            ],
        )"#,
        ks_c.x, ks_c.y, ks_c.z
    );
    // Moments of g(u) per channel, by Simpson's rule on [0, 1] (error far below the tolerance).
    let simpson = |f: &dyn Fn(f64) -> f64| {
        let m = 20_000;
        let step = 1.0 / m as f64;
        (0..=m)
            .map(|i| {
                let c = if i == 0 || i == m {
                    1.0
                } else {
                    [2.0, 4.0][i % 2]
                };
                c * f(i as f64 * step)
            })
            .sum::<f64>()
            * step
            / 3.0
    };
    let scale = a * kd_f * kd_f / (8.0 * PI * PI);
    let mut want = Vec3A::ZERO;
    let mut sigma = Vec3A::ZERO;
    for c in 0..3 {
        let (kd, ks) = (kd_c[c] as f64, ks_c[c] as f64);
        let g = |u: f64| (kd * (1.0 + u) + ks * (1.0 + u.powf(s))) * u;
        let mean = simpson(&g);
        let closed = kd * (0.5 + 1.0 / 3.0) + ks * (0.5 + 1.0 / (s + 2.0));
        assert!((mean - closed).abs() < 1e-9, "Simpson {mean} vs {closed}");
        let var = simpson(&|u| g(u) * g(u)) - mean * mean;
        want[c] = scale[c] * closed as f32;
        sigma[c] = scale[c] * (var / (w * h * n) as f64).sqrt() as f32;
    }
    for (order, r) in every_order(&text) {
        let got = r.image.mean();
        assert!(
            (got - want).abs().cmple(5.0 * sigma).all(),
            "{order}, ks_c {ks_c}: mean {got}, expected {want} +- 5 x {sigma}"
        );
    }
}
