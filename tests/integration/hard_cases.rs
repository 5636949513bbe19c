//! Hard cases stay numerically stable: each renders, asserts that no pixel is NaN or infinite,
//! and checks its specific expectation.

use crate::common::{render_scene, render_str, scene, scenes_dir};
use glam::{DVec3, Vec3A};
use rtis::render::Rendered;
use rtis::scene::{Scene, load_path};
use rtis::world::{WorldLight, WorldShape};

fn finite(r: &Rendered) {
    assert!(r.image.all_finite(), "NaN or Inf in the image");
}

/// Mean absolute difference between two images.
fn mean_abs_diff(a: &Rendered, b: &Rendered) -> f32 {
    let s: f32 = a
        .image
        .pixels
        .iter()
        .zip(&b.image.pixels)
        .map(|(p, q)| (*p - *q).abs().element_sum() / 3.0)
        .sum();
    s / a.image.pixels.len() as f32
}

/// Fraction of pixels whose channels differ by more than `tol`.
fn fraction_differing(a: &Rendered, b: &Rendered, tol: f32) -> f32 {
    let n = a
        .image
        .pixels
        .iter()
        .zip(&b.image.pixels)
        .filter(|(p, q)| (**p - **q).abs().max_element() > tol)
        .count();
    n as f32 / a.image.pixels.len() as f32
}

/// Apply `x -> s x + t` to every position of the world and the camera: a system over the
/// scene's components.
fn transform(scene: &mut Scene, s: f64, t: DVec3) {
    let f = |p: &mut DVec3| *p = *p * s + t;
    for shape in scene.world.query_mut::<&mut WorldShape>() {
        if let WorldShape::Sphere { radius, .. } = shape {
            *radius *= s;
        }
        shape.points_mut().into_iter().for_each(f);
    }
    for light in scene.world.query_mut::<&mut WorldLight>() {
        match light {
            WorldLight::Point {
                position,
                intensity,
            }
            | WorldLight::Spot {
                position,
                intensity,
                ..
            } => {
                f(position);
                // Keep the irradiance I / d^2 the same at the scaled distances.
                *intensity *= (s * s) as f32;
            }
            // A direction and an irradiance do not change with the scene's scale and place.
            WorldLight::Directional { .. } => {}
        }
    }
    let camera = &mut scene.settings.camera;
    f(&mut camera.position);
    f(&mut camera.look_at);
    // A lens's sizes scale with the scene.
    if let rtis::camera::Projection::Perspective { lens: Some(l), .. } = &mut camera.projection {
        l.radius *= s;
        l.focus_distance *= s;
    }
}

fn small_cornell(file: &str) -> Scene {
    let mut s = load_path(&scenes_dir().join(file)).unwrap();
    s.settings.film.width = 90;
    s.settings.film.height = 72;
    s
}

/// The Cornell box translated by 1e5, scaled by 1e-3, or both, matches the original: no shadow
/// acne (self-shadowed speckles), no light leaks. The prepared scene is camera-relative, so
/// the translation costs no precision; the offsets of secondary rays are relative to the
/// coordinates, so the scale costs none either. Tolerance: mean absolute difference < 2e-3 and
/// under 1% of pixels off by more than 0.02 (silhouette pixels may move by a rounding).
#[test]
fn cornell_box_is_stable_under_translation_and_scale() {
    for file in ["cornell-direct.ron", "cornell-two-bounce.ron"] {
        let mut base = small_cornell(file);
        if let rtis::shader::Shader::Global(g) = &mut base.settings.shader {
            g.samples = 8;
        }
        let reference = render_scene(&base);
        finite(&reference);
        for (s, t) in [
            (1.0, DVec3::splat(1e5)),
            (1e-3, DVec3::ZERO),
            (1e-3, DVec3::splat(1e5)),
            (1e3, DVec3::new(-3e5, 2e5, 7e4)),
        ] {
            let mut moved = small_cornell(file);
            moved.settings.shader = base.settings.shader;
            transform(&mut moved, s, t);
            let r = render_scene(&moved);
            finite(&r);
            let (mad, frac) = (
                mean_abs_diff(&r, &reference),
                fraction_differing(&r, &reference, 0.02),
            );
            assert!(
                mad < 2e-3 && frac < 0.01,
                "{file} scale {s} offset {t}: mean diff {mad}, {frac} of pixels differ"
            );
        }
    }
}

