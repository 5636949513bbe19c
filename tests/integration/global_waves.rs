//! The Global shader's two orders of tracing (`src/shader/global/waves.rs`): the trees of rays
//! below a first hit traced in waves give the depth-first walk's `L_i` to the bit, and count
//! the same rays, in every scene where the waves apply; where they would not, they stand aside.

use crate::common;

use crate::common::{lights_out_of_room, scene, scenes_dir};
use glam::Vec3A;
use rtis::RenderScene;
use rtis::geometry::Ray;
use rtis::sampling::Sampler;
use rtis::shader::global::{Order, incident_all};
use rtis::shader::{Global, Shader};
use rtis::shape::ShapeKind;
use rtis::stats::RayStats;

/// The Global parameters of a scene.
fn global(rs: &RenderScene) -> Global {
    match rs.shader {
        Shader::Global(g) => g,
        other => panic!("not a Global scene: {other:?}"),
    }
}

/// Rays as a first hit sends them: from random points in the course's box (inside the glass
/// ball too), and from points on its surfaces found by tracing, where the error bands decide.
fn rays(rs: &RenderScene, count: usize, seed: u64) -> Vec<Ray> {
    let mut s = Sampler::new(seed, 0, 0);
    let mut dir = || {
        let (u1, u2) = s.next_2d();
        let z = 1.0 - 2.0 * u1;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * u2;
        Vec3A::new(r * phi.cos(), r * phi.sin(), z)
    };
    let mut out = Vec::new();
    let mut k = 0u32;
    while out.len() < count {
        k += 1;
        // A point of the box in camera-relative coordinates (the camera is at z = -3).
        let f = |i: u32| ((i as f32 * 0.618_034).fract() * 2.0 - 1.0) * 2.9;
        let o = Vec3A::new(f(k), f(k * 7 + 1), f(k * 13 + 2) * 2.0 + 8.0);
        let free = Ray::new(o, dir());
        out.push(free);
        // The same direction's hit, and a ray leaving it on the side it was met from.
        if let Some(hit) = rs.geometry.intersect(&free) {
            let w = dir();
            let side = if w.dot(hit.n) * free.d.dot(hit.n) < 0.0 {
                w
            } else {
                -w
            };
            out.push(Ray::spawn(&hit, side, f32::INFINITY));
        }
    }
    out.truncate(count);
    out
}

/// `L_i` of every ray in `order`, as bits, with the rays it counted.
fn trace(rs: &RenderScene, g: &Global, rays: &[Ray], order: Order) -> (Vec<[u32; 3]>, RayStats) {
    let mut stats = RayStats::default();
    let mut tr = rs.tracer(Sampler::of(rs.film.sampler, 1, 2, 3), &mut stats);
    assert!(order.applies(&tr, g), "{order:?} does not apply");
    let l = incident_all(&mut tr, g, rays, order);
    (
        l.iter().map(|v| v.to_array().map(f32::to_bits)).collect(),
        stats,
    )
}

/// Both orders on `rs`: the same bits and the same counts.
fn agree(name: &str, rs: &RenderScene) {
    agree_with(name, rs, &global(rs));
}

/// Both orders on `rs` with the shader's parameters `g`, in every instruction set this CPU
/// runs (the waves' batches and light pass run in it), on 200 rays.
fn agree_with(name: &str, rs: &RenderScene, g: &Global) {
    agree_on(name, rs, g, 200);
}

/// [`agree_with`] on `count` rays ([`rays`]).
fn agree_on(name: &str, rs: &RenderScene, g: &Global, count: usize) {
    rtis::accel::require_all_isas();
    for isa in rtis::accel::Isa::all_available() {
        let mut rs = rs.clone();
        assert!(rs.geometry.bvh.set_isa(isa));
        agree_in(&format!("{name} ({})", isa.name()), &rs, g, count);
    }
}

