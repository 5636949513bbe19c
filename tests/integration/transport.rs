//! Exact answers of the course's shaders, derived by hand (see each test's comment).

use crate::common;

use crate::common::{close, render_str};
use glam::Vec3A;
use std::f32::consts::PI;

/// A 3x3 orthographic view straight down onto the plane y = 0 from y = 5: pixel centres land on
/// x, z in {-1, 0, 1}. One point light 1 above the origin, black background.
fn lit_plane(shader: &str, ks: f32, shininess: f32) -> String {
    format!(
        r#"Scene(
            film: (width: 3, height: 3, spp: 1),
            camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 3),
            shader: {shader},
            entities: [
                (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                 material: Phong(kd: (0.5, 0.25, 0.125), ks: ({ks}, {ks}, {ks}), shininess: {shininess})),
                (light: Point(position: (0, 1, 0), intensity: (2, 2, 2))),
            ],
        )"#
    )
}

/// Eq. 3 by hand at pixel (col, row): the point is p = (x, 0, z) with x = 1 - col (image right
/// is world -x when looking down with up = +z) and z = 1 - row. d^2 = x^2 + z^2 + 1,
/// wi = (-x, 1, -z) / d, wi.n = 1/d, wo = +y, wr = 2 (n.wi) n - wi = (x, 1, z) / d, wo.wr = 1/d.
/// L = I/d^2 (kd / d + ks (1/d)^s).
fn expected_direct(col: u32, row: u32, ks: f32, s: f32) -> Vec3A {
    let x = 1.0 - col as f32;
    let z = 1.0 - row as f32;
    let d = (x * x + z * z + 1.0).sqrt();
    let kd = Vec3A::new(0.5, 0.25, 0.125);
    2.0 / (d * d) * (kd / d + Vec3A::splat(ks * (1.0 / d).powf(s)))
}

#[test]
fn direct_shader_is_eq3_by_hand() {
    for (ks, s) in [(0.0, 1.0), (0.4, 10.0)] {
        let r = render_str(&lit_plane("Direct()", ks, s));
        for row in 0..3 {
            for col in 0..3 {
                let got = r.image.get(col, row);
                let want = expected_direct(col, row, ks, s);
                assert!(
                    close(got, want, 1e-5),
                    "pixel ({col},{row}): {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn global_at_depth_0_adds_exactly_the_ambient_term() {
    // Eq. 1 with Eq. 2: L = L_dir + a_t kd.
    let r = render_str(&lit_plane(
        "Global(samples: 4, max_depth: 0, ambient: (0.3, 0.6, 0.9))",
        0.4,
        10.0,
    ));
    let ambient = Vec3A::new(0.3, 0.6, 0.9) * Vec3A::new(0.5, 0.25, 0.125);
    for row in 0..3 {
        for col in 0..3 {
            let want = expected_direct(col, row, 0.4, 10.0) + ambient;
            let got = r.image.get(col, row);
            assert!(
                close(got, want, 1e-5),
                "pixel ({col},{row}): {got} vs {want}"
            );
        }
    }
}

/// The lit plane's hemisphere rays all escape to a black background, so Eq. 4 adds nothing and
/// Global at D = 1 equals Direct exactly.
#[test]
fn global_with_black_sky_equals_direct() {
    let d = render_str(&lit_plane("Direct()", 0.4, 10.0));
    let g = render_str(&lit_plane(
        "Global(samples: 16, max_depth: 1, ambient: (0.3, 0.3, 0.3))",
        0.4,
        10.0,
    ));
    assert_eq!(d.image, g.image);
}

/// A diffuse plane (ks = 0) under a uniform background b, no lights, Global with D = 1.
/// Every hemisphere ray escapes, so each pixel is 1/(2 pi n) sum_j b kd cos(theta_j) with
/// cos(theta_j) uniform on [0, 1] (mean 1/2, variance 1/12). Its expectation is b kd / (4 pi).
/// Over P pixels of n samples the image mean has standard deviation
/// b kd / (2 pi) sqrt(1 / (12 P n)); the test allows 5 of them.
#[test]
fn global_two_bounce_under_uniform_sky_converges_to_b_kd_over_4pi() {
    let (w, h, n) = (32u32, 32u32, 64u32);
    let text = format!(
        r#"Scene(
            film: (width: {w}, height: {h}),
            camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 10),
            shader: Global(samples: {n}, max_depth: 1, ambient: (9, 9, 9)),
            background: (2, 1, 0.5),
            seed: 7,
            entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                        material: Phong(kd: (0.5, 0.5, 0.5)))],
        )"#
    );
    let r = render_str(&text);
    let b = Vec3A::new(2.0, 1.0, 0.5);
    let want = b * 0.5 / (4.0 * PI);
    let sigma = b * 0.5 / (2.0 * PI) * (1.0 / (12.0 * (w * h * n) as f32)).sqrt();
    let got = r.image.mean();
    assert!(
        ((got - want).abs().cmple(5.0 * sigma)).all(),
        "mean {got}, expected {want} +- 5 x {sigma}"
    );
    // Every sample is an escaped ray: indirect count is exactly P n.
    assert_eq!(r.stats.indirect, (w * h * n) as u64);
}

