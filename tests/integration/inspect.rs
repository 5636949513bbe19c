//! Inspected renders (src/render/inspect.rs): the parts by technique and by bounce sum to the
//! render to the bit, a replayed sample adds what the render added, the per-pixel ray counts
//! sum to the render's, the path-length layer matches the cost rule in the closed room, and a
//! firefly made on purpose is found where it is.

use crate::common::{self, bits, scene};
use rtis::render::exact::RgbSum;
use rtis::render::inspect::{Inspect, inspect, inspect_pixel, luminance, replay};
use rtis::render::{pixel_sum, render, render_sample};
use rtis::shader::record::Event;
use rtis::stats::RayStats;
use std::sync::atomic::AtomicBool;

/// A small room with every kind of light (point, spot, sphere emitter, environment) and of
/// material the model shades, under `shader`.
fn room(shader: &str, model: &str) -> String {
    let bsdfs = if model == "Physical" {
        "(shape: Sphere(center: (0.8, -0.6, 0.3), radius: 0.4), material: RoughConductor(alpha: 0.2, material: \"Au\")),
         (shape: Sphere(center: (0, -0.7, -0.8), radius: 0.3), material: RoughPlastic(alpha: 0.1, diffuse_reflectance: (0.2, 0.4, 0.7))),
         (shape: Sphere(center: (-0.4, 0.6, -0.9), radius: 0.3), material: Plastic(diffuse_reflectance: (0.6, 0.3, 0.2))),"
    } else {
        ""
    };
    format!(
        "Scene(film: (width: 12, height: 10, spp: 6), shader: {shader}, model: {model},
          camera: Perspective(position: (0, 0, 3.5), look_at: (0, 0, 0), fov: 50),
          entities: [
            (shape: InfinitePlane(point: (0, -1, 0), normal: (0, 1, 0)), material: Phong(kd: (0.6, 0.6, 0.6), ks: (0.2, 0.2, 0.2), shininess: 20)),
            (shape: InfinitePlane(point: (0, 0, -1.5), normal: (0, 0, 1)), material: Phong(kd: (0.5, 0.3, 0.2))),
            (shape: Sphere(center: (-0.7, -0.5, 0), radius: 0.5), material: Transmissive(ior: 1.5)),
            (shape: Sphere(center: (0.2, 0.4, -0.5), radius: 0.3), material: Mirror()),
            {bsdfs}
            (shape: Sphere(center: (0, 1.3, 0), radius: 0.2), emitter: Emitter(radiance: (8, 7, 6))),
            (light: Point(position: (1, 1, 1), intensity: (2, 2, 2))),
            (light: Spot(position: (-1, 1.2, 1), direction: (0.5, -1, -0.5), intensity: (3, 3, 3))),
            (light: Environment(radiance: (0.3, 0.35, 0.4))),
          ])"
    )
}

/// An inspected render with its counters and `fireflies` fireflies ranked against each pixel.
fn counted(fireflies: usize) -> Inspect<'static> {
    Inspect {
        fireflies,
        counters: true,
        against: None,
    }
}

/// Every strategy and model of the path tracer, as scene text; every other one draws Sobol'
/// points.
fn path_variants() -> Vec<String> {
    let mut out = Vec::new();
    for model in ["Course", "Physical"] {
        for lights in ["Light", "Brdf", "Mis"] {
            for per_vertex in ["All", "One", "Importance"] {
                for sampling in ["Uniform", "Cosine", "Brdf"] {
                    let shader = format!(
                        "Path(max_depth: 6, rr_depth: 2, sampling: {sampling}, lights: {lights}, \
                         lights_per_vertex: {per_vertex})"
                    );
                    let text = room(&shader, model);
                    out.push(if out.len() % 2 == 1 {
                        let sobol = text.replace("spp: 6)", "spp: 6, sampler: Sobol)");
                        assert!(sobol.contains("sampler: Sobol"), "room() changed");
                        sobol
                    } else {
                        text
                    });
                }
            }
        }
    }
    out
}

/// The sum of exact sums.
fn total(parts: &[RgbSum]) -> RgbSum {
    let mut t = RgbSum::default();
    for p in parts {
        t += *p;
    }
    t
}

