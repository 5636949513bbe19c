//! Hard cases stay numerically stable: the empty-room invariant at every size, scale and
//! offset, and random scenes at extreme scales (proptest).

use crate::common;

use crate::common::scene;
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

/// Pixels that differ between the room rendered with shadow rays and without. The shadow
/// rays test the planes even though the lights are in the room (where the renderer skips them,
/// `tests/integration/room.rs`): that is what puts the planes' error bands to the test.
fn seam_pixels(width: u32, height: u32, s: f64, t: DVec3) -> usize {
    let mut lit = rtis::extract(&scene(&room(width, height, s, t, true)));
    common::lights_out_of_room(&mut lit);
    let on = render(&lit, &|| {});
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

/// Offsets follow the error of the computation, so a representable gap stays a gap far from
/// the origin. A camera between two planes `g` apart looks along them and sees a mirror floor
/// at distance `x`; the reflected ray must meet the ceiling (black: no light) and not start
/// past it and escape to the red background. With the old offset of 128 epsilon |p| the ray
/// escaped beyond |p| = 1.3e5 for a gap of 0.5.
#[test]
fn grazing_ray_between_close_planes_stays_between_them() {
    for (x, g) in [(1e3, 5e-3), (1e4, 5e-2), (1.3e5, 0.5), (1e6, 5.0)] {
        let text = format!(
            r#"Scene(film: (width: 1, height: 1), shader: Direct(), background: (1, 0, 0),
            camera: Perspective(position: (0, {h:?}, 0), look_at: ({x:?}, 0, 0), fov: 0.001),
            entities: [
                (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Mirror()),
                (shape: InfinitePlane(point: (0, {g:?}, 0), normal: (0, -1, 0)), material: Phong(kd: (1, 1, 1))),
            ])"#,
            h = g / 2.0
        );
        let r = common::render_str(&text);
        assert_eq!(
            r.stats.reflection, 1,
            "x {x}: the camera ray meets the mirror"
        );
        assert_eq!(
            r.image.pixels[0],
            glam::Vec3A::ZERO,
            "x {x}, gap {g}: the reflected ray escaped"
        );
    }
}

/// Proptest cases: `PROPTEST_CASES` when set (for long runs), else `default` (seconds in CI).
fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A PNG of `w x 1` texels of varied codes, written once per test run; its path.
fn texture_file(w: u32) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("rtis-stability-{}", std::process::id()));
    let path = dir.join(format!("row{w}.png"));
    if !path.exists() {
        std::fs::create_dir_all(&dir).unwrap();
        let tmp = dir.join(format!("row{w}.{}.png", rand_suffix()));
        image::RgbImage::from_fn(w, 1, |x, _| {
            image::Rgb([(x % 256) as u8, (x * 7 % 256) as u8, 255 - (x % 256) as u8])
        })
        .save(&tmp)
        .unwrap();
        // Written aside and renamed, so that tests on other threads never read half a file.
        std::fs::rename(&tmp, &path).unwrap();
    }
    path
}

/// A number unique to this thread, for temporary names.
fn rand_suffix() -> String {
    format!("{:?}", std::thread::current().id()).replace(|c: char| !c.is_ascii_alphanumeric(), "")
}

mod random_scenes {
    use super::*;
    use proptest::prelude::*;

    /// A number as RON, with enough digits to round-trip.
    fn num(v: f64) -> String {
        format!("{v:e}")
    }

    /// A point of the unit-box room `[-3, 3]^3` under scale `s` and offset `t`.
    fn at(s: f64, t: DVec3, p: DVec3) -> String {
        let q = t + s * p;
        format!("({}, {}, {})", num(q.x), num(q.y), num(q.z))
    }