/// Task 2 by hand. Floor y = 0 (kd_f) and ceiling y = 1 (kd_c), both diffuse, no lights, D = 2,
/// ambient a. A camera ray hits the floor (depth 0) and sends n hemisphere rays; each hits the
/// ceiling at depth 1 < D, which sends w_n (straight down) and w_r (the mirror of wo, also
/// down); both hit the floor at depth 2 = D and return a kd_f. With ks = 0 the ceiling gives
/// L_c = 1/(4 pi) (a kd_f kd_c (w_n.n) + a kd_f kd_c (w_r.n)) = a kd_f kd_c (1 + u) / (4 pi),
/// u = cos(theta) of the floor's sample. The floor then gets
/// 1/(2 pi n) sum_j L_c(u_j) kd_f u_j, with expectation
/// kd_f/(2 pi) a kd_f kd_c/(4 pi) E[(1 + u) u] = a kd_f^2 kd_c 5 / (48 pi^2), u uniform on [0,1].
/// E[((1+u)u)^2] = 1/3 + 1/2 + 1/5 = 31/30, so Var = 31/30 - 25/36 = 0.3389; tolerance 5 sigma.
#[test]
fn global_n_bounce_between_two_planes_matches_hand_derivation() {
    let (w, h, n) = (24u32, 24u32, 64u32);
    let text = format!(
        r#"Scene(
            film: (width: {w}, height: {h}),
            camera: Orthographic(position: (0, 0.5, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 1),
            shader: Global(samples: {n}, max_depth: 2, ambient: (1, 2, 3)),
            seed: 3,
            entities: [
                (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (0.8, 0.8, 0.8))),
                (shape: InfinitePlane(point: (0, 1, 0), normal: (0, -1, 0)), material: Phong(kd: (0.5, 0.5, 0.5))),
            ],
        )"#
    );
    let r = render_str(&text);
    let a = Vec3A::new(1.0, 2.0, 3.0);
    let (kf, kc) = (0.8f32, 0.5f32);
    let scale = a * kf * kf * kc / (8.0 * PI * PI);
    let want = scale * (5.0 / 6.0);
    let sigma = scale * (0.3389f32 / (w * h * n) as f32).sqrt();
    let got = r.image.mean();
    assert!(
        ((got - want).abs().cmple(5.0 * sigma)).all(),
        "mean {got}, expected {want} +- 5 x {sigma}"
    );
    // Rays: n per pixel at depth 0, then 2 per ceiling hit.
    assert_eq!(r.stats.indirect, (w * h * n * 3) as u64);
}

