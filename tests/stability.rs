//! Hard cases stay numerically stable: the empty-room invariant at every size, scale and
//! offset, and random scenes at extreme scales (proptest).

mod common;

use common::scene;
use glam::DVec3;
use rtis::render;

/// The course's box without its spheres: five planes (a convex room open behind the camera)
/// and three point lights inside, scaled by `s` and translated by `t`.
fn room(width: u32, height: u32, s: f64, t: DVec3, shadows: bool) -> String {
    let p = |x: f64, y: f64, z: f64| {
        let q = t + s * DVec3::new(x, y, z);
        format!("({:?}, {:?}, {:?})", q.x, q.y, q.z)
    };
    let plane = |pt: String, n: &str, kd: &str| {
        format!("(shape: InfinitePlane(point: {pt}, normal: {n}), material: Phong(kd: {kd})),")
    };
    let light = |pt: String| {
        let i = 7.0 * s * s;
        format!("(light: Point(position: {pt}, intensity: ({i:?}, {i:?}, {i:?}))),")
    };
    format!(
        "Scene(film: (width: {width}, height: {height}), shader: Direct(),
          camera: Perspective(position: {}, look_at: {}, fov: 60),
          effects: (shadows: {shadows}),
          entities: [{} {} {} {} {} {} {} {}])",
        p(0.0, 0.0, -3.0),
        p(0.0, 0.0, 1.0),
        plane(p(-3.0, 0.0, 0.0), "(1, 0, 0)", "(0.7, 0.2, 0.3)"),
        plane(p(3.0, 0.0, 0.0), "(-1, 0, 0)", "(0.2, 0.7, 0.3)"),
        plane(p(0.0, 3.0, 0.0), "(0, -1, 0)", "(0.8, 0.8, 0.8)"),
        plane(p(0.0, -3.0, 0.0), "(0, 1, 0)", "(0.8, 0.8, 0.8)"),
        plane(p(0.0, 0.0, 9.0), "(0, 0, -1)", "(0.3, 0.2, 0.7)"),
        light(p(0.0, 2.0, 0.0)),
        light(p(0.0, 2.0, 3.0)),
        light(p(0.0, 2.0, 6.0)),
    )
}

/// Pixels that differ between the room rendered with shadow rays and without.
fn seam_pixels(width: u32, height: u32, s: f64, t: DVec3) -> usize {
    let on = render(
        &rtis::extract(&scene(&room(width, height, s, t, true))),
        &|| {},
    );
    let off = render(
        &rtis::extract(&scene(&room(width, height, s, t, false))),
        &|| {},
    );
    assert!(on.stats.shadow > 0 && off.stats.shadow == 0);
    assert_eq!(on.stats.dropped + off.stats.dropped, 0);
    on.image
        .pixels
        .iter()
        .zip(&off.image.pixels)
        .filter(|(a, b)| a != b)
        .count()
}

/// An empty convex room lit from inside has no shadows: every point sees every light. So it
/// renders identically with shadow rays on and off, at any resolution (odd ones too), at
/// scales from 1e-3 to 1e3 and translated up to 1e6 from the origin. A shadow ray from a point
/// at a crease that is blocked by the neighbouring wall (seam acne) breaks it.
#[test]
fn empty_room_has_no_seam_pixels() {
    let mut failures = Vec::new();
    for (w, h) in [(720, 576), (333, 271), (97, 61)] {
        for s in [1e-3, 1.0, 1e3] {
            for t in [
                DVec3::ZERO,
                DVec3::new(1e6, -1e6, 1e6),
                DVec3::new(-3e5, 7e5, 2e4),
            ] {
                let n = seam_pixels(w, h, s, t);
                if n > 0 {
                    failures.push(format!("{w}x{h} scale {s} offset {t}: {n} seam pixels"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
