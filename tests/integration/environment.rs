//! The environment light (src/light/environment.rs, src/light/sky_map.rs): exact answers under a
//! constant sky (a diffuse plane reflects `kd L`, a white furnace sphere vanishes into it) for
//! every strategy; a map's irradiance on a plane against a quadrature of the map; camera rays
//! that see the map in Mitsuba's orientation, directly and through a mirror; stability under a
//! texel 10^6 times brighter than the rest, an all-black map and a 1x1 map; and located errors.

use crate::common::{mean_and_se, render_scene, render_str, scene};
use glam::DVec3;
use glam::Vec3A;
use rtis::light::{Sky, SkyMap, WorldEnvironment};
use rtis::raster::Raster;
use rtis::render::film::Image;
use rtis::render::output::{Transfer, save};
use std::f64::consts::PI;
use std::path::PathBuf;

/// A folder of its own for one test's files.
fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtis-env-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Write a `w x h` map whose texel `(x, y)` is `f(x, y)` as OpenEXR, and return its path.
fn write_exr(name: &str, w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3A) -> PathBuf {
    let mut img = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            img.pixels[(y * w + x) as usize] = f(x, y);
        }
    }
    let path = dir(name).join("sky.exr");
    save(&img, &path, Transfer::Linear).unwrap();
    path
}

/// [`write_exr`], and the same map as rtis holds it.
fn write_map(name: &str, w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3A) -> (PathBuf, SkyMap) {
    let path = write_exr(name, w, h, &f);
    let texels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f(x, y).to_array())
        .collect();
    let map = SkyMap::new(Raster::new(w as usize, h as usize, texels).unwrap());
    (path, map)
}

/// Every way the renderer gathers light under the Physical model: Direct's light samples, and
/// the path tracer's three strategies with each light choice.
const STRATEGIES: &[&str] = &[
    "Direct(light_samples: 4)",
    "Path(max_depth: 1, lights: Mis)",
    "Path(max_depth: 1, lights: Light)",
    "Path(max_depth: 1, lights: Brdf)",
    "Path(max_depth: 1, lights: Mis, lights_per_vertex: One)",
    "Path(max_depth: 1, lights: Light, lights_per_vertex: Importance)",
];

/// A grey floor seen from above by an orthographic camera, under `light`.
fn floor_under(light: &str, shader: &str, spp: u32) -> String {
    format!(
        "Scene(film: (width: 24, height: 24, spp: {spp}), shader: {shader}, model: Physical,
               camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1),
                                    height: 2),
               entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                           material: Phong(kd: (0.5, 0.5, 0.5), ks: (0, 0, 0))),
                          (light: {light})])"
    )
}

/// Assert that the mean of the render's first channel is `want` within 5 standard errors
/// (and 1e-6 for a render without noise).
fn assert_mean(text: &str, want: f64, what: &str) {
    let r = render_str(text);
    let (mean, se) = mean_and_se(&r);
    assert!(
        (mean - want).abs() <= 5.0 * se + 1e-6 * want,
        "{what}: {mean:.5} against {want:.5} (5 se = {:.2e})",
        5.0 * se
    );
}

/// Under a constant sky `L` a diffuse floor's radiance is `kd L` (its hemisphere is all sky),
/// for every strategy.
#[test]
fn a_floor_under_a_constant_sky_reflects_kd_l() {
    for shader in STRATEGIES {
        let text = floor_under("Environment(radiance: (2, 2, 2))", shader, 16);
        assert_mean(&text, 0.5 * 2.0, shader);
    }
}

/// A white furnace: a Lambertian sphere of albedo 1 in a constant sky of radiance `L`
/// reflects `L` everywhere, so the whole image is `L`, sphere and sky alike, under every
/// strategy.
#[test]
fn a_white_furnace_disappears() {
    for lights in ["Mis", "Light", "Brdf"] {
        let text = format!(
            "Scene(film: (width: 24, height: 24, spp: 16), model: Physical,
               camera: Perspective(position: (0, 0, -4), look_at: (0, 0, 0), fov: 40),
               shader: Path(rr_depth: 8, lights: {lights}),
               entities: [(shape: Sphere(center: (0, 0, 0), radius: 1),
                           material: Phong(kd: (1, 1, 1), ks: (0, 0, 0))),
                          (light: Environment(radiance: (0.7, 0.7, 0.7)))])"
        );
        let r = render_scene(&scene(&text));
        let (mean, se) = mean_and_se(&r);
        assert!(
            (mean - 0.7).abs() <= 5.0 * se + 1e-6,
            "{lights}: {mean:.5} (5 se = {:.2e})",
            5.0 * se
        );
    }
}

