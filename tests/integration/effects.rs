//! Only the effects a scene calls for are simulated, and the derived effects change no pixel.

use crate::common::{render_scene, scene, scenes_dir};
use rtis::render::render;
use rtis::scene::load_path;
use rtis::shape::Shape;

fn small(path: &str, w: u32) -> rtis::scene::Scene {
    let mut s = load_path(&scenes_dir().join(path)).unwrap();
    let f = &mut s.settings.film;
    f.height = (w as f64 * f.height as f64 / f.width as f64).round() as u32;
    f.width = w;
    f.spp = f.spp.min(2);
    s
}

#[test]
fn derived_effects_of_the_course_scenes() {
    let e = rtis::extract(&small("cornell.ron", 8)).effects;
    assert!(e.shadows && e.reflection && e.refraction && e.indirect && e.ambient);
    assert!(e.spheres && e.planes && !e.triangles && !e.background);
    let e = rtis::extract(&small("cornell-direct.ron", 8)).effects;
    assert!(!e.indirect && !e.ambient);
    let e = rtis::extract(&small("spheres.ron", 8)).effects;
    assert!(e.shadows && !e.reflection && !e.refraction && !e.triangles);
    let e = rtis::extract(&small("spheres.ron", 8)).effects;
    assert!(e.spheres && e.planes && !e.indirect && !e.ambient && !e.background);
}

#[test]
fn rays_follow_the_effects() {
    // No glass: no refraction rays. Direct: no indirect rays.
    let r = render_scene(&small("spheres.ron", 40));
    assert_eq!(
        (r.stats.refraction, r.stats.reflection, r.stats.indirect),
        (0, 0, 0)
    );
    assert!(r.stats.shadow > 0);
    // No lights: no shadow rays.
    let r = render_scene(&scene(
        "Scene(film: (width: 16, height: 16), shader: Global(samples: 4, max_depth: 2), background: (1, 1, 1),
          entities: [(shape: Sphere(center: (0, 0, 4), radius: 1), material: Phong(kd: (0.5, 0.5, 0.5)))])",
    ));
    assert_eq!(r.stats.shadow, 0);
    assert!(r.stats.indirect > 0);
    // Switched off on purpose.
    let mut s = small("cornell-two-bounce.ron", 24);
    if let rtis::shader::Shader::Global(g) = &mut s.settings.shader {
        g.samples = 4;
    }
    s.settings.effects.shadows = Some(false);
    s.settings.effects.refraction = Some(false);
    let r = render_scene(&s);
    assert_eq!((r.stats.shadow, r.stats.refraction), (0, 0));
    assert!(r.stats.reflection > 0 && r.stats.indirect > 0);
}

/// `effects: (shadows: false)` equals, on every pixel that shows the floor, the same floor with
/// the occluder removed: shadows disabled by construction. (With shadows on, the sphere's
/// shadow makes those pixels differ, so the comparison can fail.)
#[test]
fn shadows_off_equals_no_occluders() {
    let text = |sphere: bool, effects: &str| {
        format!(
            r#"Scene(film: (width: 40, height: 30), camera: Perspective(position: (0, 3, -5), look_at: (0, 0, 1)),
              shader: Direct(), {effects}
              entities: [
                (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (0.7, 0.7, 0.7), ks: (0.2, 0.2, 0.2), shininess: 20)),
                {}
                (light: Point(position: (0.5, 3, 1), intensity: (9, 9, 9))),
              ])"#,
            if sphere {
                "(shape: Sphere(center: (0, 1, 1), radius: 0.8), material: Phong(kd: (0.9, 0.1, 0.1))),"
            } else {
                ""
            }
        )
    };
    let off = scene(&text(true, "effects: (shadows: false),"));
    let on = scene(&text(true, ""));
    let bare = scene(&text(false, ""));
    let (r_off, r_on, r_bare) = (render_scene(&off), render_scene(&on), render_scene(&bare));
    assert_eq!(r_off.stats.shadow, 0);
    let prepared = rtis::extract(&off);
    let (mut floor, mut shadowed) = (0, 0);
    for row in 0..30 {
        for col in 0..40 {
            let ray =
                prepared
                    .camera
                    .ray((col as f32 + 0.5) / 40.0, (row as f32 + 0.5) / 30.0, || {
                        panic!("a pinhole draws no lens sample")
                    });
            let Some(hit) = prepared.geometry.intersect(&ray) else {
                continue;
            };
            if matches!(prepared.geometry.prim(hit.prim).shape, Shape::Plane(_)) {
                floor += 1;
                assert_eq!(
                    r_off.image.get(col, row),
                    r_bare.image.get(col, row),
                    "pixel ({col}, {row})"
                );
                if r_on.image.get(col, row) != r_bare.image.get(col, row) {
                    shadowed += 1;
                }
            }
        }
    }
    assert!(
        floor > 500 && shadowed > 10,
        "floor {floor}, shadowed {shadowed}"
    );
}

/// Global with indirect light switched off is exactly Global with D = 0.
#[test]
fn indirect_off_is_the_ambient_shader() {
    let mut off = small("cornell-n-bounce.ron", 30);
    off.settings.effects.indirect = Some(false);
    let ambient = small("cornell-ambient.ron", 30);
    let (a, b) = (render_scene(&off), render_scene(&ambient));
    assert_eq!(a.image, b.image);
    assert_eq!(a.stats.indirect, 0);
}

#[test]
fn impossible_requests_warn() {
    let s = scene("Scene(effects: (refraction: true, shadows: true), entities: [])");
    let p = rtis::extract(&s);
    assert!(
        p.warnings
            .iter()
            .any(|w| w.contains("refraction requested")),
        "{:?}",
        p.warnings
    );
    assert!(p.warnings.iter().any(|w| w.contains("shadows requested")));
    assert!(!p.effects.refraction);
}

/// The derived effects drop nothing a scene needs: every scene in `scenes/` renders
/// bit-identically (and with the same ray counts) with its derived effects and with every
/// effect on; and every scene lacks some effect, so the derivation is exercised.
#[test]
fn derived_effects_change_no_pixel() {
    let mut derived = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let mut s = small(&name, 48);
        if let rtis::shader::Shader::Global(g) = &mut s.settings.shader {
            g.samples = g.samples.min(8);
        }
        let p = rtis::extract(&s);
        let all = p.with_every_effect();
        assert_eq!(all.effects, rtis::effects::Effects::ALL);
        if p.effects != all.effects {
            derived += 1;
        }
        let (a, b) = (render(&p, &|| {}), render(&all, &|| {}));
        assert!(
            a.image == b.image,
            "{name}: effects {} differ from every effect on",
            p.effects
        );
        assert_eq!(a.stats, b.stats, "{name}");
    }
    assert!(derived >= 7, "every scene lacks some effect");
}
