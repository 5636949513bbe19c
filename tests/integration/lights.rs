//! Lights (src/light/): the spot light's falloff at known angles (Mitsuba 3's linear ramp),
//! its power against a quadrature of the falloff, and a floor under a spot: radiance
//! `(kd / pi) I falloff(theta) cos(theta) / d^2` inside the beam, nothing beyond the cutoff,
//! under Direct and Path alike.

use crate::common::render_str;
use glam::Vec3A;
use rtis::light::SpotLight;

fn spot(beam: f32, cutoff: f32) -> SpotLight {
    SpotLight {
        position: Vec3A::ZERO,
        axis: Vec3A::new(0.0, -1.0, 0.0),
        intensity: Vec3A::new(2.0, 4.0, 8.0),
        beam: beam.to_radians(),
        cutoff: cutoff.to_radians(),
        in_room: false,
    }
}

/// Within the beam 1; halfway between beam and cutoff (in angle) 1/2; a quarter of the way
/// from the cutoff 1/4; at and beyond the cutoff 0; and `incident` applies it over `d^2`.
#[test]
fn spot_falloff_is_linear_in_the_angle() {
    let s = spot(15.0, 20.0);
    let at = |deg: f32| s.falloff(deg.to_radians().cos());
    assert_eq!(at(0.0), 1.0);
    assert_eq!(at(14.9), 1.0);
    assert!((at(17.5) - 0.5).abs() < 1e-4, "{}", at(17.5));
    assert!((at(18.75) - 0.25).abs() < 1e-4, "{}", at(18.75));
    assert_eq!(at(20.0001), 0.0);
    assert_eq!(at(90.0), 0.0);
    // A point 2 below and at 17.5 degrees from the axis.
    let theta = 17.5f32.to_radians();
    let p = Vec3A::new(2.0 * theta.tan(), -2.0, 0.0);
    let inc = s.incident(p).unwrap();
    let d2 = p.length_squared();
    let want = s.intensity * 0.5 / d2;
    assert!(
        (inc.li - want).abs().max_element() < 1e-4 * want.max_element(),
        "{:?}",
        inc.li
    );
    assert!((inc.wi + p.normalize()).length() < 1e-6);
}

/// The power `2 pi I [1 - (sin c - sin b)/(c - b)]` is the falloff integrated over the sphere
/// (midpoint rule in theta, 200,000 steps), for a few beams, and `2 pi I (1 - cos c)` when the
/// beam fills the cone.
#[test]
fn spot_power_is_the_integral_of_its_falloff() {
    for (b, c) in [(15.0, 20.0), (5.0, 60.0), (30.0, 30.0), (1.0, 90.0)] {
        let s = spot(b, c);
        let n = 200_000;
        let dt = std::f64::consts::PI / n as f64;
        let integral: f64 = (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) * dt;
                s.falloff(t.cos() as f32) as f64 * t.sin() * dt
            })
            .sum::<f64>()
            * 2.0
            * std::f64::consts::PI;
        let mean_i = s.intensity.element_sum() as f64 / 3.0;
        let want = integral * mean_i;
        assert!(
            (s.power() as f64 - want).abs() < 1e-4 * want,
            "beam {b}, cutoff {c}: {} against {want}",
            s.power()
        );
    }
}

