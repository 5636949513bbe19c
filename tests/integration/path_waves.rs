//! Path's samples in waves (src/render/waves.rs, src/shader/path/lanes.rs): where they apply,
//! every pixel is the one-ray render's to the bit, with the same ray counts, a pixel alone or
//! a tile's pixels in one wave, over the strategies the lanes shade (one light by power or by
//! importance, or all; BRDF or cosine sampling; area lights sampled, left to BRDF-sampled rays
//! or both under MIS, among packed primitives and in a BVH), Russian roulette from the first
//! bounce, a depth limit, the effects that end or skip work, point, spot, directional and
//! environment lights, lights inside and outside the planes' room, textured `kd` (black texels
//! included), and the materials the lanes leave to the one-ray code (glossy Phong, mirror,
//! glass, a black surface, normal maps).

use crate::common::{self, scene};
use rtis::render::exact::RgbSum;
use rtis::render::{pixel_sum, render_sample, waves};
use rtis::shader::Shader;
use rtis::stats::RayStats;

/// A small room of planes and spheres (no BVH) with two point lights, under `shader`.
fn room(shader: &str, effects: &str) -> String {
    format!(
        "Scene(film: (width: 8, height: 6, spp: 150), shader: {shader}, model: Physical,
          camera: Perspective(position: (0, 0, 3.5), look_at: (0, 0, 0), fov: 55),
          effects: ({effects}),
          entities: [
            (shape: InfinitePlane(point: (0, -1, 0), normal: (0, 1, 0)), material: Phong(kd: (0.6, 0.6, 0.6))),
            (shape: InfinitePlane(point: (0, 0, -1.5), normal: (0, 0, 1)), material: Phong(kd: (0.5, 0.3, 0.2))),
            (shape: InfinitePlane(point: (-1.6, 0, 0), normal: (1, 0, 0)), material: Phong(kd: (0.2, 0.6, 0.3), ks: (0.2, 0.2, 0.2), shininess: 20)),
            (shape: InfinitePlane(point: (0, 1.4, 0), normal: (0, -1, 0)), material: Phong(kd: (0, 0, 0))),
            (shape: Sphere(center: (-0.7, -0.5, 0), radius: 0.5), material: Transmissive(ior: 1.5)),
            (shape: Sphere(center: (0.7, -0.6, 0.2), radius: 0.4), material: Mirror(color: (0.9, 0.9, 0.9))),
            (shape: Sphere(center: (0.1, 0.3, -0.6), radius: 0.35), material: Phong(kd: (0.7, 0.7, 0.2))),
            (light: Point(position: (0.5, 1.0, 1.0), intensity: (3, 3, 3))),
            (light: Point(position: (-1.0, 0.6, 0.5), intensity: (1, 2, 1))),
          ])"
    )
}

/// [`room`] without its ceiling: open to the sky above.
fn open_room(shader: &str, effects: &str) -> String {
    let text = room(shader, effects);
    let ceiling = "(shape: InfinitePlane(point: (0, 1.4, 0), normal: (0, -1, 0)), material: Phong(kd: (0, 0, 0))),";
    assert!(text.contains(ceiling), "room() changed");
    text.replace(ceiling, "")
}

