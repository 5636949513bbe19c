//! Cameras (src/camera/): the thin lens. With aperture 0 it is the pinhole to the bit; every
//! ray through the lens for an image point meets the plane in focus at the pinhole ray's point
//! there; the blur of a point off that plane is the thin-lens circle of confusion, measured in
//! a render.

use crate::common::{bits, render_str, scene};
use glam::{DVec3, Vec3A};
use rtis::camera::{Camera, Handedness, Projection, WorldCamera, WorldLens};
use rtis::sampling::Sampler;

fn camera(lens: Option<WorldLens>) -> Camera {
    WorldCamera {
        projection: Projection::Perspective { fov: 40.0, lens },
        position: DVec3::ZERO,
        look_at: DVec3::new(0.3, -0.2, 1.0),
        up: DVec3::Y,
        handedness: Handedness::Left,
    }
    .extract(1.5)
}

/// `aperture_radius: 0` (with any focus distance) is no lens: the box's own camera written
/// out with it renders the bits of the box as it is; an aperture above 0 does not.
#[test]
fn a_zero_aperture_is_the_pinhole_to_the_bit() {
    let base = "film: (width: 24, height: 18, spp: 4), shader: Path(max_depth: 3)";
    let pinhole = render_str(&format!("Scene(extends: \"cornell.ron\", {base})"));
    let s = scene(&format!("Scene(extends: \"cornell.ron\", {base})"));
    let c = s.settings.camera;
    let Projection::Perspective { fov, lens } = c.projection else {
        panic!("the box has a perspective camera");
    };
    assert_eq!(lens, None);
    let with = |lens: &str| {
        render_str(&format!(
            "Scene(extends: \"cornell.ron\", {base},
                   camera: Perspective(position: ({}, {}, {}), look_at: ({}, {}, {}),
                                       up: ({}, {}, {}), fov: {fov}{lens}))",
            c.position.x,
            c.position.y,
            c.position.z,
            c.look_at.x,
            c.look_at.y,
            c.look_at.z,
            c.up.x,
            c.up.y,
            c.up.z,
        ))
    };
    for zero in [
        ", aperture_radius: 0",
        ", aperture_radius: 0, focus_distance: 2",
    ] {
        assert_eq!(bits(&with(zero).image), bits(&pinhole.image), "{zero}");
    }
    let open = with(", aperture_radius: 0.05, focus_distance: 2");
    assert_ne!(bits(&open.image), bits(&pinhole.image), "a lens must blur");
}

/// Every ray through the lens for an image point meets the plane in focus where the pinhole
/// ray does, and leaves from a point on the lens disk.
#[test]
fn points_on_the_focus_plane_are_sharp() {
    let (radius, focus) = (0.25, 4.0);
    let lens = camera(Some(WorldLens {
        radius,
        focus_distance: focus,
    }));
    let pinhole = camera(None);
    let Camera::Perspective(p) = lens else {
        panic!("a perspective camera")
    };
    let forward = p.basis.forward;
    let on_plane = |o: Vec3A, d: Vec3A| o + d * ((focus as f32 - o.dot(forward)) / d.dot(forward));
    let mut s = Sampler::new(1, 2, 3);
    for (u, v) in [(0.5, 0.5), (0.0, 0.0), (1.0, 0.3), (0.2, 0.9)] {
        let want = {
            let r = pinhole.ray(u, v, || panic!("a pinhole draws no lens sample"));
            on_plane(r.o, r.d)
        };
        let mut widest = 0.0f32;
        for _ in 0..1000 {
            let r = lens.ray(u, v, || s.next_2d());
            widest = widest.max(r.o.length());
            assert!(r.o.length() <= radius as f32 * (1.0 + 1e-6), "{:?}", r.o);
            assert!(
                r.o.dot(forward).abs() < 1e-6,
                "the lens is in the plane of right and up"
            );
            let got = on_plane(r.o, r.d);
            assert!(
                (got - want).length() < 1e-5 * focus as f32,
                "({u}, {v}): {got} against {want}"
            );
        }
        assert!(
            widest > 0.9 * radius as f32,
            "the lens's edge is never used: {widest}"
        );
    }
}