/// Both orders on `rs` with the shader's parameters `g`, on `count` rays.
fn agree_in(name: &str, rs: &RenderScene, g: &Global, count: usize) {
    let g = *g;
    let rays = rays(rs, count, 11);
    let (waves, waves_stats) = trace(rs, &g, &rays, Order::Waves);
    let (walk, walk_stats) = trace(rs, &g, &rays, Order::DepthFirst);
    for (k, (a, b)) in waves.iter().zip(&walk).enumerate() {
        assert_eq!(a, b, "{name}: ray {k} ({:?}) differs", rays[k]);
    }
    assert_eq!(waves_stats, walk_stats, "{name}: ray counts differ");
    assert!(
        walk_stats.total() > 2 * rays.len() as u64,
        "{name}: traced little"
    );
    // The same rays, field for field and kind by kind, in whatever order each traces them.
    let seen = |order: Order| {
        let mut seen: Vec<_> = common::rays_traced(rs, |audited| {
            trace(audited, &g, &rays, order);
        })
        .into_iter()
        .map(|(r, kind)| {
            let [ox, oy, oz] = r.o.to_array().map(f32::to_bits);
            let [dx, dy, dz] = r.d.to_array().map(f32::to_bits);
            (
                [ox, oy, oz, dx, dy, dz, r.o_err.to_bits(), r.t_max.to_bits()],
                format!("{kind:?}"),
            )
        })
        .collect();
        seen.sort();
        seen
    };
    assert!(
        seen(Order::Waves) == seen(Order::DepthFirst),
        "{name}: the rays traced differ"
    );
}

/// `rs`'s emitters with no hit sampling them (`light_samples` 0, which a scene file cannot
/// ask for): chains through mirror and glass see them (emission changes some `L_i`, so each
/// node's `le` matters), and both orders agree.
fn unsampled_emitter_seen(name: &str, rs: &RenderScene) {
    unsampled_emitter_seen_by(name, rs, 200);
}

/// [`unsampled_emitter_seen`] with `count` rays.
fn unsampled_emitter_seen_by(name: &str, rs: &RenderScene, count: usize) {
    let g = Global {
        light_samples: 0,
        ..global(rs)
    };
    let mut dark = rs.clone();
    dark.set_effects(rtis::effects::Effects {
        emission: false,
        ..rs.effects
    });
    let rays = rays(rs, count, 11);
    assert_ne!(
        trace(rs, &g, &rays, Order::DepthFirst).0,
        trace(&dark, &g, &rays, Order::DepthFirst).0,
        "{name}: the emitters are never seen"
    );
    agree_on(name, rs, &g, count);
}

/// The first hit's rays of Eq. 4, made in lanes (`hemisphere_rays`), are the scalar warp's and
/// `Interaction::spawn`'s to the bit, in every instruction set, at hits on every surface of the
/// course's box (both sides of the glass ball), for numbers that reach 0 and 1.
#[test]
fn first_hit_rays_in_lanes_are_the_scalar_ones() {
    use rtis::geometry::{Frame, Origins};
    use rtis::sampling::hemisphere;
    let cornell = scenes_dir().join("cornell.ron");
    let rs = rtis::extract(&scene(&format!(
        "Scene(extends: {:?})",
        cornell.to_str().unwrap()
    )));
    let mut s = Sampler::new(3, 0, 0);
    let mut us: Vec<(f32, f32)> = (0..61).map(|_| s.next_2d()).collect();
    us.extend([(0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0)]);
    rtis::accel::require_all_isas();
    let mut hits = 0;
    for ray in rays(&rs, 200, 7) {
        let Some(hit) = rs.geometry.intersect(&ray) else {
            continue;
        };
        hits += 1;
        let n = if hit.n.dot(-ray.d) < 0.0 {
            -hit.n
        } else {
            hit.n
        };
        let (frame, origins) = (Frame::from_normal(n), Origins::new(&hit));
        let want: Vec<_> = us
            .iter()
            .map(|&(u1, u2)| {
                let w = frame.to_world(hemisphere::uniform(u1, u2));
                (w, origins.ray(w, f32::INFINITY))
            })
            .collect();
        for isa in rtis::accel::Isa::all_available() {
            let mut rs = rs.clone();
            assert!(rs.geometry.bvh.set_isa(isa));
            let mut stats = RayStats::default();
            let tr = rs.tracer(Sampler::new(0, 0, 0), &mut stats);
            let (mut w, mut rays) = (Vec::new(), Vec::new());
            rtis::shader::global::hemisphere_rays(&tr, &frame, &origins, &us, (&mut w, &mut rays));
            assert_eq!(w.len(), us.len());
            for (k, ((w, r), (want_w, want_r))) in w.iter().zip(&rays).zip(&want).enumerate() {
                let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
                assert_eq!(bits(*w), bits(*want_w), "{}: direction {k}", isa.name());
                assert_eq!(
                    (bits(r.o), bits(r.d), r.o_err.to_bits(), r.t_max.to_bits()),
                    (
                        bits(want_r.o),
                        bits(want_r.d),
                        want_r.o_err.to_bits(),
                        want_r.t_max.to_bits()
                    ),
                    "{}: ray {k}",
                    isa.name()
                );
            }
        }
    }
    assert!(hits > 100, "few hits: {hits}");
}