/// For every strategy and model: each pixel's parts by technique and by bounce sum exactly to
/// its exact sum, which is the render's; and the inspected image is the render's, bit for bit.
#[test]
fn parts_sum_to_the_render_bit_for_bit() {
    let _limit = common::deadline(300);
    let mut in_waves = 0;
    for text in path_variants() {
        let s = rtis::extract(&scene(&text));
        // The plain render runs these in waves (BRDF and cosine sampling) or one ray at a
        // time (uniform sampling); the inspected render always one at a time.
        let waves = rtis::render::waves::applies(&s);
        assert_eq!(waves, !text.contains("sampling: Uniform"), "{text}");
        in_waves += waves as usize;
        let mut some_light = [false; 3];
        for row in 0..s.film.height {
            for col in 0..s.film.width {
                let mut stats = RayStats::default();
                let (sums, _) = inspect_pixel(
                    &s,
                    (col, row),
                    0..s.film.spp,
                    true,
                    &mut stats,
                    |_, _, _| {},
                );
                let render = pixel_sum(&s, col, row, 0..s.film.spp, &mut RayStats::default());
                assert_eq!(sums.sum, render, "{text}");
                assert_eq!(total(&sums.techniques), sums.sum, "{text}");
                assert_eq!(total(&sums.bounces), sums.sum, "{text}");
                // Only the path tracer's techniques hold light.
                assert_eq!(sums.techniques[3], RgbSum::default());
                for (k, t) in sums.techniques[..3].iter().enumerate() {
                    some_light[k] |= *t != RgbSum::default();
                }
            }
        }
        // Emitted light is seen in every variant, and the light sample finds some wherever
        // it runs (point lights are always light-sampled).
        assert!(some_light[0] && some_light[1], "{text}");
        let inspected = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
        let rendered = render(&s, &|| {});
        assert_eq!(bits(&inspected.image), bits(&rendered.image), "{text}");
        assert_eq!(inspected.stats, rendered.stats, "{text}");
    }
    assert_eq!(in_waves, 36, "two samplings of three, in 54 variants");
}

/// Under MIS both techniques of the area light find some of it: BSDF-sampled light is not
/// all zero-weighted.
#[test]
fn mis_splits_the_area_light_between_both_techniques() {
    let s = rtis::extract(&scene(&room(
        "Path(max_depth: 4, sampling: Brdf, lights: Mis)",
        "Physical",
    )));
    let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
    let sum = |t: usize| -> f64 { r.pixels.iter().map(|p| p.techniques[t].x as f64).sum() };
    assert!(sum(1) > 0.0 && sum(2) > 0.0, "{} {}", sum(1), sum(2));
    // Under `Light` the area light met by a BSDF-sampled ray counts nothing: what the Bsdf
    // part holds came through mirrors and glass after a sampled vertex (weight 1), or is the
    // background; with the mirror, the glass, the smooth plastic's coating and the
    // environment gone, only light sampling and what the camera sees remain.
    let text = room(
        "Path(max_depth: 4, sampling: Brdf, lights: Light)",
        "Physical",
    )
    .replace("Transmissive(ior: 1.5)", "Phong(kd: (0.5, 0.5, 0.5))")
    .replace("Mirror()", "Phong(kd: (0.5, 0.5, 0.5))")
    .replace(
        "Plastic(diffuse_reflectance: (0.6, 0.3, 0.2))",
        "Phong(kd: (0.6, 0.3, 0.2))",
    )
    .replace("(light: Environment(radiance: (0.3, 0.35, 0.4))),", "");
    let s = rtis::extract(&scene(&text));
    let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
    assert!(
        r.pixels
            .iter()
            .all(|p| p.techniques[2] == glam::Vec3A::ZERO)
    );
    assert!(
        r.pixels
            .iter()
            .any(|p| p.techniques[1] != glam::Vec3A::ZERO)
    );
}