    fn unit_point() -> impl Strategy<Value = DVec3> {
        (-2.5f64..2.5, -2.5f64..2.5, -2.5f64..2.5).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    fn rgb01() -> impl Strategy<Value = String> {
        prop_oneof![
            Just("(0, 0, 0)".to_string()),
            Just("(1, 1, 1)".to_string()),
            (0.0f64..=1.0, 0.0f64..=1.0, 0.0f64..=1.0).prop_map(|(r, g, b)| format!(
                "({}, {}, {})",
                num(r),
                num(g),
                num(b)
            )),
        ]
    }

    /// A checkerboard at extreme scales, and images of 1x1 and 8192x1 texels (each filter and
    /// wrap, transforms up to 1e9 and down to 1e-9).
    fn texture() -> impl Strategy<Value = String> {
        prop_oneof![
            Just("Checkerboard(color0: (1, 1, 1), color1: (0, 0, 0), uv_transform: (scale: (1e6, 1e-6), rotate: 33))".to_string()),
            Just(format!("Image(path: {:?}, filter: Nearest, wrap: Mirror)", texture_file(1))),
            Just(format!("Image(path: {:?}, wrap: Clamp, raw: true)", texture_file(8192))),
            Just(format!("Image(path: {:?}, filter: Nearest, wrap: Repeat, uv_transform: (scale: (1e9, -1e9)))", texture_file(8192))),
            Just(format!("Image(path: {:?}, filter: Trilinear, uv_transform: (scale: (1e-9, 3), rotate: 45))", texture_file(8192))),
            Just(format!("Image(path: {:?}, filter: Trilinear, wrap: Mirror)", texture_file(1))),
        ]
    }

    /// Every material, with extreme but valid parameters.
    fn material() -> impl Strategy<Value = String> {
        prop_oneof![
            (
                rgb01(),
                rgb01(),
                prop_oneof![Just(0.0), Just(1.0), Just(100.0), Just(1e6)]
            )
                .prop_map(|(kd, ks, s)| format!(
                    "Phong(kd: {kd}, ks: {ks}, shininess: {})",
                    num(s)
                )),
            rgb01().prop_map(|c| format!("Mirror(color: {c})")),
            // Textures on Phong, a mirror and glass.
            (texture(), 0u8..3).prop_map(|(t, m)| match m {
                0 => format!("Phong(kd: {t}, ks: {t}, shininess: 10)"),
                1 => format!("Mirror(color: {t})"),
                _ => format!("Transmissive(ior: 1.5, color: {t})"),
            }),
            // Textures on the rough materials' colours and roughness (a texture's values of 0
            // and 1 clamp to alpha 1e-4 and 1), and normal maps of every texture (normals
            // leaning to and below the horizon) around Phong, a mirror and a rough metal.
            (texture(), 0u8..6).prop_map(|(t, m)| match m {
                0 => format!("RoughConductor(alpha: {t}, specular_reflectance: {t})"),
                1 => format!(
                    "RoughDielectric(alpha_u: {t}, alpha_v: 0.3, specular_reflectance: {t}, \
                     specular_transmittance: {t})"
                ),
                2 => format!("RoughPlastic(diffuse_reflectance: {t}, specular_reflectance: {t})"),
                3 => format!(
                    "NormalMap(normal_map: {t}, material: Phong(kd: {t}, ks: (0.5, 0.5, 0.5)))"
                ),
                4 => format!("NormalMap(normal_map: {t}, material: Mirror())"),
                _ => format!("NormalMap(normal_map: {t}, material: RoughConductor(alpha: {t}))"),
            }),
            // Metals: three named ones (a mirror among them), and eta and k at the ends of
            // their range, 0 to 1000 (eta 0 with k 0 reflects everything at every angle).
            (
                prop_oneof![
                    Just("material: \"Au\"".to_string()),
                    Just("material: \"Cr\"".to_string()),
                    Just("material: \"none\"".to_string()),
                    Just("eta: (0, 0, 0), k: (0, 0, 0)".to_string()),
                    Just("eta: (1000, 0.001, 1), k: (0, 1000, 1e-3)".to_string()),
                ],
                rgb01()
            )
                .prop_map(|(m, c)| format!("Conductor({m}, specular_reflectance: {c})")),
            (
                prop_oneof![Just(0.01), Just(1.0), Just(1.5), Just(2.4), Just(100.0)],
                rgb01()
            )
                .prop_map(|(ior, c)| format!("Transmissive(ior: {}, color: {c})", num(ior))),
            // Rough materials and plastics at the ends of their ranges: alpha 1e-4 and 1 (and
            // an anisotropic pair), indices 1.0001 and 4 (against an outside of 1), both
            // distributions and samplers.
            (
                prop_oneof![
                    Just("RoughConductor"),
                    Just("RoughDielectric"),
                    Just("RoughPlastic")
                ],
                prop_oneof![Just("alpha: 1e-4"), Just("alpha: 1"), Just("alpha: 0.2")],
                prop_oneof![Just("Ggx"), Just("Beckmann")],
                prop_oneof![Just("Visible"), Just("Full")],
                prop_oneof![Just(1.0001), Just(1.5), Just(4.0)],
                rgb01(),
            )
                .prop_map(|(m, a, d, smp, ior, c)| match m {
                    "RoughConductor" => format!(
                        "RoughConductor(distribution: {d}, {a}, material: \"Cu\", \
                         specular_reflectance: {c}, sampling: {smp})"
                    ),
                    "RoughDielectric" => format!(
                        "RoughDielectric(distribution: {d}, {a}, int_ior: {}, ext_ior: 1, \
                         specular_transmittance: {c}, sampling: {smp})",
                        num(ior)
                    ),
                    _ => format!(
                        "RoughPlastic(distribution: {d}, {a}, int_ior: {}, ext_ior: 1, \
                         diffuse_reflectance: {c}, sampling: {smp}, nonlinear: true)",
                        num(ior)
                    ),
                }),
            Just("RoughDielectric(alpha_u: 1e-4, alpha_v: 1, int_ior: 4, ext_ior: 1)".to_string()),
            (prop_oneof![Just(1.0001), Just(4.0)], rgb01()).prop_map(|(ior, c)| format!(
                "Plastic(int_ior: {}, ext_ior: 1, diffuse_reflectance: {c})",
                num(ior)
            )),
        ]
    }

    /// Spheres, planes, triangles and meshes inside the room, each with a material.
    fn shape(s: f64, t: DVec3) -> impl Strategy<Value = String> {
        prop_oneof![
            (unit_point(), 0.05f64..1.5).prop_map(move |(c, r)| format!(
                "Sphere(center: {}, radius: {})",
                at(s, t, c),
                num(r * s)
            )),
            (unit_point(), unit_point()).prop_filter_map("zero normal", move |(p, n)| {
                (n.length() > 0.1).then(|| {
                    format!(
                        "InfinitePlane(point: {}, normal: ({}, {}, {}))",
                        at(s, t, p),
                        num(n.x),
                        num(n.y),
                        num(n.z)
                    )
                })
            }),
            (unit_point(), unit_point(), unit_point()).prop_map(move |(a, b, c)| format!(
                "Triangle(a: {}, b: {}, c: {})",
                at(s, t, a),
                at(s, t, b),
                at(s, t, c)
            )),
            (unit_point(), unit_point(), unit_point()).prop_filter_map(
                "parallel edges",
                move |(c, u, v)| {
                    (u.cross(v).length() > 1e-3).then(|| {
                        format!(
                            "Rectangle(corner: {}, u: ({}, {}, {}), v: ({}, {}, {}))",
                            at(s, t, c),
                            num(u.x * s),
                            num(u.y * s),
                            num(u.z * s),
                            num(v.x * s),
                            num(v.y * s),
                            num(v.z * s)
                        )
                    })
                }
            ),
            (unit_point(), 0.1f64..1.0).prop_map(move |(c, r)| {
                // An octahedron: a closed mesh.
                let v: Vec<String> = [
                    DVec3::X,
                    -DVec3::X,
                    DVec3::Y,
                    -DVec3::Y,
                    DVec3::Z,
                    -DVec3::Z,
                ]
                .iter()
                .map(|d| at(s, t, c + r * *d))
                .collect();
                format!(
                    "TriangleMesh(vertices: [{}], faces: [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), \
                     (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)])",
                    v.join(", ")
                )
            }),
        ]
    }

    /// Every shader, with settings kept small enough for a test.
    fn shader(s: f64) -> impl Strategy<Value = String> {
        prop_oneof![
            Just("Intersection()".to_string()),
            Just(format!("Depth(max_distance: {})", num(20.0 * s))),
            Just("Normal".to_string()),
            (0u32..40, 1u32..4)
                .prop_map(|(m, k)| format!("Direct(max_specular: {m}, light_samples: {k})")),
            (
                1u32..4,
                0u32..4,
                prop_oneof![Just(0.0), Just(0.3), Just(1e6)],
                1u32..3,
            )
                .prop_map(|(n, d, a, k)| format!(
                    "Global(samples: {n}, max_depth: {d}, ambient: ({}, {}, {}), max_specular: 16, \
                     light_samples: {k})",
                    num(a),
                    num(a),
                    num(a)
                )),
            (
                prop_oneof![
                    Just("None".to_string()),
                    (0u32..8).prop_map(|d| format!("Some({d})"))
                ],
                0u32..6,
                prop_oneof![Just("Uniform"), Just("Cosine"), Just("Brdf")],
                prop_oneof![Just("Mis"), Just("Light"), Just("Brdf")],
                prop_oneof![Just("All"), Just("One"), Just("Importance")],
            )
                .prop_map(|(d, rr, smp, lights, per_vertex)| format!(
                    "Path(max_depth: {d}, rr_depth: {rr}, sampling: {smp}, lights: {lights}, \
                     lights_per_vertex: {per_vertex})"
                )),
        ]
    }

    prop_compose! {
        /// A random scene: a room of five planes (or none), shapes inside (some emitting), point
        /// lights, a background or an environment light (constant, or a map up to 1e6 bright),
        /// a perspective or orthographic camera, any shader and model, at scale `s` from 1e-4
        /// to 1e4 and offset up to 1e6.
        fn random_scene()(
            s in prop_oneof![Just(1e-4), Just(1e-2), Just(1.0), Just(1e2), Just(1e4)],
            t in prop_oneof![
                Just(DVec3::ZERO),
                (-1e6f64..1e6, -1e6f64..1e6, -1e6f64..1e6).prop_map(|(x, y, z)| DVec3::new(x, y, z)),
            ],
        )(
            s in Just(s),
            t in Just(t),
            room in any::<bool>(),
            shapes in proptest::collection::vec(
                (
                    shape(s, t),
                    material(),
                    proptest::option::of((prop_oneof![Just(1e-3), Just(1.0), Just(1e6)], any::<bool>())),
                ),
                0..5,
            ),
            lights in proptest::collection::vec((unit_point(), prop_oneof![Just(1e-3), Just(7.0), Just(1e6)]), 0..3),
            ortho in any::<bool>(),
            shader in shader(s),
            physical in any::<bool>(),
            background in prop_oneof![Just(0.0), Just(1.0), Just(1e6)],
            sky in 0u8..4,
            spp in 1u32..3,
            seed in any::<u64>(),
        ) -> String {
            let walls = if room {
                [
                    ((-3.0, 0.0, 0.0), "(1, 0, 0)"),
                    ((3.0, 0.0, 0.0), "(-1, 0, 0)"),
                    ((0.0, 3.0, 0.0), "(0, -1, 0)"),
                    ((0.0, -3.0, 0.0), "(0, 1, 0)"),
                    ((0.0, 0.0, 9.0), "(0, 0, -1)"),
                ]
                .iter()
                .map(|&((x, y, z), n)| format!(
                    "(shape: InfinitePlane(point: {}, normal: {n}), material: Phong(kd: (0.8, 0.5, 0.3))),",
                    at(s, t, DVec3::new(x, y, z))
                ))
                .collect::<String>()
            } else {
                String::new()
            };
            // Any shape but a plane may emit.
            let things: String = shapes
                .iter()
                .map(|(sh, m, e)| match e {
                    // A two-sided emitter of radiance 1 has the 8192x1 image's radiance.
                    Some((l, true)) if *l == 1.0 && !sh.starts_with("InfinitePlane") => format!(
                        "(shape: {sh}, material: {m}, emitter: Emitter(radiance: Image(path: {:?}, \
                         filter: Trilinear), two_sided: true)),",
                        texture_file(8192)
                    ),
                    Some((l, two)) if !sh.starts_with("InfinitePlane") => format!(
                        "(shape: {sh}, material: {m}, emitter: Emitter(radiance: ({l}, {l}, {l}), \
                         two_sided: {two})),",
                        l = num(*l)
                    ),
                    _ => format!("(shape: {sh}, material: {m}),"),
                })
                .collect();
            let lamps: String = lights
                .iter()
                .map(|(p, i)| {
                    let i = num(i * s * s);
                    format!("(light: Point(position: {}, intensity: ({i}, {i}, {i}))),", at(s, t, *p))
                })
                .collect();
            let camera = if ortho {
                format!(
                    "Orthographic(position: {}, look_at: {}, height: {})",
                    at(s, t, DVec3::new(0.0, 0.0, -2.9)),
                    at(s, t, DVec3::new(0.1, 0.2, 1.0)),
                    num(5.0 * s)
                )
            } else {
                format!(
                    "Perspective(position: {}, look_at: {}, fov: 70)",
                    at(s, t, DVec3::new(0.0, 0.0, -2.9)),
                    at(s, t, DVec3::new(0.1, 0.2, 1.0))
                )
            };
            // A sky in place of the background: none, a constant one, or the generated map at
            // its own scale or 1e6 times it.
            let map = crate::common::scenes_dir().join("assets/sky.exr");
            let (sky, background) = match sky {
                0 => (String::new(), format!("background: ({b}, {b}, {b}), ", b = num(background))),
                1 => (format!("(light: Environment(radiance: ({b}, {b}, {b}))),", b = num(background)), String::new()),
                k => (
                    format!("(light: Environment(image: {map:?}, scale: {}, rotate: (10, 70, 0))),",
                            if k == 2 { "1" } else { "1e6" }),
                    String::new(),
                ),
            };
            // Rough materials and plastics render under the Physical model, in Direct and
            // Path: a scene with one gets those.
            let bsdf = things.contains("Rough") || things.contains("Plastic(");
            let physical = physical || bsdf;
            let shader = if bsdf && shader.starts_with("Global") { "Path()".to_string() } else { shader };
            format!(
                "Scene(film: (width: 9, height: 7, spp: {spp}), seed: {seed}, camera: {camera}, \
                 shader: {shader}, model: {}, {background}\
                 entities: [{walls} {things} {lamps} {sky}])",
                if physical { "Physical" } else { "Course" }
            )
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(cases(96)))]

        /// Random scenes at extreme scales and offsets, with every shape, material, shader and
        /// model: no panic, no dropped sample, every pixel finite and non-negative.
        #[test]
        fn random_scenes_render_finite(text in random_scene()) {
            let scene = rtis::scene::load_str(&text, "random.ron", None)
                .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
            let r = render(&rtis::extract(&scene), &|| {});
            prop_assert_eq!(r.stats.dropped, 0, "{}", text);
            prop_assert!(
                r.image.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0),
                "{}", text
            );
        }

        /// The empty-room invariant at random sizes, scales from 1e-4 to 1e4 and offsets up to
        /// 1e6.
        #[test]
        fn empty_room_invariant_holds_at_random_scales(
            w in 1u32..90,
            h in 1u32..90,
            e in -4.0f64..4.0,
            t in (-1e6f64..1e6, -1e6f64..1e6, -1e6f64..1e6),
        ) {
            let n = seam_pixels(w, h, 10f64.powf(e), DVec3::new(t.0, t.1, t.2));
            prop_assert_eq!(n, 0, "{}x{} scale 1e{} offset {:?}", w, h, e, t);
        }
    }
}