/// A perfect mirror facing the camera shows the background tinted by its colour, and the
/// Intersection, Depth and Normal shaders give their formulas.
#[test]
fn mirror_and_basic_shaders_by_hand() {
    let base = |shader: &str, material: &str| {
        format!(
            r#"Scene(
                film: (width: 2, height: 2),
                camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), fov: 10),
                shader: {shader},
                background: (0.5, 0.5, 0.5),
                entities: [(shape: InfinitePlane(point: (0, 0, 4), normal: (0, 0, -1)), material: {material})],
            )"#
        )
    };
    let r = render_str(&base("Direct()", "Mirror(color: (1, 0.5, 0.25))"));
    for p in &r.image.pixels {
        assert!(close(*p, Vec3A::new(0.5, 0.25, 0.125), 1e-6), "{p}");
    }
    let r = render_str(&base(
        "Intersection(color: (0.1, 0.2, 0.3))",
        "Phong(kd: (1, 1, 1))",
    ));
    assert!(
        r.image
            .pixels
            .iter()
            .all(|p| *p == Vec3A::new(0.1, 0.2, 0.3))
    );
    let r = render_str(&base("Normal", "Phong(kd: (1, 1, 1))"));
    assert!(
        r.image
            .pixels
            .iter()
            .all(|p| close(*p, Vec3A::new(0.5, 0.5, 0.0), 1e-6))
    );
    // Depth: the pixel through direction d hits z = 4 at t = 4 / d.z.
    let r = render_str(&base(
        "Depth(max_distance: 8, color: (1, 1, 1))",
        "Phong(kd: (1, 1, 1))",
    ));
    let h = (5f32.to_radians()).tan() * 0.5; // pixel centres at +-half of the half-extent
    let t = 4.0 * (1.0 + 2.0 * h * h).sqrt();
    for p in &r.image.pixels {
        assert!(
            (p.x - (1.0 - t / 8.0)).abs() < 1e-5,
            "{p} vs {}",
            1.0 - t / 8.0
        );
    }
}

/// The course's three spheres on a floor under an open sky, with its sources scaled: `light` on the three point lights' intensity,
/// `ambient` on Global's a_t, `sky` on the background.
fn sources(shader: &str, light: f32, ambient: f32, sky: f32) -> rtis::render::Rendered {
    let shader = shader.replace("AMBIENT", &format!("({ambient}, {ambient}, {ambient})"));
    let mut s = common::scene(&format!(
        "Scene(extends: \"spheres.ron\", film: (width: 24, height: 20, spp: 2), shader: {shader},
          background: ({sky}, {sky}, {sky}))"
    ));
    for l in s.world.query_mut::<&mut rtis::world::WorldLight>() {
        let (rtis::world::WorldLight::Point { intensity, .. }
        | rtis::world::WorldLight::Spot { intensity, .. }
        | rtis::world::WorldLight::Directional {
            irradiance: intensity,
            ..
        }) = l;
        *intensity *= light;
    }
    common::render_scene(&s)
}

/// Light transport is linear in its sources, in every shader and model: the image with the
/// point lights, the ambient term and the sky together is the sum of the three images with one
/// source each (the random directions do not depend on the sources, so the sums match to
/// rounding). A term added at the wrong step (direct light at an intermediate bounce of the
/// n-bounce rule, an escape at depth D) breaks it.
#[test]
fn transport_is_linear_in_its_sources() {
    for shader in [
        "Direct()",
        "Global(samples: 4, max_depth: 0, ambient: AMBIENT)",
        "Global(samples: 4, max_depth: 1, ambient: AMBIENT)",
        "Global(samples: 4, max_depth: 3, ambient: AMBIENT)",
        "Path(max_depth: 6)",
    ] {
        let all = sources(shader, 1.0, 0.3, 0.5);
        let parts = [
            sources(shader, 1.0, 0.0, 0.0),
            sources(shader, 0.0, 0.3, 0.0),
            sources(shader, 0.0, 0.0, 0.5),
        ];
        // Tolerance: the rounding of a few additions in single precision, about 16 ulp (the
        // sums agree to 1.8e-7 relative; dropping the direct light at an intermediate
        // bounce of the n-bounce rule breaks it by 1.7e-5).
        for (i, p) in all.image.pixels.iter().enumerate() {
            let sum: Vec3A = parts.iter().map(|r| r.image.pixels[i]).sum();
            assert!(close(*p, sum, 2e-6), "{shader}: pixel {i}: {p} vs {sum}");
        }
        // Each source this shader can see contributes (the test would be empty otherwise):
        // the lights and the sky always, the ambient term in Global.
        let sees = [true, shader.contains("AMBIENT"), true];
        for (k, r) in parts.iter().enumerate() {
            let contributes = r.image.mean().max_element() > 0.0;
            assert_eq!(
                contributes,
                sees[k],
                "{shader}: source {k}: mean {}",
                r.image.mean()
            );
        }
    }
}