/// A replayed sample adds, to the bit, what the render added for it, and its events are
/// those of a path: hits, contributions that sum to it, scattered rays.
#[test]
fn a_replay_adds_what_the_render_added() {
    let _limit = common::deadline(120);
    for text in path_variants().into_iter().step_by(5) {
        let s = rtis::extract(&scene(&text));
        for (col, row, k) in [(0, 0, 0), (5, 7, 3), (11, 9, 5), (6, 4, 1)] {
            let mut stats = RayStats::default();
            let want = render_sample(&s, col, row, k, &mut stats);
            let r = replay(&s, col, row, k);
            assert_eq!(r.sum, want, "{text} {col},{row} #{k}");
            assert_eq!(r.stats.total(), stats.total(), "{text}");
            // The contributions the events list sum to the same bits.
            let mut sum = RgbSum::default();
            for e in &r.events {
                if let Event::Add { l, .. } = e {
                    sum.add(glam::Vec3A::from_array(*l));
                }
            }
            assert_eq!(sum, want, "{text}");
            let hits = r
                .events
                .iter()
                .filter(|e| matches!(e, Event::Hit { .. }))
                .count() as u64;
            assert_eq!(
                hits,
                r.stats.total()
                    - r.stats.shadow
                    - r.events
                        .iter()
                        .filter(|e| matches!(e, Event::Escape { .. }))
                        .count() as u64,
                "a hit per ray that is not a shadow ray and did not escape"
            );
        }
    }
}

/// Outside Path's waves, a render traces each pixel's camera rays in groups of up to
/// `MAX_LANES` samples (`render::pixel_sum`): in packets where every primitive is in the BVH,
/// in lanes where none is. Every sample still adds what its replay (one ray at a time) adds, whatever range of
/// samples a pass starts and ends at, with the same ray counts.
#[test]
fn groups_of_camera_rays_add_what_each_sample_alone_adds() {
    let dir = common::scenes_dir();
    let area = std::fs::read_to_string(dir.join("mitsuba-cornell.ron"))
        .unwrap()
        .replace(
            "width: 128, height: 128, spp: 64",
            "width: 9, height: 7, spp: 19",
        )
        // (Uniform sampling here too: not in waves.)
        .replace("sampling: Brdf)", "sampling: Uniform, lights: Mis)");
    let boxed = std::fs::read_to_string(dir.join("cornell-physical.ron"))
        .unwrap()
        .replace(
            "extends: \"cornell.ron\"",
            &format!("extends: {:?}", dir.join("cornell.ron")),
        )
        .replace(
            "width: 360, height: 288, spp: 64",
            "width: 9, height: 7, spp: 19",
        )
        // (Uniform sampling: not in waves, `render::waves`, whose test is path_waves.rs.)
        .replace("sampling: Brdf)", "sampling: Uniform)");
    for text in [area, boxed] {
        let s = rtis::extract(&scene(&text));
        assert!(!rtis::render::waves::applies(&s));
        assert!(
            s.geometry.groups_pay(),
            "every primitive in the BVH, or none"
        );
        for (col, row) in [(0, 0), (4, 3), (8, 6), (2, 5)] {
            for samples in [0..19, 3..19, 5..6, 0..16] {
                let (mut grouped, mut alone) = (RayStats::default(), RayStats::default());
                let got = pixel_sum(&s, col, row, samples.clone(), &mut grouped);
                let mut want = RgbSum::default();
                for k in samples.clone() {
                    want += render_sample(&s, col, row, k, &mut alone);
                }
                assert_eq!(got, want, "{col},{row} {samples:?}");
                assert_eq!(grouped.total(), alone.total(), "{col},{row} {samples:?}");
                assert_eq!(grouped.camera, samples.len() as u64);
            }
        }
    }
}

/// The per-pixel ray counts sum to the render's totals, and the first-hit layers and
/// variance are what the scene makes them.
#[test]
fn per_pixel_counts_sum_to_the_render() {
    let s = rtis::extract(&scene(&room("Path(rr_depth: 3)", "Physical")));
    let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
    let mut sum = RayStats::default();
    for p in &r.pixels {
        sum += p.rays;
    }
    assert_eq!(sum, r.stats);
    assert_eq!(sum, render(&s, &|| {}).stats);
    for p in &r.pixels {
        assert!(p.seconds > 0.0);
        assert!(p.variance.min_element() >= 0.0 && p.variance.is_finite());
        // Every camera ray meets a surface here: a normal, a depth, an albedo.
        assert!(p.depth > 0.0 && p.normal != glam::Vec3A::ZERO, "{p:?}");
        assert!(p.albedo != glam::Vec3A::ZERO, "{p:?}");
    }
}

