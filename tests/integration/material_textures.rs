//! Textures on every material's parameters and normal maps (src/texture/mod.rs,
//! `MaterialTextures`; src/shader/surface.rs, `normal_mapped` and `valid_normal`): a texture of
//! one colour renders the bits of that constant on every material; a flat normal map changes no
//! pixel; a tilted one shades as the tilted normal, exactly, in Mitsuba's tangent frame; a
//! normal leaning to the horizon leaks no light through the surface and leaves no black or
//! non-finite pixel.

use crate::common::{bits, render_str};

/// A checkerboard of one colour `c`.
fn one(c: &str) -> String {
    format!("Checkerboard(color0: {c}, color1: {c})")
}

/// Spheres of the given materials on a Lambertian floor under a sky and a sun, by Path.
fn spheres(materials: &[String]) -> String {
    let balls: String = materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            format!(
                "(shape: Sphere(center: ({}, 0.5, 2), radius: 0.45), material: {m}),",
                i as f32 - (materials.len() as f32 - 1.0) / 2.0
            )
        })
        .collect();
    format!(
        "Scene(film: (width: 32, height: 16, spp: 4), shader: Path(max_depth: 6), model: Physical,
               camera: Perspective(position: (0, 1, -2), look_at: (0, 0.5, 2), fov: 60),
               entities: [
                 (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Phong(kd: (0.5, 0.5, 0.5))),
                 {balls}
                 (light: Environment(radiance: (0.3, 0.3, 0.4))),
                 (light: Directional(direction: (0.3, -1, 0.5), irradiance: (3, 3, 3)))])"
    )
}

/// Every parameter a texture can take, on every material, as a texture of one colour (and a
/// roughness as a grey one): the same bits as the constants.
#[test]
fn one_colour_textures_render_as_their_constants() {
    let materials = |t: &dyn Fn(&str) -> String, a: &dyn Fn(&str) -> String| {
        vec![
            format!(
                "RoughConductor(material: \"Au\", alpha: {}, specular_reflectance: {})",
                a("0.3"),
                t("(0.9, 0.8, 0.7)")
            ),
            format!(
                "RoughConductor(material: \"Cu\", alpha_u: {}, alpha_v: {})",
                a("0.05"),
                a("0.4")
            ),
            format!(
                "RoughDielectric(alpha: {}, specular_reflectance: {}, specular_transmittance: {})",
                a("0.2"),
                t("(0.9, 0.9, 0.8)"),
                t("(0.7, 0.8, 0.9)")
            ),
            format!(
                "RoughPlastic(alpha: 0.2, diffuse_reflectance: {}, specular_reflectance: {})",
                t("(0.2, 0.4, 0.6)"),
                t("(0.8, 0.8, 0.8)")
            ),
            format!(
                "Plastic(diffuse_reflectance: {}, specular_reflectance: {})",
                t("(0.6, 0.3, 0.2)"),
                t("(0.9, 0.9, 0.9)")
            ),
            format!(
                "Conductor(material: \"Ag\", specular_reflectance: {})",
                t("(0.8, 0.9, 1)")
            ),
        ]
    };
    let constant = |c: &str| c.to_string();
    let plain = render_str(&spheres(&materials(&constant, &constant)));
    let grey = |a: &str| one(&format!("({a}, {a}, {a})"));
    let textured = render_str(&spheres(&materials(&one, &grey)));
    assert_eq!(bits(&plain.image), bits(&textured.image));
    // A texture that differs is seen: the same scene with a darker specular texture.
    let darker = |c: &str| {
        if c == "(0.9, 0.8, 0.7)" {
            one("(0.5, 0.5, 0.5)")
        } else {
            one(c)
        }
    };
    let other = render_str(&spheres(&materials(&darker, &grey)));
    assert_ne!(bits(&plain.image), bits(&other.image));
}

/// A texture's roughness is its luminance, clamped to [1e-4, 1]: a map of 2 renders as alpha 1.
#[test]
fn a_roughness_texture_is_clamped() {
    let m = |a: &str| vec![format!("RoughConductor(material: \"Au\", alpha: {a})")];
    let clamped = render_str(&spheres(&m(&one("(1, 1, 1)"))));
    let one_alpha = render_str(&spheres(&m("1")));
    assert_eq!(bits(&clamped.image), bits(&one_alpha.image));
}