/// An emitting sphere on the axis, behind the plane in focus, blurs into the convolution of
/// its image (a disk of radius `a = s / sqrt(z^2 - s^2)` on the image plane at distance 1) with
/// the thin-lens circle of confusion (radius `c = r |z - f| / (f z)`, by similar triangles from
/// the lens of radius `r` to the point in focus at `f`). Within `c - a` of the centre a pixel
/// sees the sphere through a fraction `(a / c)^2` of the lens; beyond `c + a`, not at all.
/// With a pinhole the same sphere is a sharp disk of radius `a`.
#[test]
fn the_blur_of_a_point_off_focus_is_the_circle_of_confusion() {
    let (r, f, z, s, fov, side) = (0.5f64, 5.0f64, 10.0f64, 0.3f64, 30.0f64, 101u32);
    let text = |lens: &str| {
        format!(
            "Scene(film: (width: {side}, height: {side}, spp: 256), shader: Path(max_depth: 1),
                   model: Physical,
                   camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), fov: {fov}{lens}),
                   entities: [(shape: Sphere(center: (0, 0, {z}), radius: {s}),
                               material: Phong(kd: (0, 0, 0)),
                               emitter: Emitter(radiance: (1, 1, 1)))])"
        )
    };
    let blurred = render_str(&text(&format!(
        ", aperture_radius: {r}, focus_distance: {f}"
    )));
    let sharp = render_str(&text(""));
    // Pixels per unit of the image plane at distance 1.
    let px = side as f64 / 2.0 / (fov.to_radians() / 2.0).tan();
    let c = r * (z - f).abs() / (f * z) * px;
    let a = s / (z * z - s * s).sqrt() * px;
    let centre = (side as f64 - 1.0) / 2.0;
    // (distance of the pixel's centre from the image centre, its value)
    let pixels = |img: &rtis::render::film::Image| -> Vec<(f64, f64)> {
        (0..side * side)
            .map(|i| {
                let (x, y) = (i % side, i / side);
                let d = ((x as f64 - centre).powi(2) + (y as f64 - centre).powi(2)).sqrt();
                (d, img.get(x, y).x as f64)
            })
            .collect()
    };
    let half_diagonal = std::f64::consts::FRAC_1_SQRT_2;
    let blur = pixels(&blurred.image);
    // Nothing beyond c + a.
    for &(d, v) in &blur {
        assert!(
            v == 0.0 || d - half_diagonal <= c + a,
            "lit at {d:.2} px; c + a = {:.2}",
            c + a
        );
    }
    // Within c - a: every pixel lit, at (a / c)^2 on average (binomial noise of 256 samples a
    // pixel, 5 standard deviations over the pixels averaged).
    let inner: Vec<f64> = blur
        .iter()
        .filter(|(d, _)| d + half_diagonal < c - a)
        .map(|&(_, v)| v)
        .collect();
    assert!(
        inner.len() >= 9 && inner.iter().all(|&v| v > 0.0),
        "{inner:?}"
    );
    let mean = inner.iter().sum::<f64>() / inner.len() as f64;
    let p = (a / c).powi(2);
    let sigma = (p * (1.0 - p) / (256.0 * inner.len() as f64)).sqrt();
    assert!(
        (mean - p).abs() < 5.0 * sigma,
        "mean {mean:.4} against (a/c)^2 = {p:.4} +- {sigma:.4}"
    );
    // The pinhole: lit exactly where the sphere's disk of radius a is.
    for (d, v) in pixels(&sharp.image) {
        if d + half_diagonal < a {
            assert_eq!(v, 1.0, "inside the sharp disk at {d:.2} px");
        }
        if d - half_diagonal > a {
            assert_eq!(v, 0.0, "outside the sharp disk at {d:.2} px");
        }
    }
}

/// Mitsuba 3's image of a thin lens focused on the middle of three diffuse spheres, lit by two
/// spot lights and a faint sun (`thinlens`, `spot`, `directional`;
/// bench/mitsuba_lights_reference.py, 4096 spp, llvm_ad_rgb, noise RMSE 0.00243 per pixel).
/// rtis renders the same scene (tests/data/lens_spot.ron) twice at 64 spp; on 4x4 blocks, the
/// mean squared difference from Mitsuba is within 1.5 times what the two noises explain, and
/// the image means agree within 1%.
#[test]
fn lens_spots_and_sun_match_mitsuba() {
    let (mse, explained, m) = crate::common::against_mitsuba(
        "lens_spot.ron",
        "mitsuba_lens_spot_160x120_spp4096.exr",
        0.00243,
    );
    eprintln!(
        "lens, spots and sun: block MSE vs Mitsuba {mse:.3e}; noise explains {explained:.3e}"
    );
    assert!(
        mse < 1.5 * explained,
        "block MSE {mse:.3e} vs {explained:.3e}"
    );
    let mean = Vec3A::new(0.069236, 0.070572, 0.064752);
    assert!(
        ((m - mean) / mean).abs().max_element() < 0.01,
        "mean {m} vs {mean}"
    );
}