/// The variance layer is the variance of the pixel's mean, from its samples' spread: the
/// unbiased variance of the samples each render adds (`render_sample`), over their count.
#[test]
fn the_variance_layer_is_the_spread_of_the_samples_the_render_adds() {
    let text = room("Path(rr_depth: 3)", "Physical").replace("spp: 6", "spp: 9");
    let s = rtis::extract(&scene(&text));
    let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
    let mut spread = 0;
    for (i, p) in r.pixels.iter().enumerate() {
        let (col, row) = (i as u32 % s.film.width, i as u32 / s.film.width);
        let l: Vec<glam::DVec3> = (0..s.film.spp)
            .map(|k| {
                let sample = render_sample(&s, col, row, k, &mut RayStats::default());
                sample.mean(1).as_dvec3()
            })
            .collect();
        let n = l.len() as f64;
        let mean = l.iter().sum::<glam::DVec3>() / n;
        let var = l
            .iter()
            .map(|x| (*x - mean) * (*x - mean))
            .sum::<glam::DVec3>()
            / (n - 1.0)
            / n;
        let got = p.variance.as_dvec3();
        let scale = l.iter().map(|x| x.length_squared()).sum::<f64>() / n;
        assert!(
            (got - var).abs().max_element() <= 1e-6 * scale + 1e-12,
            "pixel {col},{row}: {got} against {var}"
        );
        spread += (var.max_element() > 0.0) as usize;
    }
    assert!(spread > r.pixels.len() / 2, "most pixels vary: {spread}");
}

/// In a sphere room of radius 10 centred on the camera every camera ray meets the wall at
/// distance 10, where its albedo is the Phong `kd` and its normal faces the camera.
#[test]
fn first_hit_layers_in_a_room_centred_on_the_camera() {
    let text = "Scene(film: (width: 8, height: 6, spp: 4), shader: Path(),
          camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), fov: 70),
          entities: [(shape: Sphere(center: (0, 0, 0), radius: 10), material: Phong(kd: (0.5, 0.25, 0.125))),
                     (light: Point(position: (0, 2, 0), intensity: (5, 5, 5)))])";
    let s = rtis::extract(&scene(text));
    let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
    for p in &r.pixels {
        assert!((p.depth - 10.0).abs() <= 1e-4, "{}", p.depth);
        assert_eq!(p.albedo, glam::Vec3A::new(0.5, 0.25, 0.125));
        // The mean of the inward normals of the pixel's samples: nearly unit (they span a
        // pixel), towards the camera, so against the view direction +z.
        let len = p.normal.length();
        assert!(len > 0.99 && len <= 1.0 + 1e-5, "{}", p.normal);
        assert!(p.normal.z < -0.5, "{}", p.normal);
    }
}

/// A closed sphere room of Phong walls around the camera (tests/integration/estimate.rs's):
/// every ray meets a Phong surface.
fn closed_room(shader: &str) -> String {
    format!(
        "Scene(film: (width: 12, height: 10, spp: 2), shader: {shader},
          camera: Perspective(position: (0, 0, -3), look_at: (0, 0, 0), fov: 60),
          entities: [(shape: Sphere(center: (0, 0, 0), radius: 10), material: Phong(kd: (0.5, 0.5, 0.5))),
                     (light: Point(position: (0, 2, 0), intensity: (5, 5, 5)))])"
    )
}

/// In the closed room the path-length layer is the cost rule's: `1 + n (2^D - 1)` rays per
/// sample for Global, `D + 1` for a Path of depth `D` that roulette never ends; each of them
/// tests the room's one sphere (packed: no BVH node), and so does each shadow ray.
#[test]
fn path_length_matches_the_cost_rule_in_the_closed_room() {
    for (shader, length) in [
        ("Global(samples: 4, max_depth: 3)", 29.0),
        ("Global(samples: 3, max_depth: 0)", 1.0),
        ("Path(max_depth: 3, rr_depth: 100)", 4.0),
        ("Direct()", 1.0),
    ] {
        let s = rtis::extract(&scene(&closed_room(shader)));
        let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
        for p in &r.pixels {
            assert_eq!(p.path_length, length, "{shader}");
            assert_eq!(p.nodes, 0, "{shader}");
            assert_eq!(p.prims, p.rays.total(), "{shader}");
        }
    }
}