/// A floor seen from straight above by an orthographic camera, lit by a sun of irradiance pi
/// from `sun` (the direction light travels), wearing `material`: on a Lambertian floor a
/// pixel's radiance is `kd cos` of the angle between the sun and the shading normal.
fn lit_floor(material: &str, sun: (f32, f32, f32), shader: &str) -> rtis::render::film::Image {
    let text = format!(
        "Scene(film: (width: 8, height: 8, spp: 1), shader: {shader}, model: Physical,
               camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1),
                                    height: 4),
               entities: [
                 (shape: Rectangle(corner: (-3, 0, 3), u: (6, 0, 0), v: (0, 0, -6)), material: {material}),
                 (light: Directional(direction: ({}, {}, {}),
                                     irradiance: (3.14159265, 3.14159265, 3.14159265)))])",
        sun.0, sun.1, sun.2
    );
    render_str(&text).image
}

/// A normal map of the flat normal `(0.5, 0.5, 1)` changes no pixel, on a floor and a sphere,
/// under Direct, Path and Global.
#[test]
fn a_flat_normal_map_changes_no_pixel() {
    let flat = one("(0.5, 0.5, 1)");
    for shader in [
        "Direct()",
        "Path(max_depth: 3)",
        "Global(samples: 2, max_depth: 1)",
    ] {
        let model = if shader.starts_with("Global") {
            "Course"
        } else {
            "Physical"
        };
        let scene = |m: &str| {
            format!(
                "Scene(film: (width: 24, height: 16, spp: 2), shader: {shader}, model: {model},
                   camera: Perspective(position: (0, 1, -3), look_at: (0, 0.5, 2), fov: 50),
                   entities: [
                     (shape: Rectangle(corner: (-3, 0, 5), u: (6, 0, 0), v: (0, 0, -8)), material: {m}),
                     (shape: Sphere(center: (0, 0.6, 2), radius: 0.6), material: {m}),
                     (light: Point(position: (1, 3, -1), intensity: (10, 10, 10)))])"
            )
        };
        let phong = "Phong(kd: (0.6, 0.5, 0.4), ks: (0.2, 0.2, 0.2), shininess: 20)";
        let plain = render_str(&scene(phong));
        let mapped = render_str(&scene(&format!(
            "NormalMap(normal_map: {flat}, material: {phong})"
        )));
        assert_eq!(bits(&plain.image), bits(&mapped.image), "{shader}");
    }
}

/// A normal map tilting the normal by 30 degrees towards the rectangle's `u` (`+x` here): under a
/// sun from 30 degrees on the `+x` side the floor shades as if lit head on (`kd`), under one from
/// the `-x` side as at 60 degrees (`kd / 2`); `2 c - 1` is the normal in the frame of `dp/du`,
/// `n x dp/du` and `n`. Tilted towards `v` (`-z` here, where `t = n x s` points) likewise.
#[test]
fn a_tilted_normal_map_shades_as_its_normal() {
    let (s, c) = (0.5f32, 3f32.sqrt() / 2.0);
    let map = |x: f32, y: f32| {
        one(&format!(
            "({}, {}, {})",
            (x + 1.0) / 2.0,
            (y + 1.0) / 2.0,
            (c + 1.0) / 2.0
        ))
    };
    let kd = 0.8f32;
    for (tilt, sun, want) in [
        (map(s, 0.0), (-s, -c, 0.0), kd),
        (map(s, 0.0), (s, -c, 0.0), kd * 0.5),
        (map(0.0, s), (0.0, -c, s), kd),
        (map(0.0, s), (0.0, -c, -s), kd * 0.5),
    ] {
        let m = format!("NormalMap(normal_map: {tilt}, material: Phong(kd: ({kd}, {kd}, {kd})))");
        let img = lit_floor(&m, sun, "Direct()");
        for row in 0..8 {
            for col in 0..8 {
                let got = img.get(col, row).x;
                assert!(
                    (got - want).abs() < 2e-3,
                    "{tilt}, sun {sun:?}: {got} vs {want}"
                );
            }
        }
    }
}