/// Pixel filters (src/sampling/filter.rs): a vertical edge between white (x >= 0) and black,
/// on a pixel boundary, seen orthographically at one scene unit per pixel. With the box each
/// pixel is all one side; with a Gaussian of standard deviation `s` (truncated at 4 s), pixel
/// `c` is the share of the filter around its centre that lies past the edge,
/// `(erf(4 / sqrt 2) - erf(d / (s sqrt 2))) / (2 erf(4 / sqrt 2))` with `d` its distance to the
/// edge, within the stratification's noise at 4096 spp. A stddev above 8 is refused.
#[test]
fn a_gaussian_filter_blurs_an_edge_by_its_profile() {
    let text = |filter: &str| {
        format!(
            "Scene(film: (width: 32, height: 4, spp: 4096{filter}),
                   shader: Intersection(color: (1, 1, 1)),
                   camera: Orthographic(position: (0, 0, -5), look_at: (0, 0, 0), up: (0, 1, 0),
                                        height: 4),
                   entities: [(shape: Rectangle(corner: (0, -50, 0), u: (100, 0, 0),
                                                v: (0, 100, 0)),
                               material: Phong(kd: (1, 1, 1)))])"
        )
    };
    let boxed = crate::common::render_str(&text(""));
    for c in 0..32 {
        let want = if c >= 16 { 1.0 } else { 0.0 };
        assert_eq!(boxed.image.get(c, 1).x, want, "box, column {c}");
    }
    for s in [0.5f64, 1.5] {
        let r = crate::common::render_str(&text(&format!(", filter: Gaussian(stddev: {s})")));
        let e = libm::erf(4.0 / std::f64::consts::SQRT_2);
        for c in 0..32u32 {
            // The edge's distance from the pixel's centre, along +x.
            let d = 16.0 - (c as f64 + 0.5);
            let want = if d >= 4.0 * s {
                0.0
            } else if d <= -4.0 * s {
                1.0
            } else {
                (e - libm::erf(d / (s * std::f64::consts::SQRT_2))) / (2.0 * e)
            };
            let got = r.image.get(c, 1).x as f64;
            assert!(
                (got - want).abs() < 2e-3,
                "stddev {s}, column {c}: {got} against {want}"
            );
        }
    }
    let e = rtis::scene::load_str(&text(", filter: Gaussian(stddev: 9)"), "t.ron", None)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("at most 8 pixels"), "{e}");
}

/// `handedness: Right` (Mitsuba's) renders the mirror image of the course's camera: a seen
/// checkerboard emitter, every column of one the other's mirror, pixel for pixel.
#[test]
fn right_handedness_mirrors_the_image() {
    let text = |hand: &str| {
        format!(
            "Scene(film: (width: 8, height: 6, spp: 1), shader: Path(max_depth: 1), model: Physical,
                   camera: Orthographic(position: (0, 0, -5), look_at: (0, 0, 0), up: (0, 1, 0),
                                        height: 2{hand}),
                   entities: [
                     (shape: Rectangle(corner: (-2, 1, 0), u: (4, 0, 0), v: (0, -2, 0)),
                      emitter: (radiance: Checkerboard(color0: (0.9, 0.8, 0.7),
                                                       color1: (0.1, 0.2, 0.3),
                                                       uv_transform: (scale: (3, 2))),
                                two_sided: true))])"
        )
    };
    let left = render_str(&text("")).image;
    let right = render_str(&text(", handedness: Right")).image;
    let mut differs = false;
    for row in 0..6 {
        for col in 0..8 {
            assert_eq!(
                left.get(col, row),
                right.get(7 - col, row),
                "({col}, {row})"
            );
            differs |= left.get(col, row) != right.get(col, row);
        }
    }
    assert!(
        differs,
        "the image is its own mirror: the test sees nothing"
    );
}