/// In a mesh the counters count. Two triangles in one leaf fill the view: each camera ray of
/// the Normal shader tests the root (one node test: the top node holds the leaf) and the leaf's
/// two triangles, exactly. In a larger mesh every ray tests the root at least, and a pixel
/// whose rays all miss it tests nothing more.
#[test]
fn bvh_counters_count_node_and_primitive_tests() {
    let text = "Scene(film: (width: 12, height: 10, spp: 3), shader: Normal,
          camera: Perspective(position: (0, 0, 3), look_at: (0, 0, 0), fov: 40),
          entities: [(shape: Triangle(a: (-5, -5, 0), b: (5, -5, 0), c: (5, 5, 0)), material: Phong(kd: (0.5, 0.5, 0.5))),
                     (shape: Triangle(a: (-5, -5, 0), b: (5, 5, 0), c: (-5, 5, 0)), material: Phong(kd: (0.5, 0.5, 0.5)))])";
    let s = rtis::extract(&scene(text));
    let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
    for p in &r.pixels {
        assert_eq!((p.nodes, p.prims), (3, 6), "{p:?}");
    }
    // Without counters nothing is counted, and the image is the same.
    let quiet = inspect(&s, Inspect::default(), &|| {}, &AtomicBool::new(false));
    assert!(quiet.pixels.iter().all(|p| p.nodes == 0 && p.prims == 0));
    assert_eq!(bits(&quiet.image), bits(&r.image));
    let text = "Scene(film: (width: 12, height: 10, spp: 2), shader: Direct(),
          camera: Perspective(position: (0, 0, 3), look_at: (0, 0, 0), fov: 50),
          entities: [(shape: Mesh(path: \"assets/blob.obj\"), material: Phong(kd: (0.5, 0.5, 0.5))),
                     (light: Point(position: (0, 2, 2), intensity: (5, 5, 5)))])";
    let s = rtis::extract(&scene(text));
    let r = inspect(&s, counted(0), &|| {}, &AtomicBool::new(false));
    assert!(r.pixels.iter().all(|p| p.nodes >= p.rays.total()));
    assert!(r.pixels.iter().any(|p| p.prims > 0));
    assert!(
        r.pixels
            .iter()
            .any(|p| p.prims == 0 && p.nodes == p.rays.total())
    );
}

/// At 1 spp a pixel's mean is its one sample: the fireflies are then the brightest samples,
/// each above zero; ranked against an image, they stand out from it.
#[test]
fn fireflies_at_one_sample_are_the_brightest() {
    let s = rtis::extract(&scene(
        &room("Path(rr_depth: 3)", "Physical").replace("spp: 6", "spp: 1"),
    ));
    let r = inspect(&s, counted(4), &|| {}, &AtomicBool::new(false));
    assert_eq!(r.fireflies.len(), 4);
    let brightest = r
        .image
        .pixels
        .iter()
        .map(|&p| luminance(p))
        .fold(0.0f32, f32::max);
    assert_eq!(r.fireflies[0].luminance, brightest);
    assert!(
        r.fireflies
            .iter()
            .all(|f| f.excess > 0.0 && f.excess == f.luminance)
    );
    // Against a black image the same ranking; against the image itself nothing stands out.
    let black = rtis::render::film::Image::new(s.film.width, s.film.height);
    let want = Inspect {
        fireflies: 4,
        counters: false,
        against: Some(&black),
    };
    let against_black = inspect(&s, want, &|| {}, &AtomicBool::new(false));
    assert_eq!(against_black.fireflies[0].pixel, r.fireflies[0].pixel);
    let want = Inspect {
        fireflies: 4,
        counters: false,
        against: Some(&r.image),
    };
    assert!(
        inspect(&s, want, &|| {}, &AtomicBool::new(false))
            .fireflies
            .is_empty()
    );
}