/// A normal leaning 80 degrees towards `+x` on a one-sided floor lit only from below, at a
/// grazing angle from the `+x` side: the light is above the bent normal but below the surface,
/// and none of it leaks through, under Direct and Path.
#[test]
fn a_leaning_normal_leaks_no_light() {
    let (s, c) = (80f32.to_radians().sin(), 80f32.to_radians().cos());
    let tilt = one(&format!("({}, 0.5, {})", (s + 1.0) / 2.0, (c + 1.0) / 2.0));
    let m = format!("NormalMap(normal_map: {tilt}, material: Phong(kd: (0.8, 0.8, 0.8)))");
    // The light travels towards -x and up: it comes from +x, below the floor.
    for shader in ["Direct()", "Path(max_depth: 4)"] {
        let img = lit_floor(&m, (-0.99, 0.141, 0.0), shader);
        for row in 0..8 {
            for col in 0..8 {
                assert_eq!(img.get(col, row).x, 0.0, "{shader} ({col}, {row})");
            }
        }
    }
}

/// Normals leaning every way, up to the horizon and below it, on a sphere, a floor and a
/// mirror, under sky and sun: every pixel finite, and every pixel of the lit floor seen from
/// above above zero (a shading normal with the viewer below it would give black).
#[test]
fn leaning_normals_leave_no_black_or_non_finite_pixel() {
    for (x, y, z) in [
        (1.0f32, 0.0, 0.0),
        (0.0, -1.0, 0.05),
        (0.7, 0.7, -0.2),
        (0.0, 0.0, -1.0),
    ] {
        let tilt = one(&format!(
            "({}, {}, {})",
            (x + 1.0) / 2.0,
            (y + 1.0) / 2.0,
            (z + 1.0) / 2.0
        ));
        let lambert =
            format!("NormalMap(normal_map: {tilt}, material: Phong(kd: (0.8, 0.8, 0.8)))");
        let img = lit_floor(&lambert, (0.0, -1.0, 0.0), "Path(max_depth: 3)");
        for row in 0..8 {
            for col in 0..8 {
                let v = img.get(col, row);
                assert!(
                    v.is_finite() && v.x > 0.0,
                    "({x}, {y}, {z}) at ({col}, {row}): {v}"
                );
            }
        }
        let balls = [
            lambert.clone(),
            format!("NormalMap(normal_map: {tilt}, material: Mirror())"),
            format!("NormalMap(normal_map: {tilt}, material: RoughConductor(alpha: 0.2))"),
        ];
        let r = render_str(&spheres(&balls));
        for row in 0..16 {
            for col in 0..32 {
                assert!(
                    r.image.get(col, row).is_finite(),
                    "({x}, {y}, {z}): ({col}, {row})"
                );
            }
        }
    }
}

/// Side by side with Mitsuba 3 (bench/mitsuba_texture_reference.py --scene rough): a plastic
/// on a checkerboard, a rough gold sphere with a roughness map and a tint image, a panel
/// bent by a normal map (Mitsuba's `normalmap`), and a rectangle light whose radiance is an
/// OpenEXR image. Two renders of 64 spp agree with Mitsuba's on 4x4 blocks within what noise
/// explains, and in the mean within 1%.
#[test]
fn textured_materials_and_lights_match_mitsuba() {
    let (mse, explained, m) = crate::common::against_mitsuba(
        "texture_rough.ron",
        "mitsuba_texture_rough_160x120_spp4096.exr",
        0.005479,
    );
    eprintln!("block MSE vs Mitsuba {mse:.3e}; noise explains {explained:.3e}; mean {m}");
    assert!(
        mse < 1.5 * explained,
        "block MSE {mse:.3e} vs {explained:.3e}"
    );
    let mean = glam::Vec3A::new(0.42344, 0.4383, 0.4199);
    assert!(
        ((m - mean) / mean).abs().max_element() < 0.01,
        "mean {m} vs {mean}"
    );
}