/// The Sobol' sampler: the waves draw each node's numbers in the walk's order, so they give
/// its bits with Sobol' points too (each draw a dimension of its own), at depths 1 to 3.
#[test]
fn waves_give_the_depth_first_bits_with_the_sobol_sampler() {
    let cornell = scenes_dir().join("cornell.ron");
    let cornell = cornell.to_str().unwrap();
    for d in 1..=3 {
        let text = format!(
            "Scene(extends: {cornell:?}, film: (width: 720, height: 576, sampler: Sobol), shader: Global(samples: 4, max_depth: {d}, ambient: (0.3, 0.3, 0.3)))"
        );
        let rs = rtis::extract(&scene(&text));
        assert_eq!(rs.film.sampler, rtis::sampling::SamplerKind::Sobol);
        agree(&format!("Sobol', D = {d}"), &rs);
    }
}

/// The course's box under every depth from 1 to 8, with glass and mirror chains, and with
/// each effect switched off in turn.
#[test]
fn waves_give_the_depth_first_bits_in_the_course_box() {
    let cornell = scenes_dir().join("cornell.ron");
    let cornell = cornell.to_str().unwrap();
    for d in 1..=8 {
        let text = format!(
            "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: {d}, ambient: (0.3, 0.3, 0.3)))"
        );
        agree(&format!("D = {d}"), &rtis::extract(&scene(&text)));
    }
    // Mirror and glass chains cut short.
    let text = format!(
        "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.3, 0.3, 0.3)))"
    );
    let rs = rtis::extract(&scene(&text));
    for max_specular in [0, 1, 2] {
        let g = Global {
            max_specular,
            ..global(&rs)
        };
        agree_with(&format!("max_specular {max_specular}"), &rs, &g);
    }
    for effect in [
        "shadows",
        "reflection",
        "refraction",
        "emission",
        "indirect",
        "ambient",
        "background",
    ] {
        let text = format!(
            "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.3, 0.3, 0.3)), effects: ({effect}: false))"
        );
        agree(&format!("{effect} off"), &rtis::extract(&scene(&text)));
    }
    // A sky that escaped chains see.
    let text = format!(
        "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.3, 0.3, 0.3)), background: (0.5, 0.6, 0.7))"
    );
    agree("a sky", &rtis::extract(&scene(&text)));
    // Coloured point lights beside the grey ones (the light pass divides once for a grey
    // light, three times for a coloured one).
    let text = format!(
        "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.3, 0.3, 0.3)), \
         entities: [(light: Point(position: (1, 2.5, 4), intensity: (9, 3, 0.5))), \
         (light: Point(position: (-1.5, 1, 1), intensity: (0, 2, 6)))])"
    );
    agree("coloured lights", &rtis::extract(&scene(&text)));
    // Spot lights, grey and coloured, whose cones end on the walls: their falloff lane by
    // lane gives the walk's bits.
    let text = format!(
        "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.3, 0.3, 0.3)), \
         entities: [(light: Spot(position: (0, 2.5, 3), direction: (0.3, -1, 0.4), intensity: (6, 6, 6), \
         cutoff_angle: 50, beam_width: 20)), \
         (light: Spot(position: (-1, 1, 1), direction: (1, 0, 1), intensity: (1, 4, 2), cutoff_angle: 70))])"
    );
    agree("spot lights", &rtis::extract(&scene(&text)));
    // A sun over the course's spheres on their plane (no ceiling): its light reaches the
    // floor and the spheres, its shadow rays run to infinity; without it the image differs.
    let spheres = scenes_dir().join("spheres.ron");
    let spheres = spheres.to_str().unwrap();
    let sunny = rtis::extract(&scene(&format!(
        "Scene(extends: {spheres:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.1, 0.1, 0.1)), \
         entities: [(light: Directional(direction: (0.3, -1, 0.2), irradiance: (2, 1.5, 1)))])"
    )));
    agree("a sun", &sunny);
    let shaded = rtis::extract(&scene(&format!(
        "Scene(extends: {spheres:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.1, 0.1, 0.1)))"
    )));
    let g = global(&sunny);
    let rays = rays(&sunny, 64, 5);
    assert_ne!(
        trace(&sunny, &g, &rays, Order::Waves).0,
        trace(&shaded, &g, &rays, Order::Waves).0,
        "the sun lights nothing"
    );
    // Ceiling panels with emission off: no hit samples them, and their rectangles are
    // geometry like any other.
    let area = scenes_dir().join("cornell-area.ron");
    let text = format!(
        "Scene(extends: {:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.1, 0.1, 0.1)), effects: (emission: false))",
        area.to_str().unwrap()
    );
    agree("area lights switched off", &rtis::extract(&scene(&text)));
    // A ceiling panel that no hit samples (light_samples 0, which a scene file cannot ask
    // for): chains through mirror and glass see it (each node's `le`, which must matter here).
    let text = format!(
        "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.1, 0.1, 0.1)), \
         entities: [(name: \"panel\", shape: Rectangle(corner: (-2.9, 2.99, -2.9), u: (5.8, 0, 0), v: (0, 0, 11.8)), \
         emitter: Emitter(radiance: (1, 1, 1)))])"
    );
    unsampled_emitter_seen("unsampled area lights", &rtis::extract(&scene(&text)));
    // The same with an emitting sphere, which keeps the scene free of a BVH: its hits are
    // shaded in lanes, and those seen through mirror and glass emit (each node's `le`).
    let text = format!(
        "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.1, 0.1, 0.1)), \
         entities: [(name: \"lamp\", shape: Sphere(center: (1.5, 1.4, 6.5), radius: 1.4), \
         emitter: Emitter(radiance: (2, 1.5, 1)))])"
    );
    let rs = rtis::extract(&scene(&text));
    assert!(
        rs.geometry.bvh.is_empty(),
        "the lamp put the scene in a BVH"
    );
    unsampled_emitter_seen("an unsampled emitting sphere", &rs);
    // Lights outside the room: their shadow rays test the planes too.
    let text = format!(
        "Scene(extends: {cornell:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.3, 0.3, 0.3)))"
    );
    let mut rs = rtis::extract(&scene(&text));
    lights_out_of_room(&mut rs);
    agree("lights out of the room", &rs);
}