const BOX: &str = r#"
        (shape: InfinitePlane(point: (0, -3, 0), normal: (0, 1, 0)), material: Phong(kd: (0.8, 0.8, 0.8))),
        (shape: InfinitePlane(point: (0, 0, 9), normal: (0, 0, -1)), material: Phong(kd: (0.3, 0.2, 0.7))),
        (shape: InfinitePlane(point: (-3, 0, 0), normal: (1, 0, 0)), material: Phong(kd: (0.7, 0.2, 0.3))),
        (light: Point(position: (0, 2, 3), intensity: (7, 7, 7))),
"#;

fn boxed(camera: &str, shader: &str, extra: &str) -> String {
    format!(
        "Scene(film: (width: 48, height: 40), camera: {camera}, shader: {shader}, \
         background: (0.1, 0.1, 0.1), entities: [{BOX} {extra}])"
    )
}

/// A glass sphere of ior 1 bends nothing: the image equals the scene without it. The light sits
/// between the sphere and the wall, so the sphere casts no shadow into the view (glass blocks
/// shadow rays, as in the course).
#[test]
fn ior_one_sphere_vanishes() {
    let scene = |extra: &str| {
        format!(
            r#"Scene(film: (width: 48, height: 40),
            camera: Perspective(position: (0, 0, -3), look_at: (0, 0, 1)),
            shader: Direct(), background: (0.1, 0.1, 0.1),
            entities: [
                (shape: InfinitePlane(point: (0, 0, 9), normal: (0, 0, -1)), material: Phong(kd: (0.8, 0.6, 0.4), ks: (0.3, 0.3, 0.3), shininess: 8)),
                (light: Point(position: (0.5, 0.3, 7), intensity: (7, 7, 7))),
                {extra}
            ])"#
        )
    };
    let with = render_str(&scene(
        "(shape: Sphere(center: (0, -0.5, 3), radius: 1.5), material: Transmissive(ior: 1))",
    ));
    let without = render_str(&scene(""));
    finite(&with);
    assert!(with.stats.refraction > 100, "the sphere is in view");
    let worst = with
        .image
        .pixels
        .iter()
        .zip(&without.image.pixels)
        .map(|(p, q)| (*p - *q).abs().max_element())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "ior 1 changes a pixel by {worst}");
}

/// The camera inside a glass sphere: every ray leaves through the sphere; finite image, and
/// with ior 1 it is the plain box.
#[test]
fn camera_inside_glass_sphere() {
    let cam = "Perspective(position: (0, 0, 0), look_at: (0, 0, 1))";
    for ior in [1.0, 1.5, 2.4] {
        let r = render_str(&boxed(
            cam,
            "Global(samples: 4, max_depth: 1)",
            &format!(
                "(shape: Sphere(center: (0, 0, 0.2), radius: 1), material: Transmissive(ior: {ior}))"
            ),
        ));
        finite(&r);
        assert!(
            r.stats.refraction >= 48 * 40,
            "every camera ray refracts out"
        );
        assert!(r.image.mean().max_element() > 0.0);
    }
}

/// Total internal reflection: from inside dense glass, rays beyond the critical angle reflect.
/// With the camera off-centre in an ior-2.4 sphere (critical angle 24.6 degrees), many camera
/// rays reach the surface beyond it; they must come back as reflection rays, finite.
#[test]
fn total_internal_reflection_is_finite_and_counted() {
    let r = render_str(&boxed(
        "Perspective(position: (0.9, 0, 0), look_at: (0.9, 0, 1), fov: 120)",
        "Direct(max_specular: 64)",
        "(shape: Sphere(center: (0, 0, 0), radius: 1), material: Transmissive(ior: 2.4))",
    ));
    finite(&r);
    assert!(
        r.stats.reflection > 1000,
        "TIR rays: {}",
        r.stats.reflection
    );
}