/// A tiny bright light seen only through glass makes rare, huge samples: the one that stands
/// out most is found at the pixel and sample where a brute-force search finds it, its
/// path crosses the glass, and the fireflies are the same whatever the thread count.
#[test]
fn a_firefly_made_on_purpose_is_found_and_replayed() {
    let _limit = common::deadline(120);
    // The light sits at the centre of a glass ball: it covers a fraction of a pixel, and only
    // the camera rays that find it through the glass see it. The film spans six tiles, so
    // that the tiles' fireflies are merged.
    let text = "Scene(film: (width: 40, height: 30, spp: 16), shader: Path(rr_depth: 8, lights: Mis), model: Physical,
          camera: Perspective(position: (0, 1, 4), look_at: (0, 0, 0), fov: 50),
          entities: [
            (shape: InfinitePlane(point: (0, -1, 0), normal: (0, 1, 0)), material: Phong(kd: (0.5, 0.5, 0.5))),
            (shape: Sphere(center: (0, 0, 0), radius: 0.6), material: Transmissive(ior: 1.5)),
            (shape: Sphere(center: (0, 0, 0), radius: 0.05), emitter: Emitter(radiance: (1e4, 1e4, 1e4))),
            (light: Point(position: (2, 3, 2), intensity: (3, 3, 3))),
          ])";
    let s = rtis::extract(&scene(text));
    // Brute force: every sample's kept radiance against its pixel's colour in the render.
    let image = render(&s, &|| {}).image;
    let mut best = (f32::MIN, 0u32, 0u32, 0u32);
    for row in 0..s.film.height {
        for col in 0..s.film.width {
            let pixel = luminance(image.get(col, row));
            for k in 0..s.film.spp {
                let l = render_sample(&s, col, row, k, &mut RayStats::default()).mean(1);
                if luminance(l) - pixel > best.0 {
                    best = (luminance(l) - pixel, col, row, k);
                }
            }
        }
    }
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| inspect(&s, counted(5), &|| {}, &AtomicBool::new(false)));
    let two = pool(2).install(|| inspect(&s, counted(5), &|| {}, &AtomicBool::new(false)));
    let f = &one.fireflies[0];
    assert_eq!(
        (f.excess, f.pixel, f.sample),
        (best.0, [best.1, best.2], best.3)
    );
    assert_eq!(
        serde_json::to_string(&one.fireflies).unwrap(),
        serde_json::to_string(&two.fireflies).unwrap()
    );
    // Far above its pixel's mean, and made through the glass.
    let mean = luminance(one.image.get(best.1, best.2));
    assert!(f.luminance > 4.0 * mean, "{} vs {mean}", f.luminance);
    assert!(f.path.iter().any(|e| matches!(
        e,
        Event::Hit {
            kind: "Transmissive",
            ..
        }
    )));
    // Most first.
    assert!(one.fireflies.windows(2).all(|w| w[0].excess >= w[1].excess));
}

/// The float channels of an EXR file by name.
fn channels(path: &std::path::Path) -> std::collections::HashMap<String, Vec<f32>> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    image.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| {
            let values = c.sample_data.values_as_f32().collect();
            (c.name.to_string(), values)
        })
        .collect()
}