/// The irradiance on an upward floor from a map: `E = int L(w) cos(theta) dw` over the upper
/// hemisphere, by a midpoint rule over `(u, v)` on a grid much finer than the map's texels.
fn irradiance_up(map: &SkyMap) -> f64 {
    let (nu, nv) = (1024, 1024);
    let mut e = 0.0;
    for j in 0..nv / 2 {
        let v = (j as f64 + 0.5) / nv as f64;
        let theta = v * PI;
        for i in 0..nu {
            let u = (i as f64 + 0.5) / nu as f64;
            let l = map.eval(u as f32, v as f32).x as f64;
            e += l * theta.cos() * theta.sin() * (PI / nv as f64) * (2.0 * PI / nu as f64);
        }
    }
    e
}

/// [`irradiance_up`] for the map turned by `rotate` (degrees about x, then y, then z): the
/// light's radiance over the world's upper hemisphere, on a fine midpoint grid in
/// `(theta, phi)` about the world's `+y`.
fn irradiance_up_rotated(map: &SkyMap, rotate: DVec3) -> f64 {
    let light = WorldEnvironment {
        sky: Sky::Map {
            map: std::sync::Arc::new(map.clone()),
            source: "test".into(),
        },
        scale: 1.0,
        rotate,
    }
    .extract(1.0);
    let (nt, np) = (768, 1536);
    let (dt, dp) = (0.5 * PI / nt as f64, 2.0 * PI / np as f64);
    let mut e = 0.0;
    for j in 0..nt {
        let theta = (j as f64 + 0.5) * dt;
        for i in 0..np {
            let phi = (i as f64 + 0.5) * dp;
            let w = Vec3A::new(
                (theta.sin() * phi.cos()) as f32,
                theta.cos() as f32,
                (theta.sin() * phi.sin()) as f32,
            );
            e += light.radiance(w).x as f64 * theta.cos() * theta.sin() * dt * dp;
        }
    }
    e
}

/// A map with a small bright sun over a blue-ish gradient: a floor under it has radiance
/// `(kd / pi) E`, `E` the map's irradiance, for every strategy (importance sampling, BSDF
/// sampling and their MIS all estimate the same integral), whatever the sky's rotation about
/// the vertical.
#[test]
fn a_floor_under_a_map_matches_its_irradiance() {
    let (w, h) = (64, 32);
    let sun = |x: u32, y: u32| (x == 40 || x == 41) && (y == 9 || y == 10);
    let (path, map) = write_map("floor", w, h, |x, y| {
        let s = if sun(x, y) { 200.0 } else { 0.0 };
        Vec3A::new(0.2 + s, 0.4 + s, 0.6 + 0.01 * x as f32 + s) * (1.0 - y as f32 / h as f32)
    });
    let unturned = 0.5 / PI * irradiance_up(&map);
    for rotate in [DVec3::ZERO, DVec3::new(30.0, 75.0, -20.0)] {
        let want = 0.5 / PI * irradiance_up_rotated(&map, rotate);
        if rotate == DVec3::ZERO {
            assert!(
                (want / unturned - 1.0).abs() < 1e-3,
                "{want} against {unturned}"
            );
        } else {
            // Tilted, the sun and the sky's gradient light the floor differently.
            assert!(
                (want / unturned - 1.0).abs() > 0.05,
                "{want} against {unturned}"
            );
        }
        for shader in STRATEGIES {
            let light = format!(
                "Environment(image: {path:?}, rotate: ({}, {}, {}))",
                rotate.x, rotate.y, rotate.z
            );
            assert_mean(&floor_under(&light, shader, 64), want, shader);
        }
    }
}