/// [`open_room`] with a spot light (its cone taking in part of the room) and a directional
/// light from above too, which the lanes take lane by lane (`Light::incident`).
fn spot_room(shader: &str, effects: &str) -> String {
    open_room(shader, effects).replace(
        "(light: Point(position: (0.5, 1.0, 1.0)",
        "(light: Spot(position: (-1, 1.2, 1), direction: (0.5, -1, -0.5), intensity: (4, 3, 3), cutoff_angle: 35, beam_width: 20)),
            (light: Directional(direction: (0.3, -1, -0.6), irradiance: (0.6, 0.5, 0.4))),
            (light: Point(position: (0.5, 1.0, 1.0)",
    )
}

/// [`room`] with an emitting sphere under the ceiling too (an area light among the packed
/// primitives).
fn lit_room(shader: &str, effects: &str) -> String {
    room(shader, effects).replace(
        "(light: Point(position: (0.5, 1.0, 1.0)",
        "(shape: Sphere(center: (-0.2, 1.1, 0.4), radius: 0.15), material: Phong(kd: (0.5, 0.5, 0.5)), emitter: Emitter(radiance: (6, 5, 4))),
            (light: Point(position: (0.5, 1.0, 1.0)",
    )
}

/// Mitsuba's Cornell box (scenes/mitsuba-cornell.ron: 36 triangles in a BVH, and a rectangle
/// light) on a small film, under `shader`, with a point light too if `point`.
fn triangle_box(shader: &str, effects: &str, point: bool) -> String {
    let text = std::fs::read_to_string(common::scenes_dir().join("mitsuba-cornell.ron")).unwrap();
    let mut text = text
        .replace(
            "film: (width: 128, height: 128, spp: 64)",
            "film: (width: 6, height: 5, spp: 150)",
        )
        .replace(
            "shader: Path(rr_depth: 5, sampling: Brdf)",
            &format!("shader: {shader}, effects: ({effects})"),
        );
    if point {
        text = text.replace(
            "entities: [",
            "entities: [\n        (light: Point(position: (0.3, 0.5, 0.2), intensity: (0.6, 0.5, 0.4))),",
        );
    }
    assert!(
        text.contains(shader) && text.contains("spp: 150") && text.contains("Point(") == point,
        "mitsuba-cornell.ron changed"
    );
    text
}

/// Each pixel's sum in waves against its samples' one-ray sums, and the ray counts, in every
/// instruction set this CPU runs (the lanes' widths: 4, 8, 16); a few pixels with more samples
/// than a wave holds, so that the slots of ended paths take new samples.
fn agrees(s: &rtis::RenderScene, what: &str) {
    assert!(waves::applies(s), "{what}: the waves apply");
    rtis::accel::require_all_isas();
    for isa in rtis::accel::Isa::all_available() {
        let mut s = s.clone();
        assert!(s.geometry.bvh.set_isa(isa));
        let s = &s;
        assert!(s.film.spp as usize > 2 * waves::WAVE);
        let (mut waved, mut alone) = (RayStats::default(), RayStats::default());
        let (mut pixels, mut first) = (Vec::new(), Vec::new());
        let mut first_stats = RayStats::default();
        for row in 0..s.film.height {
            for col in 0..s.film.width {
                let mut ranges = vec![0..21, 5..17];
                if (col + row) % 7 == 0 {
                    ranges.push(3..s.film.spp);
                }
                for samples in ranges {
                    let got = pixel_sum(s, col, row, samples.clone(), &mut waved);
                    let mut want = RgbSum::default();
                    for k in samples.clone() {
                        want += render_sample(s, col, row, k, &mut alone);
                        if samples == (0..21) {
                            render_sample(s, col, row, k, &mut first_stats);
                        }
                    }
                    assert_eq!(got, want, "{what} ({isa:?}): pixel {col},{row}");
                    if samples == (0..21) {
                        pixels.push((col, row));
                        first.push(want);
                    }
                }
            }
        }
        assert_eq!(waved, alone, "{what} ({isa:?}): ray counts");
        // The pixels together, as a tile's: a wave of the samples of one pixel after another.
        let Shader::Path(p) = &s.shader else {
            panic!("{what}: the waves are the path tracer's")
        };
        let mut tiled = RayStats::default();
        let sums = waves::sums(s, &pixels, 0..21, p, &mut tiled);
        assert_eq!(sums, first, "{what} ({isa:?}): a tile's pixels");
        assert_eq!(tiled, first_stats, "{what} ({isa:?}): a tile's ray counts");
        // More samples per pixel than a wave holds: the wave holds one pixel's last samples
        // and the next one's first.
        let many = 3..s.film.spp;
        let three = &pixels[..3];
        let want: Vec<RgbSum> = three
            .iter()
            .map(|&(col, row)| {
                let mut sum = RgbSum::default();
                for k in many.clone() {
                    sum += render_sample(s, col, row, k, &mut RayStats::default());
                }
                sum
            })
            .collect();
        let got = waves::sums(s, three, many, p, &mut RayStats::default());
        assert_eq!(got, want, "{what} ({isa:?}): pixels of many samples");
        // The same rays, field for field: origins and error bounds too, which a pixel's sum
        // may not show (an origin off by less than its error band meets the same surfaces).
        let rays_of = |run: &dyn Fn(&rtis::RenderScene)| {
            let mut rays: Vec<_> = common::rays_traced(s, run)
                .into_iter()
                .map(|(r, kind)| {
                    let v = [r.o.to_array(), r.d.to_array(), [r.t_max, r.o_err, 0.0]];
                    (format!("{kind:?}"), v.map(|v| v.map(f32::to_bits)))
                })
                .collect();
            rays.sort();
            rays
        };
        let waved_rays = rays_of(&|a| {
            waves::sums(a, &pixels, 0..21, p, &mut RayStats::default());
        });
        let alone_rays = rays_of(&|a| {
            for &(col, row) in &pixels {
                for k in 0..21 {
                    render_sample(a, col, row, k, &mut RayStats::default());
                }
            }
        });
        assert!(
            waved_rays == alone_rays,
            "{what} ({isa:?}): the rays traced"
        );
        // (Without point lights, BRDF sampling alone traces no shadow ray.)
        let no_shadows = what.contains("shadows: false")
            || (what.contains("lights: Brdf") && what.contains("point light false"));
        assert!(alone.shadow > 0 || no_shadows, "{what}");
    }
}

/// [`agrees`] on the scene `text`, then with its lights moved out of the planes' room (so that
/// their shadow rays test the planes too).
fn agrees_in_and_out_of_room(text: &str, what: &str) {
    agrees(&rtis::extract(&scene(text)), what);
    let mut s = rtis::extract(&scene(text));
    common::lights_out_of_room(&mut s);
    agrees(&s, &format!("{what}, lights out of the room"));
}

#[test]
fn waves_give_the_one_ray_pixels() {
    let _limit = common::deadline(120);
    for per_vertex in ["One", "All", "Importance"] {
        for sampling in ["Brdf", "Cosine"] {
            for depth in ["rr_depth: 1", "rr_depth: 5", "max_depth: 2, rr_depth: 1"] {
                let shader =
                    format!("Path({depth}, sampling: {sampling}, lights_per_vertex: {per_vertex})");
                let text = room(&shader, "");
                agrees_in_and_out_of_room(&text, &shader);
            }
        }
    }
    // The Course model: every point light at every vertex, the course's reflectance, the
    // indirect weights over (2 pi)^2.
    // (`lights_per_vertex` is the Physical model's: the Course model sums every light.)
    for per_vertex in ["One", "All", "Importance"] {
        for sampling in ["Brdf", "Cosine"] {
            for depth in ["rr_depth: 1", "max_depth: 3, rr_depth: 2"] {
                let shader =
                    format!("Path({depth}, sampling: {sampling}, lights_per_vertex: {per_vertex})");
                let text = room(&shader, "").replace("model: Physical", "model: Course");
                agrees_in_and_out_of_room(&text, &format!("{shader}, Course"));
            }
        }
    }
    // Spot and directional lights beside the point lights, in the planes' room and out of it
    // (a directional light never is).
    for model in ["Physical", "Course"] {
        for per_vertex in ["One", "All", "Importance"] {
            for sampling in ["Brdf", "Cosine"] {
                let shader = format!(
                    "Path(rr_depth: 2, sampling: {sampling}, lights_per_vertex: {per_vertex})"
                );
                let text =
                    spot_room(&shader, "").replace("model: Physical", &format!("model: {model}"));
                let what = format!("{shader}, {model}, spot and directional");
                agrees_in_and_out_of_room(&text, &what);
            }
        }
    }
    // Effects that end paths at their first vertex, or skip the shadow rays.
    for effects in [
        "indirect: false",
        "shadows: false",
        "reflection: false, refraction: false",
    ] {
        let text = room(
            "Path(rr_depth: 2, sampling: Brdf, lights_per_vertex: One)",
            effects,
        );
        agrees(&rtis::extract(&scene(&text)), effects);
    }
}

/// The path tracers of the light-sample tests: light sampling, BRDF sampling or MIS; one
/// light by power or by importance, or all; BRDF sampling (roulette from the first bounce) or
/// cosine sampling (a depth limit).
fn light_strategies() -> Vec<String> {
    let mut shaders = Vec::new();
    for lights in ["Mis", "Light", "Brdf"] {
        for per_vertex in ["One", "All", "Importance"] {
            for (sampling, depth) in [
                ("Brdf", "rr_depth: 1"),
                ("Cosine", "max_depth: 3, rr_depth: 2"),
            ] {
                shaders.push(format!(
                    "Path({depth}, sampling: {sampling}, lights: {lights}, lights_per_vertex: {per_vertex})"
                ));
            }
        }
    }
    shaders
}

/// Area lights in the waves: an emitting sphere among packed primitives, and a rectangle light
/// in a scene of triangles (in a BVH; one-sided, and two-sided once), with point lights or
/// without, over
/// the strategies (light sampling, BRDF sampling, MIS; one light by power or by importance, or
/// all), both samplings, both models, and the effects that skip work.
#[test]
fn waves_give_the_one_ray_pixels_with_area_lights() {
    let _limit = common::deadline(240);
    for shader in light_strategies() {
        agrees(
            &rtis::extract(&scene(&lit_room(&shader, ""))),
            &format!("{shader}, sphere light"),
        );
        for point in [false, true] {
            let text = triangle_box(&shader, "", point);
            agrees(
                &rtis::extract(&scene(&text)),
                &format!("{shader}, box, point light {point}"),
            );
        }
    }
    // Packed primitives and a BVH together: a mesh in the lit room.
    let shader = "Path(rr_depth: 1, sampling: Brdf, lights: Mis, lights_per_vertex: One)";
    let mixed = lit_room(shader, "").replace(
        "entities: [",
        "entities: [\n            (shape: TriangleMesh(vertices: [(-1, -0.9, -1), (1, -0.9, -1), (0, 0.2, -0.8)], faces: [(0, 1, 2)]), material: Phong(kd: (0.4, 0.5, 0.6))),
            (shape: TriangleMesh(vertices: [(1.5, -0.9, -1), (1.5, 0.5, -1), (1.2, -0.9, 0.5)], faces: [(0, 1, 2)], normals: [(-0.9, 0.1, 0.3), (-0.8, 0, 0.5), (-1, 0.2, 0)]), material: Phong(kd: (0.6, 0.5, 0.4))),
            (shape: Rectangle(corner: (-1.5, 1.3, -1), u: (0.3, 0, 0), v: (0, 0, 0.3)), emitter: (radiance: Checkerboard(color0: (0.9, 0.8, 0.7), color1: (0.1, 0.2, 0.3)))),
            (shape: TriangleMesh(vertices: [(-1.3, -0.9, 0.4), (-0.3, -0.9, 0.2), (-0.8, 0.1, 0.1)], faces: [(0, 2, 1)]), material: Phong(kd: (0.5, 0.6, 0.4))),
            (shape: Rectangle(corner: (0.5, 1.3, -0.6), u: (0.4, 0, 0), v: (0, 0, 0.4)), emitter: (radiance: (3, 3, 2.5))),",
    );
    assert!(mixed.contains("normals:"), "room() changed");
    let s = rtis::extract(&scene(&mixed));
    assert!(!s.geometry.bvh.is_empty());
    // (A smooth triangle, a triangle facing away from the camera (its hits' normals turned
    // to the viewer, their shadow rays leaving from the back origin), and a textured and an
    // untextured rectangle light, among them; with one light or every light at each vertex,
    // untextured triangle lights sampled and their shadow rays made in lanes.)
    agrees(&s, "sphere light, meshes, textured light");
    let all = mixed.replace("lights_per_vertex: One", "lights_per_vertex: All");
    assert!(all.contains("lights_per_vertex: All"));
    agrees(
        &rtis::extract(&scene(&all)),
        "sphere light, meshes, textured light, all",
    );
    let shader = "Path(rr_depth: 1, sampling: Brdf, lights: Mis, lights_per_vertex: All)";
    // Mitsuba's light two-sided: the ceiling, 0.01 above it, sees its back.
    let two_sided = triangle_box(shader, "", false).replace("two_sided: false", "two_sided: true");
    assert!(
        two_sided.contains("two_sided: true"),
        "mitsuba-cornell.ron changed"
    );
    agrees(&rtis::extract(&scene(&two_sided)), "box, two-sided light");
    let course = lit_room(shader, "").replace("model: Physical", "model: Course");
    assert!(course.contains("model: Course"));
    agrees(&rtis::extract(&scene(&course)), "sphere light, Course");
    let course = triangle_box(shader, "", true).replace("model: Physical", "model: Course");
    assert!(course.contains("model: Course"));
    agrees(&rtis::extract(&scene(&course)), "box, Course");
    let cosine = "Path(max_depth: 3, rr_depth: 1, sampling: Cosine, lights: Mis)";
    let course = lit_room(cosine, "").replace("model: Physical", "model: Course");
    agrees(
        &rtis::extract(&scene(&course)),
        "sphere light, Course, cosine",
    );
    for (effects, lights) in [
        ("indirect: false", "Mis"),
        ("indirect: false", "Brdf"),
        ("shadows: false", "Mis"),
        ("emission: false", "Mis"),
    ] {
        for per_vertex in ["One", "All"] {
            let shader = format!(
                "Path(rr_depth: 2, sampling: Brdf, lights: {lights}, lights_per_vertex: {per_vertex})"
            );
            let what = format!("{shader}, {effects}");
            agrees(&rtis::extract(&scene(&lit_room(&shader, effects))), &what);
            let text = triangle_box(&shader, effects, true);
            agrees(&rtis::extract(&scene(&text)), &what);
        }
    }
}

/// Environment lights in the waves: a constant sky and an image (`scenes/assets/sky.exr`) over
/// the lit room without its ceiling (the sky seen above, and through the front and the right),
/// with its point lights and its emitting sphere, over the strategies and both samplings, and
/// with the effects that skip work; and the sky through the open side of Mitsuba's box (a BVH)
/// with a spot and a directional light.
#[test]
fn waves_give_the_one_ray_pixels_with_an_environment() {
    let _limit = common::deadline(240);
    let sky = common::scenes_dir().join("assets/sky.exr");
    let skies = [
        "(light: Environment(radiance: (0.3, 0.35, 0.4)))".to_string(),
        format!("(light: Environment(image: {sky:?}, rotate: (0, 40, 0)))"),
    ];
    // The lit room without its ceiling.
    let open = |text: String| {
        let ceiling = "(shape: InfinitePlane(point: (0, 1.4, 0), normal: (0, -1, 0)), material: Phong(kd: (0, 0, 0))),";
        assert!(text.contains(ceiling), "room() changed");
        text.replace(ceiling, "")
    };
    let under = |shader: &str, effects: &str, sky: &str| {
        let text = open(lit_room(shader, effects))
            .replace("entities: [", &format!("entities: [\n            {sky},"));
        assert!(text.contains("Environment("), "room() changed");
        rtis::extract(&scene(&text))
    };
    for sky in &skies {
        for shader in light_strategies() {
            agrees(&under(&shader, "", sky), &format!("{shader}, {sky}"));
        }
        // The Course model (every light at every vertex, the course's weights).
        let shader = "Path(rr_depth: 2, sampling: Brdf, lights: Mis)";
        let text = open(lit_room(shader, ""))
            .replace("model: Physical", "model: Course")
            .replace("entities: [", &format!("entities: [\n            {sky},"));
        assert!(text.contains("model: Course") && text.contains("Environment("));
        agrees(&rtis::extract(&scene(&text)), &format!("Course, {sky}"));
        for effects in ["indirect: false", "shadows: false", "emission: false"] {
            for per_vertex in ["One", "All"] {
                let shader = format!(
                    "Path(rr_depth: 2, sampling: Brdf, lights: Mis, lights_per_vertex: {per_vertex})"
                );
                agrees(
                    &under(&shader, effects, sky),
                    &format!("{shader}, {effects}, {sky}"),
                );
            }
        }
        // A BVH's shadow rays, one at a time: the sky, a spot and a directional light in
        // Mitsuba's box.
        for per_vertex in ["One", "All", "Importance"] {
            let shader = format!(
                "Path(rr_depth: 2, sampling: Brdf, lights: Mis, lights_per_vertex: {per_vertex})"
            );
            let text = triangle_box(&shader, "", false).replace(
                "entities: [",
                &format!(
                    "entities: [\n        {sky},
        (light: Spot(position: (0, 0.8, 0.5), direction: (0.2, -1, -0.3), intensity: (2, 2, 1.5), cutoff_angle: 40)),
        (light: Directional(direction: (0.1, -0.3, -1), irradiance: (0.5, 0.5, 0.4))),"
                ),
            );
            assert!(text.contains("Spot(") && text.contains("Environment("));
            agrees(
                &rtis::extract(&scene(&text)),
                &format!("{shader}, box, {sky}"),
            );
        }
    }
}

/// Textured materials in the waves: a diffuse `kd` textured by a checkerboard (one square
/// black, which the lanes leave to the one-ray code) on the back wall and by an image
/// (`scenes/assets/checks.png`, filtered over each sample's footprint) on the floor, a
/// textured glossy sphere and a normal-mapped one (the one-ray code's), with the room's point
/// lights and emitting sphere, over the strategies, both samplings and both models.
#[test]
fn waves_give_the_one_ray_pixels_with_textures() {
    let _limit = common::deadline(240);
    let checks = common::scenes_dir().join("assets/checks.png");
    let textured = |shader: &str| {
        let text = lit_room(shader, "")
            .replace(
                "material: Phong(kd: (0.6, 0.6, 0.6))",
                &format!("material: Phong(kd: Image(path: {checks:?}, uv_transform: (scale: (3, 3))))"),
            )
            .replace(
                "material: Phong(kd: (0.5, 0.3, 0.2))",
                "material: Phong(kd: Checkerboard(color0: (0.7, 0.4, 0.2), color1: (0, 0, 0), uv_transform: (scale: (4, 4))))",
            )
            .replace(
                "entities: [",
                "entities: [
            (shape: Sphere(center: (0.9, 0.5, -0.8), radius: 0.3), material: Phong(kd: Checkerboard(color0: (0.5, 0.4, 0.3)), ks: (0.2, 0.2, 0.2), shininess: 30)),
            (shape: Sphere(center: (-1.0, 0.6, -0.9), radius: 0.3), material: NormalMap(normal_map: Checkerboard(color0: (0.6, 0.5, 1), color1: (0.4, 0.5, 1)), material: Phong(kd: (0.5, 0.6, 0.7)))),",
            );
        assert!(
            text.contains("Image(") && text.matches("Checkerboard(").count() == 3,
            "room() changed"
        );
        text
    };
    for model in ["Physical", "Course"] {
        for lights in ["Mis", "Light"] {
            for per_vertex in ["One", "All", "Importance"] {
                for sampling in ["Brdf", "Cosine"] {
                    let shader = format!(
                        "Path(rr_depth: 2, sampling: {sampling}, lights: {lights}, lights_per_vertex: {per_vertex})"
                    );
                    let text =
                        textured(&shader).replace("model: Physical", &format!("model: {model}"));
                    agrees(
                        &rtis::extract(&scene(&text)),
                        &format!("{shader}, {model}, textured"),
                    );
                }
            }
        }
    }
}

/// The waves are for the scenes whose vertices the lanes shade: not with uniform sampling (under
/// either model).
#[test]
fn waves_apply_only_where_the_lanes_shade() {
    let path = "Path(sampling: Brdf)";
    assert!(waves::applies(&rtis::extract(&scene(&room(path, "")))));
    let with = |entity: &str| {
        let text = room(path, "").replace(
            "(light: Point(position: (0.5, 1.0, 1.0)",
            &format!("{entity},\n            (light: Point(position: (0.5, 1.0, 1.0)"),
        );
        assert!(text.contains(entity), "{entity}");
        rtis::extract(&scene(&text))
    };
    for (what, text) in [
        ("uniform sampling", room("Path(sampling: Uniform)", "")),
        (
            "uniform sampling, Course",
            room("Path(sampling: Uniform)", "").replace("model: Physical", "model: Course"),
        ),
    ] {
        assert!(!waves::applies(&rtis::extract(&scene(&text))), "{what}");
    }
    // Spot, directional and environment lights, textures, an emitting shape and a BVH take the
    // waves.
    for entity in [
        "(shape: Sphere(center: (1, 1, -1), radius: 0.2), material: Phong(kd: Checkerboard(color0: (1, 1, 1))))",
        "(light: Environment(radiance: (0.3, 0.35, 0.4)))",
        "(light: Spot(position: (-1, 1.2, 1), direction: (0.5, -1, -0.5), intensity: (3, 3, 3)))",
        "(light: Directional(direction: (0.3, -1, 0.2), irradiance: (2, 1.5, 1)))",
        "(shape: Sphere(center: (0, 1.2, 0), radius: 0.1), emitter: Emitter(radiance: (8, 7, 6)))",
        "(shape: TriangleMesh(vertices: [(-1, -0.9, -1), (1, -0.9, -1), (0, -0.9, -0.5)], faces: [(0, 1, 2)]), material: Phong(kd: (0.5, 0.5, 0.5)))",
    ] {
        assert!(waves::applies(&with(entity)), "{entity}");
    }
    let text = triangle_box(path, "", false);
    assert!(waves::applies(&rtis::extract(&scene(&text))));
}

/// The Sobol' sampler in the waves: its draws in lanes (`SobolLanes`) are each path's own,
/// 1D and 2D draws alike (a light sample's point and the next direction are 2D points, not
/// two 1D ones), so the waves give the one-ray pixels with it too: point lights, an emitting
/// sphere and Mitsuba's box under each light strategy, and an image sky.
#[test]
fn waves_give_the_one_ray_pixels_with_the_sobol_sampler() {
    let _limit = common::deadline(240);
    let sobol = |text: String| {
        let with = text.replacen("spp: 150)", "spp: 150, sampler: Sobol)", 1);
        assert!(with.contains("sampler: Sobol"), "the film changed");
        let s = rtis::extract(&scene(&with));
        assert_eq!(s.film.sampler, rtis::sampling::SamplerKind::Sobol);
        s
    };
    for per_vertex in ["One", "All", "Importance"] {
        let shader = format!("Path(rr_depth: 1, sampling: Brdf, lights_per_vertex: {per_vertex})");
        agrees(&sobol(room(&shader, "")), &format!("Sobol, {shader}"));
    }
    for lights in ["Mis", "Light", "Brdf"] {
        for per_vertex in ["One", "All"] {
            let shader = format!(
                "Path(rr_depth: 1, sampling: Brdf, lights: {lights}, lights_per_vertex: {per_vertex})"
            );
            agrees(
                &sobol(lit_room(&shader, "")),
                &format!("Sobol, {shader}, sphere light"),
            );
            agrees(
                &sobol(triangle_box(&shader, "", true)),
                &format!("Sobol, {shader}, box, point light true"),
            );
        }
    }
    let sky = common::scenes_dir().join("assets/sky.exr");
    let shader = "Path(max_depth: 3, rr_depth: 2, sampling: Cosine, lights: Mis)";
    let text = open_room(shader, "").replace(
        "entities: [",
        &format!("entities: [\n            (light: Environment(image: {sky:?})),"),
    );
    agrees(&sobol(text), "Sobol, image sky");
}