/// A mesh in a BVH (answered ray by ray inside the batches), and a Physical box.
#[test]
fn waves_give_the_depth_first_bits_with_a_bvh_and_the_physical_model() {
    for (file, extra) in [
        ("mesh.ron", ""),
        ("cornell.ron", ", model: Physical"),
        ("spheres.ron", ""),
        ("triangles.ron", ""),
    ] {
        let path = scenes_dir().join(file);
        let text = format!(
            "Scene(extends: {:?}, shader: Global(samples: 4, max_depth: 3, ambient: (0.2, 0.2, 0.2)){extra})",
            path.to_str().unwrap()
        );
        agree(file, &rtis::extract(&scene(&text)));
    }
}

/// Where the waves would not give the walk's bits or would outgrow their memory bounds, they
/// stand aside: area-light samples (their random numbers would be drawn in another order),
/// D = 0 (no tree), D > 8, and more than 64 point lights.
#[test]
fn waves_stand_aside_where_they_would_not_give_the_same_bits_or_fit() {
    let applies = |rs: &RenderScene, g: &Global| {
        let mut stats = RayStats::default();
        let tr = rs.tracer(Sampler::new(1, 2, 3), &mut stats);
        Order::Waves.applies(&tr, g)
    };
    let area = scenes_dir().join("cornell-area.ron");
    let text = format!(
        "Scene(extends: {:?}, shader: Global(samples: 4, max_depth: 2, ambient: (0.1, 0.1, 0.1), light_samples: 2))",
        area.to_str().unwrap()
    );
    let rs = rtis::extract(&scene(&text));
    assert!(!applies(&rs, &global(&rs)));
    let cornell = scenes_dir().join("cornell.ron");
    let text = format!(
        "Scene(extends: {:?}, shader: Global(samples: 1, max_depth: 9, ambient: (0.1, 0.1, 0.1)))",
        cornell.to_str().unwrap()
    );
    let rs = rtis::extract(&scene(&text));
    let g = global(&rs);
    assert!(!applies(&rs, &g));
    assert!(applies(&rs, &Global { max_depth: 8, ..g }));
    assert!(!applies(&rs, &Global { max_depth: 0, ..g }));
    // 65 point lights.
    let lights: String = (0..65)
        .map(|k| {
            format!(
                "(light: Point(position: ({}, 2, 3), intensity: (1, 1, 1))),",
                -2.0 + k as f64 * 0.05
            )
        })
        .collect();
    let text = format!(
        "Scene(extends: {:?}, shader: Global(samples: 1, max_depth: 2, ambient: (0.1, 0.1, 0.1)), entities: [{lights}])",
        cornell.to_str().unwrap()
    );
    let rs = rtis::extract(&scene(&text));
    assert_eq!(rs.lights.len(), 68);
    assert!(!applies(&rs, &global(&rs)));
}

