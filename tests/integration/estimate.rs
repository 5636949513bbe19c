//! The cost estimate (src/render/estimate.rs): the shader's rule is exact where every ray meets
//! a Phong surface, the calibration is close on the course's box, and `render` refuses a
//! ruinous estimate without `--force`.

use crate::common::{render_scene, scene};
use rtis::render::estimate::{estimate, rule_rays_per_sample};

/// A closed sphere room of Phong walls around the camera, with `lights` point lights inside:
/// every ray meets a Phong surface.
fn closed_room(shader: &str, lights: usize) -> String {
    let lights: String = (0..lights)
        .map(|i| {
            format!(
                "(light: Point(position: ({}, 2, 0), intensity: (5, 5, 5))),",
                i
            )
        })
        .collect();
    format!(
        "Scene(film: (width: 12, height: 10), shader: {shader},
          camera: Perspective(position: (0, 0, -3), look_at: (0, 0, 0), fov: 60),
          entities: [(shape: Sphere(center: (0, 0, 0), radius: 10), material: Phong(kd: (0.5, 0.5, 0.5))), {lights}])"
    )
}

/// Every ray meets a Phong surface: the rule is the exact count, and the estimate equals it.
#[test]
fn rule_is_exact_in_a_closed_room() {
    for (shader, lights, per_sample) in [
        ("Normal", 2, 1.0),
        ("Direct()", 3, 4.0),
        // (1 + L)(1 + n (2^D - 1)) = 3 (1 + 4 * 7).
        ("Global(samples: 4, max_depth: 3)", 2, 87.0),
        ("Global(samples: 5, max_depth: 0)", 1, 2.0),
    ] {
        let s = scene(&closed_room(shader, lights));
        let prepared = rtis::extract(&s);
        assert_eq!(
            rule_rays_per_sample(&prepared),
            Some(per_sample),
            "{shader}"
        );
        let rendered = render_scene(&s);
        assert_eq!(
            rendered.stats.total() as f64,
            per_sample * 120.0,
            "{shader}"
        );
        assert_eq!(estimate(&prepared).rays(), per_sample * 120.0, "{shader}");
    }
}

/// A Global too deep to calibrate sample by sample is calibrated on a shallower one and
/// scaled by the rule: still exact in the closed room.
#[test]
fn deep_global_is_estimated_through_a_shallower_one() {
    let s = scene(&closed_room("Global(samples: 64, max_depth: 16)", 3));
    let e = estimate(&rtis::extract(&s));
    assert!(e.proxy);
    let rule = 4.0 * (1.0 + 64.0 * 65535.0);
    assert_eq!(e.rays(), rule * 120.0);
}

/// On the course's box (open behind the camera, mirror and glass spheres) the calibrated
/// estimate is within 2% of the rays the render traces.
#[test]
fn estimate_is_close_on_the_course_box() {
    for shader in ["Global(samples: 8, max_depth: 2)", "Path(max_depth: 4)"] {
        let s = scene(&format!(
            "Scene(extends: \"cornell.ron\", film: (width: 72, height: 58), shader: {shader})"
        ));
        let prepared = rtis::extract(&s);
        let e = estimate(&prepared);
        let actual = render_scene(&s).stats.total() as f64;
        let rel = (e.rays() - actual).abs() / actual;
        assert!(
            rel < 0.02,
            "{shader}: estimate {} against {actual}",
            e.rays()
        );
    }
}