/// `render --aov --parts --fireflies` writes the image of a plain render, to the bit, and its
/// layers; the fireflies' JSON names a sample that `rtis replay` retraces to the same
/// radiance; bad asks are refused before rendering.
#[test]
fn the_cli_writes_the_same_image_and_its_layers() {
    let d = std::env::temp_dir().join(format!("rtis-inspect-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let scene_file = common::scenes_dir().join("cornell-physical.ron");
    let run = |args: &[&str]| {
        common::output_within(
            std::process::Command::new(env!("CARGO_BIN_EXE_rtis")).args(args),
            120,
        )
    };
    let scene_arg = scene_file.to_str().unwrap();
    let (plain, inspected) = (d.join("plain.exr"), d.join("inspected.exr"));
    let (aov, parts) = (d.join("aov.exr"), d.join("parts.exr"));
    let small = ["--width", "24", "--spp", "4"];
    let o = run(&[
        &["render", scene_arg, "-o", plain.to_str().unwrap()][..],
        &small,
    ]
    .concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(&[
        &[
            "render",
            scene_arg,
            "-o",
            inspected.to_str().unwrap(),
            "--aov",
            aov.to_str().unwrap(),
            "--parts",
            parts.to_str().unwrap(),
            "--fireflies",
            "3",
        ][..],
        &small,
    ]
    .concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(&plain).unwrap(),
        std::fs::read(&inspected).unwrap()
    );
    // The layers are there: the time layer measured, the parts adding up to the image
    // within the rounding of each part's mean.
    let aov_layers = channels(&aov);
    for want in [
        "time.us",
        "rays.shadow",
        "bvh.nodes",
        "path.length",
        "variance.G",
        "albedo.R",
        "normal.Z",
        "depth.Z",
    ] {
        assert!(aov_layers.contains_key(want), "{want}");
    }
    assert!(aov_layers["time.us"].iter().all(|&t| t > 0.0));
    let part_layers = channels(&parts);
    for want in [
        "technique.light.R",
        "technique.bsdf.G",
        "bounce.direct.B",
        "bounce.3+.R",
    ] {
        assert!(part_layers.contains_key(want), "{want}");
    }
    for c in ["R", "G", "B"] {
        let image = &part_layers[c];
        for split in [
            ["technique.emitted", "technique.light", "technique.bsdf", ""],
            ["bounce.direct", "bounce.1", "bounce.2", "bounce.3+"],
        ] {
            for (i, &want) in image.iter().enumerate() {
                let sum: f32 = split
                    .iter()
                    .filter(|p| !p.is_empty())
                    .map(|p| part_layers[&format!("{p}.{c}")][i])
                    .sum();
                assert!(
                    (sum - want).abs() <= 1e-5 * want.max(1.0),
                    "{split:?} {c}: {sum} vs {want}"
                );
            }
        }
    }
    // The largest firefly, replayed.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("inspected.fireflies.json")).unwrap())
            .unwrap();
    let f = &json["fireflies"][0];
    let pixel = format!("{},{}", f["pixel"][0], f["pixel"][1]);
    let sample = f["sample"].to_string();
    let o = run(&[
        &[
            "replay", scene_arg, "--pixel", &pixel, "--sample", &sample, "--json",
        ][..],
        &small,
    ]
    .concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let back: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(back["radiance"], f["radiance"]);
    assert_eq!(back["path"], f["path"]);
    // Refused with a clear message and a non-zero exit, before rendering: a pixel off the
    // film, a sample past spp, parts of a shader that does not split, a layer file named as
    // the image; nothing is written.
    let refused = |args: &[&str], says: &str| {
        let o = run(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    };
    refused(
        &["replay", scene_arg, "--pixel", "999,0", "--sample", "0"],
        "outside the",
    );
    refused(
        &[
            &["replay", scene_arg, "--pixel", "1,1", "--sample", "4"][..],
            &small,
        ]
        .concat(),
        "out of range",
    );
    let cornell = common::scenes_dir().join("cornell.ron");
    let fresh = d.join("fresh.exr");
    refused(
        &[
            "render",
            cornell.to_str().unwrap(),
            "--parts",
            fresh.to_str().unwrap(),
        ],
        "not Path",
    );
    let twice = d.join("twice.exr");
    refused(
        &[
            "render",
            scene_arg,
            "-o",
            twice.to_str().unwrap(),
            "--aov",
            twice.to_str().unwrap(),
        ],
        "written twice",
    );
    // The same file by another name (`sub/../`), and --stats over the fireflies' JSON.
    std::fs::create_dir_all(d.join("sub")).unwrap();
    let round = d.join("sub").join("..").join("twice.exr");
    refused(
        &[
            "render",
            scene_arg,
            "-o",
            round.to_str().unwrap(),
            "--aov",
            twice.to_str().unwrap(),
        ],
        "written twice",
    );
    let json = d.join("twice.fireflies.json");
    refused(
        &[
            "render",
            scene_arg,
            "-o",
            twice.to_str().unwrap(),
            "--fireflies",
            "2",
            "--stats",
            json.to_str().unwrap(),
        ],
        "written twice",
    );
    // A film beyond what an inspected render holds is refused before the scene is prepared.
    refused(
        &[
            "render",
            scene_arg,
            "--width",
            "4096",
            "--height",
            "4096",
            "--aov",
            fresh.to_str().unwrap(),
        ],
        "at most",
    );
    assert!(!fresh.exists() && !twice.exists() && !json.exists());
    std::fs::remove_dir_all(&d).unwrap();
}