/// What the walk meets of the rays the comparison of [`unsampled_emitter_seen_by`] traces
/// (`count` of [`rays`], with `light_samples` 0; every ray but the shadow rays, seen through
/// the tracer's audit): the kind of material (diffuse or glossy Phong, mirror, metal, glass)
/// and of shape of each hit.
fn materials_met(rs: &RenderScene, count: usize) -> Vec<(&'static str, ShapeKind)> {
    use rtis::material::Material;
    let g = Global {
        light_samples: 0,
        ..global(rs)
    };
    let traced = common::rays_traced(rs, |audited| {
        trace(audited, &g, &rays(rs, count, 11), Order::DepthFirst);
    });
    let mut met = Vec::new();
    // Shadow rays are left out: their hits are not shaded.
    for (ray, _) in traced
        .iter()
        .filter(|(_, k)| *k != rtis::stats::RayKind::Shadow)
    {
        let Some(hit) = rs.geometry.intersect(ray) else {
            continue;
        };
        let prim = rs.geometry.prim(hit.prim);
        let what = match rs.materials[prim.material as usize] {
            Material::Phong(p) if p.is_black() => "black",
            Material::Phong(p) if p.ks == Vec3A::ZERO => "diffuse",
            Material::Phong(_) => "glossy",
            Material::Mirror(_) => "mirror",
            Material::Conductor(_) => "metal",
            Material::Transmissive(_) => "glass",
            Material::Bsdf(b) => b.name(),
        };
        let key = (what, prim.shape.kind());
        if !met.contains(&key) {
            met.push(key);
        }
    }
    met
}