/// Two facing mirrors and a camera between them looking straight at one: the ray bounces until
/// the specular cap and returns black; the render terminates and counts the bounces.
#[test]
fn facing_mirrors_terminate() {
    let text = r#"Scene(
        film: (width: 4, height: 4),
        camera: Orthographic(position: (0, 0, 0), look_at: (0, 0, 1), height: 0.1),
        shader: Direct(max_specular: 32),
        background: (1, 1, 1),
        entities: [
            (shape: InfinitePlane(point: (0, 0, 1), normal: (0, 0, -1)), material: Mirror(color: (0.9, 0.9, 0.9))),
            (shape: InfinitePlane(point: (0, 0, -1), normal: (0, 0, 1)), material: Mirror(color: (0.9, 0.9, 0.9))),
        ])"#;
    let r = render_str(text);
    finite(&r);
    assert!(r.image.pixels.iter().all(|p| *p == Vec3A::ZERO));
    // 32 reflections after the camera ray hits the first mirror, for each of 16 pixels.
    assert_eq!(r.stats.reflection, 16 * 32);
}

/// A zero-area triangle is ignored (with a warning), not a NaN normal.
#[test]
fn degenerate_triangle_is_ignored() {
    let s = scene(
        r#"Scene(film: (width: 8, height: 8), background: (0.2, 0.3, 0.4),
        entities: [(name: "sliver", shape: Triangle(a: (0, 0, 5), b: (1, 1, 5), c: (2, 2, 5)),
                    material: Phong(kd: (1, 1, 1)))])"#,
    );
    let prepared = rtis::extract(&s);
    assert!(prepared.geometry.is_empty());
    assert!(
        prepared
            .warnings
            .iter()
            .any(|w| w.contains("sliver") && w.contains("zero-area"))
    );
    let r = render_scene(&s);
    assert!(
        r.image
            .pixels
            .iter()
            .all(|p| *p == Vec3A::new(0.2, 0.3, 0.4))
    );
}

/// A point light lying on a surface: that surface gets no light from it (wi.n = 0 everywhere on
/// it), the rest of the scene does, and nothing is NaN.
#[test]
fn point_light_on_a_surface() {
    let text = r#"Scene(
        film: (width: 32, height: 32),
        camera: Perspective(position: (0, 3, -4), look_at: (0, 0, 0)),
        shader: Global(samples: 4, max_depth: 1),
        entities: [
            (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (0.8, 0.8, 0.8), ks: (0.5, 0.5, 0.5), shininess: 2)),
            (shape: Sphere(center: (0, 1, 2), radius: 0.5), material: Phong(kd: (0.8, 0.8, 0.8))),
            (light: Point(position: (0, 0, 0), intensity: (5, 5, 5))),
        ])"#;
    let direct = render_str(&text.replace("Global(samples: 4, max_depth: 1)", "Direct()"));
    finite(&direct);
    let g = render_str(text);
    finite(&g);
    // Look down the image centre column: the plane's pixels (bottom rows) are black in Direct;
    // the sphere's lower half, above the light, is lit.
    assert_eq!(direct.image.get(16, 31), Vec3A::ZERO);
    assert!(
        direct.image.pixels.iter().any(|p| p.x > 0.1),
        "the sphere is lit"
    );
}

/// Grazing views: a camera almost in the plane of the floor and a sphere seen at its rim.
#[test]
fn grazing_rays_are_finite() {
    for cam in [
        "Perspective(position: (0, -2.9999, -3), look_at: (0, -2.9999, 5))",
        "Perspective(position: (0, -3, -3), look_at: (0, -3, 5))",
        "Perspective(position: (0, 0, -3), look_at: (0, 0, 1), fov: 179)",
    ] {
        let r = render_str(&boxed(
            cam,
            "Global(samples: 4, max_depth: 2)",
            "(shape: Sphere(center: (0, -1, 4), radius: 1.5), material: Phong(kd: (0.5, 0.5, 0.5), ks: (0.5, 0.5, 0.5), shininess: 64))",
        ));
        finite(&r);
    }
}