/// Camera rays see the map in Mitsuba's orientation: looking along +z, the centre of the
/// image (u = 1/2); along +x a quarter across; along -z the left and right edges' mean (u wraps
/// there); straight up, the top row. Through a mirror facing the camera, the map behind it.
#[test]
fn camera_rays_see_the_map_in_mitsubas_orientation() {
    // Each texel's colour names its column and row.
    let (path, _) = write_map("orient", 8, 5, |x, y| Vec3A::new(x as f32, y as f32, 1.0));
    let look = |dir: &str, up: &str| {
        let text = format!(
            "Scene(film: (width: 2, height: 2), shader: Direct(),
                   camera: Orthographic(position: (0, 0, 0), look_at: {dir}, up: {up}, height: 1),
                   entities: [(light: Environment(image: {path:?}))])"
        );
        let r = render_str(&text);
        r.image.pixels[0]
    };
    // u = 1/2: between columns 3 and 4 (centres at 3.5/8 and 4.5/8); v = 1/2: row 2 of 0..4.
    assert_eq!(look("(0, 0, 1)", "(0, 1, 0)"), Vec3A::new(3.5, 2.0, 1.0));
    // u = 1/4: between columns 1 and 2.
    assert_eq!(look("(1, 0, 0)", "(0, 1, 0)"), Vec3A::new(1.5, 2.0, 1.0));
    // Off the axes, which tells the map from its mirror image: u = 3/8, column 2.5 (mirrored,
    // 0.5).
    let x = look("(1, 0, 1)", "(0, 1, 0)").x;
    assert!((x - 2.5).abs() < 1e-4, "{x}");
    // u = 0: between the last column and the first.
    assert_eq!(look("(0, 0, -1)", "(0, 1, 0)"), Vec3A::new(3.5, 2.0, 1.0));
    assert_eq!(look("(0, 1, 0)", "(0, 0, 1)").y, 0.0);
    assert_eq!(look("(0, -1, 0)", "(0, 0, 1)").y, 4.0);
    // A mirror at z = 2 facing the camera, which looks along +z: the reflected rays look along
    // -z, and see u = 0 (tinted by the mirror's colour).
    let text = format!(
        "Scene(film: (width: 2, height: 2), shader: Direct(),
               camera: Orthographic(position: (0, 0, 0), look_at: (0, 0, 1), up: (0, 1, 0),
                                    height: 1),
               entities: [(shape: Rectangle(corner: (-2, -2, 2), u: (4, 0, 0), v: (0, 4, 0)),
                           material: Mirror(color: (0.5, 0.5, 0.5))),
                          (light: Environment(image: {path:?}))])"
    );
    assert_eq!(
        render_str(&text).image.pixels[0],
        Vec3A::new(1.75, 1.0, 0.5)
    );
}

/// Hard maps stay stable: a texel 10^6 times brighter than the rest lights a floor, within
/// noise of the exact value, with bounded weights under importance sampling. A light sample's
/// weight `L f cos / p` is at most `8 (kd / pi) int L dw`: within a cell the bilinear radiance
/// is at most 4 times the mean of its corners that the density follows, and `sin(theta)` at
/// most twice its mean over the cell's row. An all-black map gives black with no sample
/// dropped; a 1x1 map is a constant sky.
#[test]
fn hard_maps_stay_stable() {
    let (w, h) = (32, 16);
    let (path, map) = write_map("hot", w, h, |x, y| {
        Vec3A::splat(if (x, y) == (7, 4) { 1e6 } else { 1.0 })
    });
    let want = 0.5 / PI * irradiance_up(&map);
    let light = format!("Environment(image: {path:?})");
    assert_mean(
        &floor_under(&light, "Direct(light_samples: 4)", 16),
        want,
        "a texel 1e6 times brighter",
    );
    // One light sample per pixel: each pixel is one weight.
    let r = render_str(&floor_under(&light, "Direct(light_samples: 1)", 1));
    let bound = 8.0 * 0.5 / PI * map.integral().x as f64;
    let max = r
        .image
        .pixels
        .iter()
        .map(|p| p.x as f64)
        .fold(0.0, f64::max);
    assert!(max <= bound, "a weight of {max} above {bound}");

    let (black, _) = write_map("black", 8, 4, |_, _| Vec3A::ZERO);
    for shader in STRATEGIES {
        let light = format!("Environment(image: {black:?})");
        let r = render_str(&floor_under(&light, shader, 4));
        assert!(r.image.pixels.iter().all(|p| *p == Vec3A::ZERO), "{shader}");
    }

    let (one, _) = write_map("one", 1, 1, |_, _| Vec3A::splat(3.0));
    for shader in STRATEGIES {
        let light = format!("Environment(image: {one:?})");
        assert_mean(&floor_under(&light, shader, 16), 0.5 * 3.0, shader);
    }
}