/// Each wave kernel against the walk on one scene that holds every material it serves: the
/// course's diffuse Phong (shaded in lanes), a glossy Phong (the scalar reflectance), a mirror,
/// a metal (`Conductor`), glass, and an emitter that chains see (not sampled: `light_samples`
/// 0), with grey and coloured point lights, under both models, on 1000 rays. Packed (the
/// kernel of `waves/lanes.rs`: planes and spheres) and with a BVH (the kernel of `waves.rs`:
/// the same, with triangles of each material and a smooth mesh).
#[test]
fn each_wave_kernel_gives_the_walk_on_every_material_it_serves() {
    let cornell = scenes_dir().join("cornell.ron");
    let packed = "(name: \"lamp\", shape: Sphere(center: (1.5, 1.4, 6.5), radius: 1.4), \
         emitter: Emitter(radiance: (2, 1.5, 1))), \
         (shape: Sphere(center: (-2.2, 2, 7.5), radius: 0.7), material: Phong(kd: (0.2, 0.6, 0.3), ks: (0.5, 0.4, 0.3), shininess: 12)), \
         (shape: Sphere(center: (2.2, -2.2, 2.5), radius: 0.7), material: Conductor(material: \"Cu\")), \
         (shape: Sphere(center: (-0.5, 2, 8), radius: 0.7), material: Transmissive(ior: 1.8, color: (0.9, 1, 0.85))), \
         (shape: Sphere(center: (2.3, 2.1, 1.2), radius: 0.6), material: Mirror(color: (0.9, 0.95, 1)), \
         emitter: Emitter(radiance: (1, 0.6, 0.3))), \
         (light: Point(position: (1, 2.5, 4), intensity: (9, 3, 0.5)))";
    let meshes = "(shape: TriangleMesh(vertices: [(-1.6, -3, 1), (-0.4, -3, 1), (-1, -3, 2), (-1.6, -1.6, 1), (-0.4, -1.6, 1), (-1, -1.6, 2)], \
         faces: [(0, 1, 2), (3, 5, 4), (0, 3, 4), (0, 4, 1), (1, 4, 5), (1, 5, 2), (2, 5, 3), (2, 3, 0)]), material: Transmissive(ior: 1.3, color: (0.9, 1, 0.95))), \
         (shape: TriangleMesh(vertices: [(0.5, -3, 7.5), (2.8, -3, 6.5), (2.8, 0, 6.5), (0.5, 0, 7.5)], faces: [(0, 1, 2), (0, 2, 3)]), material: Mirror(color: (0.95, 0.95, 0.95))), \
         (shape: Triangle(a: (-2.5, -2.99, 0.5), b: (-1, -2.99, 0), c: (-1.8, -2.99, 1.2)), material: Phong(kd: (0.9, 0.9, 0.2))), \
         (shape: TriangleMesh(vertices: [(-2.9, -2, 8), (-1, -2, 8.9), (-1, 1, 8.9), (-2.9, 1, 8)], faces: [(0, 1, 2), (0, 2, 3)]), material: Conductor(material: \"Au\")), \
         (shape: Mesh(path: \"assets/blob.obj\"), material: Phong(kd: (0.6, 0.6, 0.3), ks: (0.3, 0.3, 0.3), shininess: 30), transform: (scale: (0.8, 0.8, 0.8), translate: (1.8, -2, 5))), \
         (shape: Rectangle(corner: (-0.5, 2.9, 2.5), u: (1, 0, 0), v: (0, 0, 1)), emitter: Emitter(radiance: (3, 3, 3)))";
    for (kernel, extra) in [
        ("lanes", packed.to_string()),
        ("bvh", format!("{packed}, {meshes}")),
    ] {
        for model in ["Course", "Physical"] {
            let text = format!(
                "Scene(extends: {:?}, model: {model}, shader: Global(samples: 4, max_depth: 3, ambient: (0.1, 0.1, 0.1)), \
                 entities: [{extra}])",
                cornell.to_str().unwrap()
            );
            let rs = rtis::extract(&scene(&text));
            assert_eq!(rs.geometry.bvh.is_empty(), kernel == "lanes", "{kernel}");
            let name = format!("every material, {kernel}, {model}");
            // The rays of the comparison meet every material: diffuse walls, glossy, mirror,
            // metal and glass spheres, and with a BVH the same five on triangles.
            let met = materials_met(&rs, 1000);
            let mut want = vec![
                ("diffuse", ShapeKind::Plane),
                ("glossy", ShapeKind::Sphere),
                ("mirror", ShapeKind::Sphere),
                ("metal", ShapeKind::Sphere),
                ("glass", ShapeKind::Sphere),
            ];
            if kernel == "bvh" {
                for what in ["diffuse", "glossy", "mirror", "metal", "glass"] {
                    want.push((what, ShapeKind::Triangle));
                }
            }
            for key in want {
                assert!(met.contains(&key), "{name}: no ray meets {key:?}: {met:?}");
            }
            unsampled_emitter_seen_by(&name, &rs, 1000);
        }
    }
}