/// A huge intensity: the EXR keeps the value, the PNG clamps to 255.
#[test]
fn huge_intensity_exr_keeps_png_clamps() {
    let text = r#"Scene(
        film: (width: 3, height: 3),
        camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 3),
        entities: [
            (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (1, 1, 1))),
            (light: Point(position: (0, 1, 0), intensity: (1e30, 1e30, 1e30))),
        ])"#;
    let r = render_str(text);
    finite(&r);
    let centre = r.image.get(1, 1);
    assert!((centre.x - 1e30).abs() / 1e30 < 1e-5, "{centre}");
    let dir = std::env::temp_dir().join(format!("rtis-huge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (exr, png) = (dir.join("huge.exr"), dir.join("huge.png"));
    rtis::render::output::save(&r.image, &exr, Default::default()).unwrap();
    rtis::render::output::save(&r.image, &png, Default::default()).unwrap();
    let back = rtis::render::output::load(&exr).unwrap();
    assert_eq!(back.get(1, 1), centre);
    let png8 = image::open(&png).unwrap().to_rgb8();
    assert_eq!(png8.get_pixel(1, 1).0, [255, 255, 255]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Depth-like settings are bounded with a located error, and the largest allowed chain runs as
/// a loop: two facing mirrors at `max_specular: 1024` trace exactly 1024 reflections per pixel
/// and return black, with no stack to overflow.
#[test]
fn specular_chains_are_capped_and_loop() {
    let text = |max: u32| {
        format!(
            r#"Scene(
        film: (width: 4, height: 4),
        camera: Orthographic(position: (0, 0, 0), look_at: (0, 0, 1), height: 0.1),
        shader: Global(samples: 1, max_depth: 1, max_specular: {max}),
        background: (1, 1, 1),
        entities: [
            (shape: InfinitePlane(point: (0, 0, 1), normal: (0, 0, -1)), material: Mirror(color: (0.9, 0.9, 0.9))),
            (shape: InfinitePlane(point: (0, 0, -1), normal: (0, 0, 1)), material: Mirror(color: (0.9, 0.9, 0.9))),
        ])"#
        )
    };
    let r = render_str(&text(1024));
    finite(&r);
    assert!(r.image.pixels.iter().all(|p| *p == Vec3A::ZERO));
    assert_eq!(r.stats.reflection, 16 * 1024);
    let err = rtis::scene::load_str(&text(100_000), "mirrors.ron", None)
        .err()
        .expect("max_specular beyond its cap is refused");
    let msg = err.to_string();
    assert!(
        msg.starts_with("mirrors.ron:4:64:") && msg.contains("at most 1024, got 100000"),
        "{msg}"
    );
    for bad in [
        "Path(rr_depth: 5000)",
        "Path(max_depth: 5000)",
        "Global(max_depth: 17)",
        "Direct(max_specular: 1025)",
    ] {
        let e = rtis::scene::load_str(&format!("Scene(shader: {bad})"), "s.ron", None)
            .err()
            .unwrap_or_else(|| panic!("{bad} is refused"));
        assert!(e.to_string().contains("at most"), "{bad}: {e}");
    }
}

/// The last line of defence: a sample that comes out non-finite or negative is dropped and
/// counted, and the pixel stays finite. Validation keeps such values out of scene files, so the
/// render scene is edited directly: one light made infinite, one negative.
#[test]
fn non_finite_and_negative_samples_are_dropped_and_counted() {
    let s = scene(
        r#"Scene(film: (width: 8, height: 8), shader: Direct(),
        entities: [
            (shape: InfinitePlane(point: (0, -1, 0), normal: (0, 1, 0)), material: Phong(kd: (0.5, 0.5, 0.5))),
            (light: Point(position: (0, 1, 2), intensity: (1, 1, 1))),
        ])"#,
    );
    let mut p = rtis::extract(&s);
    let clean = rtis::render(&p, &|| {});
    assert_eq!(clean.stats.dropped, 0);
    for bad in [f32::INFINITY, -1.0] {
        let rtis::light::Light::Point(l) = &mut p.lights[0] else {
            panic!("the box's lights are point lights");
        };
        l.intensity = Vec3A::splat(bad);
        let r = rtis::render(&p, &|| {});
        assert!(r.stats.dropped > 10, "{bad}: {} dropped", r.stats.dropped);
        assert!(
            r.image
                .pixels
                .iter()
                .all(|q| q.is_finite() && q.min_element() >= 0.0)
        );
    }
}