/// A grey floor (kd 0.5) under a spot 2 units up pointing down, seen by an orthographic camera
/// from above: inside the beam each pixel is `(kd / pi) I cos(theta) / d^2` at its point
/// (within the variation over the pixel), beyond the cutoff 0, and Path (next-event
/// estimation; no other surface) gives Direct's value.
#[test]
fn a_floor_under_a_spot_has_the_exact_radiance() {
    let (h, i, beam, cutoff) = (2.0f64, 10.0f64, 20.0f64, 30.0f64);
    let side = 64u32;
    let extent = 4.0 * h * cutoff.to_radians().tan();
    let text = |shader: &str| {
        format!(
            "Scene(film: (width: {side}, height: {side}, spp: 4), shader: {shader}, model: Physical,
                   camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1),
                                        height: {extent}),
                   entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                               material: Phong(kd: (0.5, 0.5, 0.5), ks: (0, 0, 0))),
                              (light: Spot(position: (0, {h}, 0), direction: (0, -1, 0),
                                           intensity: ({i}, {i}, {i}),
                                           cutoff_angle: {cutoff}, beam_width: {beam}))])"
        )
    };
    let direct = render_str(&text("Direct()"));
    let path = render_str(&text("Path(max_depth: 1)"));
    let px = extent / side as f64;
    let (mut inside, mut outside) = (0, 0);
    for row in 0..side {
        for col in 0..side {
            // The pixel's centre on the floor; its corners' angles bound the variation.
            let x = (col as f64 + 0.5 - side as f64 / 2.0) * px;
            let z = (side as f64 / 2.0 - row as f64 - 0.5) * px;
            let r = (x * x + z * z).sqrt();
            let theta = r.atan2(h).to_degrees();
            let v = direct.image.get(col, row).x as f64;
            let reach = (r + px).atan2(h).to_degrees();
            let near = (r - px).max(0.0).atan2(h).to_degrees();
            if reach < beam {
                let d2 = h * h + r * r;
                let cos = h / d2.sqrt();
                let want = 0.5 / std::f64::consts::PI * i * cos / d2;
                assert!(
                    (v - want).abs() < 0.03 * want,
                    "({col}, {row}) at {theta:.1} deg: {v} against {want}"
                );
                inside += 1;
            } else if near > cutoff {
                assert_eq!(
                    v, 0.0,
                    "({col}, {row}) at {theta:.1} deg, beyond the cutoff"
                );
                outside += 1;
            }
            let p = path.image.get(col, row).x as f64;
            assert!(
                (p - v).abs() <= 1e-5 * v.max(1e-3),
                "({col}, {row}): Path {p}, Direct {v}"
            );
        }
    }
    assert!(
        inside > 200 && outside > 200,
        "{inside} inside, {outside} outside"
    );
}

/// A floor (kd 0.5) under a sun 35 degrees from the vertical with irradiance E = 3: every
/// pixel is `(kd / pi) E cos(35 deg)` (no distance, no falloff), under Direct and Path alike,
/// except under a black ball (seen from above) and in its shadow, whose centre is black.
#[test]
fn a_floor_under_a_sun_has_irradiance_e_cos_theta() {
    let theta = 35f64.to_radians();
    let (e, kd) = (3.0f64, 0.5f64);
    let (dx, dy) = (theta.sin(), -theta.cos());
    // The ball at height 1.5 casts its shadow's centre at x = 1.5 tan(theta).
    let shadow_x = 1.5 * theta.tan();
    let text = |shader: &str| {
        format!(
            "Scene(film: (width: 40, height: 40, spp: 4), shader: {shader}, model: Physical,
                   camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1),
                                        height: 8),
                   entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                               material: Phong(kd: ({kd}, {kd}, {kd}), ks: (0, 0, 0))),
                              (shape: Sphere(center: (0, 1.5, 0), radius: 0.5),
                               material: Phong(kd: (0, 0, 0), ks: (0, 0, 0))),
                              (light: Directional(direction: ({dx}, {dy}, 0),
                                                  irradiance: ({e}, {e}, {e})))])"
        )
    };
    let want = kd / std::f64::consts::PI * e * theta.cos();
    for shader in ["Direct()", "Path(max_depth: 1)"] {
        let r = render_str(&text(shader));
        let px = 8.0 / 40.0;
        let (mut lit, mut dark) = (0, 0);
        for row in 0..40u32 {
            for col in 0..40u32 {
                // The pixel's centre on the floor (the image's right is up x forward = +x).
                let x = (col as f64 + 0.5) * px - 4.0;
                let z = 4.0 - (row as f64 + 0.5) * px;
                // Whether any of the pixel's floor can see the ball above it towards the sun.
                let d = ((x - shadow_x).powi(2) + z * z).sqrt();
                let v = r.image.get(col, row).x as f64;
                // The black ball itself, seen from above, hides the floor within 0.5 of the axis.
                let under_ball = (x * x + z * z).sqrt() < 0.5 + px;
                if d > 1.2 && !under_ball {
                    assert!(
                        (v - want).abs() < 1e-5 * want,
                        "{shader} ({col}, {row}): {v} vs {want}"
                    );
                    lit += 1;
                } else if d < 0.25 {
                    assert_eq!(v, 0.0, "{shader} ({col}, {row}) in the shadow");
                    dark += 1;
                }
            }
        }
        assert!(lit > 1000 && dark >= 4, "{shader}: {lit} lit, {dark} dark");
    }
}