/// The errors of environment lights, each located at the light and saying what to do.
#[test]
fn environment_errors_are_located() {
    let err = |light: &str, extra: &str| {
        let text = format!(
            "Scene({extra}entities: [(shape: Sphere(center: (0, 0, 3), radius: 1),
                                    material: Phong(kd: (1, 1, 1))),
                                   (light: {light})])"
        );
        rtis::scene::load_str(&text, "t.ron", None)
            .err()
            .unwrap_or_else(|| panic!("{light} loads"))
            .to_string()
    };
    let e = err("Environment(image: \"no-such-sky.exr\")", "");
    assert!(
        e.contains("t.ron:3:") && e.contains("no-such-sky.exr"),
        "{e}"
    );
    assert!(e.to_lowercase().contains("no such file"), "{e}");
    let e = err("Environment(image: \"a.exr\", radiance: (1, 1, 1))", "");
    assert!(e.contains("not both"), "{e}");
    let e = err("Environment(scale: 2)", "");
    assert!(e.contains("needs an `image"), "{e}");
    let e = err("Environment(radiance: (1, 1, 1), scale: -1)", "");
    assert!(e.contains("scale") || e.contains("from 0"), "{e}");
    let e = err(
        "Environment(radiance: (1, 1, 1))",
        "background: (0.1, 0.1, 0.1), ",
    );
    assert!(e.contains("has a background of"), "{e}");
    // A black one (as cornell.ron writes) is the same as none.
    let text =
        "Scene(background: (0, 0, 0), entities: [(light: Environment(radiance: (1, 1, 1)))])";
    assert!(rtis::scene::load_str(text, "t.ron", None).is_ok());
    // Radiance times scale beyond 1e30.
    let e = err("Environment(radiance: (1e25, 1, 1), scale: 1e6)", "");
    assert!(e.contains("above the limit of 1e30"), "{e}");
    let text = "Scene(entities: [(light: Environment(radiance: (1, 1, 1))),
                                 (light: Environment(radiance: (2, 2, 2)))])";
    let e = rtis::scene::load_str(text, "t.ron", None)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("t.ron:2:") && e.contains("the first at t.ron:1:"),
        "{e}"
    );
    // A texel that is not a radiance.
    let nan = write_exr("nan", 2, 2, |x, _| {
        Vec3A::splat(if x == 1 { f32::NAN } else { 1.0 })
    });
    let e = err(&format!("Environment(image: {nan:?})"), "");
    assert!(e.contains("texel (1, 0)"), "{e}");
}

/// Side by side with Mitsuba 3 (bench/mitsuba_sky_reference.py): a floor and three spheres
/// (diffuse, rough gold, glass) under the generated sky of scenes/assets/sky.exr, a map with a
/// sun about 3 degrees across, turned 40 degrees about the vertical. Two renders of 64 spp
/// agree with Mitsuba's 16384 spp on 4x4 blocks within what noise explains, and in the mean
/// within 1%.
#[test]
fn a_sky_matches_mitsuba() {
    let (mse, explained, m) =
        crate::common::against_mitsuba("sky.ron", "mitsuba_sky_160x120_spp16384.exr", 0.005355);
    eprintln!("sky: block MSE vs Mitsuba {mse:.3e}; noise explains {explained:.3e}");
    assert!(
        mse < 1.5 * explained,
        "block MSE {mse:.3e} vs {explained:.3e}"
    );
    let mean = Vec3A::new(0.334792, 0.374639, 0.493499);
    assert!(
        ((m - mean) / mean).abs().max_element() < 0.01,
        "mean {m} vs {mean}"
    );
}

/// The environment shares the choice of one light with the others: a floor point lit by a
/// point light, a sun and a constant sky `L` (its whole upper hemisphere) has radiance
/// `(kd / pi)(I cos / d^2 + E cos) + kd L`, under every light choice (all, one by power, one by
/// importance) with MIS and with light sampling alone, within 5 standard errors.
#[test]
fn the_sky_shares_the_light_choice() {
    let (kd, l) = (0.5f64, 0.3f64);
    let (p, i_p) = ([-0.5f64, 2.0, -0.5], 3.0f64);
    let (sun, e) = ([0.3f64, -1.0, 0.2], 1.5f64);
    let d2 = p.iter().map(|c| c * c).sum::<f64>();
    let sun_cos = -sun[1] / sun.iter().map(|c| c * c).sum::<f64>().sqrt();
    let want = kd / PI * (i_p * (p[1] / d2.sqrt()) / d2 + e * sun_cos) + kd * l;
    for per_vertex in ["All", "One", "Importance"] {
        for lights in ["Mis", "Light"] {
            let text = format!(
                "Scene(film: (width: 32, height: 32, spp: 16),
                   camera: Perspective(position: (3, 1, -0.5), look_at: (0, 0, 0), fov: 0.001),
                   model: Physical,
                   shader: Path(max_depth: 1, lights: {lights}, lights_per_vertex: {per_vertex}),
                   entities: [
                     (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                      material: Phong(kd: ({kd}, {kd}, {kd}), ks: (0, 0, 0))),
                     (light: Point(position: ({}, {}, {}), intensity: ({i_p}, {i_p}, {i_p}))),
                     (light: Directional(direction: ({}, {}, {}), irradiance: ({e}, {e}, {e}))),
                     (light: Environment(radiance: ({l}, {l}, {l}))),
                   ])",
                p[0], p[1], p[2], sun[0], sun[1], sun[2]
            );
            assert_mean(&text, want, &format!("{per_vertex}, {lights}"));
        }
    }
}