/// The choice of one light per vertex covers every kind: a floor point lit by a point light
/// (`I cos / d^2`), a spot aimed at it (in its beam: the same), and a sun (`E cos`), seen by a
/// pinpoint camera, has `(kd / pi)` times their sum under every strategy (summing all, one by
/// power, one by importance), within 5 standard errors; one light per vertex traces one shadow
/// ray per camera ray, all lights three.
#[test]
fn one_light_per_vertex_covers_every_kind() {
    let kd = 0.5f64;
    let (p, i_p) = ([-0.5f64, 2.0, -0.5], 3.0f64);
    let (s, i_s) = ([0.5f64, 2.5, 0.0], 4.0f64);
    let (sun, e) = ([0.3f64, -1.0, 0.2], 1.5f64);
    let at = |x: [f64; 3], i: f64| {
        let d2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        i * (x[1] / d2.sqrt()) / d2
    };
    let sun_cos = -sun[1] / (sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]).sqrt();
    let want = kd / std::f64::consts::PI * (at(p, i_p) + at(s, i_s) + e * sun_cos);
    for shader in [
        "Path(max_depth: 1, lights_per_vertex: All)",
        "Path(max_depth: 1, lights_per_vertex: One)",
        "Path(max_depth: 1, lights_per_vertex: Importance)",
    ] {
        let text = format!(
            "Scene(film: (width: 32, height: 32, spp: 16),
               camera: Perspective(position: (3, 1, -0.5), look_at: (0, 0, 0), fov: 0.001),
               model: Physical, shader: {shader},
               entities: [
                 (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                  material: Phong(kd: ({kd}, {kd}, {kd}), ks: (0, 0, 0))),
                 (light: Point(position: ({}, {}, {}), intensity: ({i_p}, {i_p}, {i_p}))),
                 (light: Spot(position: ({}, {}, {}), direction: ({}, {}, {}),
                              intensity: ({i_s}, {i_s}, {i_s}), cutoff_angle: 30, beam_width: 20)),
                 (light: Directional(direction: ({}, {}, {}), irradiance: ({e}, {e}, {e}))),
               ])",
            p[0], p[1], p[2], s[0], s[1], s[2], -s[0], -s[1], -s[2], sun[0], sun[1], sun[2]
        );
        let r = render_str(&text);
        let (mean, se) = crate::common::mean_and_se(&r);
        let tol = 5.0 * se + 1e-5 * want;
        assert!(
            (mean - want).abs() <= tol,
            "{shader}: {mean:.6} vs exact {want:.6} (tolerance {tol:.2e})"
        );
        let shadow = r.stats.shadow as f64 / r.stats.camera as f64;
        let expect = if shader.contains("All") { 3.0 } else { 1.0 };
        assert!(
            shadow <= expect + 1e-9,
            "{shader}: {shadow} shadow rays per camera ray"
        );
    }
}

/// A sun grazing a floor stays finite and exact: at `cos(theta)` of 1e-2, 1e-4 and 1e-7 (and
/// exactly along the floor, 0) a Lambertian floor under Direct reflects `(kd / pi) E cos`, with
/// no sample dropped; a rough plastic floor under Path stays finite and non-negative.
#[test]
fn a_sun_grazing_a_floor_is_finite() {
    for cos in [1e-2f64, 1e-4, 1e-7, 0.0] {
        let sin = (1.0 - cos * cos).sqrt();
        let floor = |material: &str, shader: &str| {
            format!(
                "Scene(film: (width: 8, height: 8, spp: 4), shader: {shader}, model: Physical,
                       camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0),
                                            up: (0, 0, 1), height: 2),
                       entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                                   material: {material}),
                                  (light: Directional(direction: ({sin}, {}, 0),
                                                      irradiance: (3, 3, 3)))])",
                -cos
            )
        };
        let r = render_str(&floor(
            "Phong(kd: (0.5, 0.5, 0.5), ks: (0, 0, 0))",
            "Direct()",
        ));
        let want = 0.5 / std::f64::consts::PI * 3.0 * cos;
        for p in &r.image.pixels {
            assert!(
                (p.x as f64 - want).abs() <= 1e-3 * want + 1e-12,
                "cos {cos}: {} against {want}",
                p.x
            );
        }
        let r = render_str(&floor(
            "RoughPlastic(alpha: 0.05, diffuse_reflectance: (0.5, 0.5, 0.5))",
            "Path(max_depth: 3)",
        ));
        for p in &r.image.pixels {
            assert!(p.x.is_finite() && p.x >= 0.0, "cos {cos}: {}", p.x);
        }
    }
}
