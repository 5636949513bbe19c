//! Texture coordinates (src/accel/mod.rs, `Geometry::uv`), Mitsuba 3's conventions: exact
//! values at known points of every shape, through a ray that hits there (each shape textured:
//! only a textured shape keeps its corners' coordinates). Textures
//! (src/texture/): the checkerboard at known points, an image's texels decoded from sRGB or
//! raw, a texture's mean over its shape, an image read once, and located errors.

use crate::common::scene;
use glam::{Vec2, Vec3A};
use rtis::geometry::Ray;

/// The texture coordinates where the ray from `from` along `dir` first meets the scene of
/// `entities` (the camera at the origin, so render and scene coordinates agree).
fn uv_at(entities: &str, from: Vec3A, dir: Vec3A) -> Vec2 {
    let s = scene(&format!("Scene(entities: [{entities}])"));
    let r = rtis::extract(&s);
    let hit = r
        .geometry
        .intersect(&Ray::new(from, dir.normalize()))
        .expect("the ray meets the shape");
    let prim = r.geometry.prim(hit.prim);
    r.geometry.uv(&prim, hit.p)
}

fn close(a: Vec2, b: Vec2) -> bool {
    (a - b).abs().max_element() < 1e-5
}

/// A sphere: `u = atan2(y, x) / (2 pi)` in [0, 1) and `v = acos(z) / pi` of the direction from
/// its centre: +x at (0, 1/2), +y a quarter round, -x half, -y three quarters, +z the pole.
#[test]
fn sphere_coordinates() {
    let e = "(shape: Sphere(center: (1, 2, 3), radius: 2), material: Phong(kd: Checkerboard(color0: (1, 1, 1))))";
    let c = Vec3A::new(1.0, 2.0, 3.0);
    for (d, want) in [
        (Vec3A::X, Vec2::new(0.0, 0.5)),
        (Vec3A::Y, Vec2::new(0.25, 0.5)),
        (-Vec3A::X, Vec2::new(0.5, 0.5)),
        (-Vec3A::Y, Vec2::new(0.75, 0.5)),
        (Vec3A::new(0.0, 1.0, 1.0).normalize(), Vec2::new(0.25, 0.25)),
        (-Vec3A::Z, Vec2::new(0.0, 1.0)),
    ] {
        // From outside, straight at the point c + 2 d.
        let uv = uv_at(e, c + 5.0 * d, -d);
        let ok = close(uv, want) || (want.y == 1.0 && (uv.y - 1.0).abs() < 1e-5);
        assert!(ok, "{d}: {uv} against {want}");
    }
}

/// A rectangle: `(s, t)` of `corner + s u + t v`, in both of its triangles, also mirrored by
/// its transform; a triangle without coordinates: its barycentric `(b1, b2)`.
#[test]
fn rectangle_and_triangle_coordinates() {
    let rect = "(shape: Rectangle(corner: (-1, -1, 5), u: (2, 0, 0), v: (0, 3, 0)),
                 material: Phong(kd: Checkerboard(color0: (1, 1, 1))))";
    for (s, t) in [(0.25f32, 0.5f32), (0.75, 0.25), (0.1, 0.9)] {
        let p = Vec3A::new(-1.0 + 2.0 * s, -1.0 + 3.0 * t, 5.0);
        let uv = uv_at(rect, Vec3A::ZERO, p);
        assert!(close(uv, Vec2::new(s, t)), "({s}, {t}): {uv}");
    }
    let mirrored = "(shape: Rectangle(corner: (-1, -1, 5), u: (2, 0, 0), v: (0, 3, 0)),
                     material: Phong(kd: Checkerboard(color0: (1, 1, 1))),
                     transform: (scale: (-1, 1, 1)))";
    // Mirrored in x, the point (s, t) lands at x = -(-1 + 2 s); in both triangles.
    for (s, t) in [(0.2f32, 0.7f32), (0.8, 0.1)] {
        let p = Vec3A::new(1.0 - 2.0 * s, -1.0 + 3.0 * t, 5.0);
        let uv = uv_at(mirrored, Vec3A::ZERO, p);
        assert!(close(uv, Vec2::new(s, t)), "mirrored ({s}, {t}): {uv}");
    }
    // A mirrored triangle keeps the barycentric coordinates of its vertices as written.
    let tri = "(shape: Triangle(a: (0, 0, 4), b: (2, 0, 4), c: (0, 2, 4)),
                material: Phong(kd: Checkerboard(color0: (1, 1, 1))),
                transform: (scale: (-1, 1, 1)))";
    let uv = uv_at(tri, Vec3A::ZERO, Vec3A::new(-2.0 * 0.2, 2.0 * 0.3, 4.0));
    assert!(close(uv, Vec2::new(0.2, 0.3)), "mirrored triangle: {uv}");

    let tri = "(shape: Triangle(a: (0, 0, 4), b: (2, 0, 4), c: (0, 2, 4)),
                material: Phong(kd: Checkerboard(color0: (1, 1, 1))))";
    let p = Vec3A::new(2.0 * 0.2, 2.0 * 0.3, 4.0);
    let uv = uv_at(tri, Vec3A::ZERO, p);
    assert!(close(uv, Vec2::new(0.2, 0.3)), "triangle: {uv}");
}

/// An infinite plane: the offset from its point along the two world axes other than the
/// normal's largest (`x, z` for a floor).
#[test]
fn plane_coordinates() {
    let floor = "(shape: InfinitePlane(point: (1, -1, 2), normal: (0, 1, 0)),
                  material: Phong(kd: Checkerboard(color0: (1, 1, 1))))";
    let uv = uv_at(floor, Vec3A::new(3.0, 1.0, -1.0), -Vec3A::Y);
    assert!(close(uv, Vec2::new(2.0, -3.0)), "floor: {uv}");
    let wall = "(shape: InfinitePlane(point: (5, 0, 0), normal: (-1, 0.2, 0)),
                 material: Phong(kd: Checkerboard(color0: (1, 1, 1))))";
    // The ray meets the wall at (5.1, 0.5, 1.5); the wall's u is z and its v is y, from its
    // point (5, 0, 0).
    let uv = uv_at(wall, Vec3A::new(0.0, 0.5, 1.5), Vec3A::X);
    assert!(close(uv, Vec2::new(1.5, 0.5)), "wall: {uv}");
}

/// An OBJ mesh's `vt`, with `v` flipped as Mitsuba reads OBJ files, interpolated across a face.
#[test]
fn mesh_coordinates_flip_v() {
    let dir = std::env::temp_dir().join(format!("rtis-uv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("quad.obj");
    std::fs::write(
        &obj,
        "v -1 -1 3\nv 1 -1 3\nv 1 1 3\nvt 0.1 0.2\nvt 0.9 0.2\nvt 0.9 0.8\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let e = format!(
        "(shape: Mesh(path: {:?}), material: Phong(kd: Checkerboard(color0: (1, 1, 1))))",
        obj
    );
    // At the first vertex's corner: (0.1, 1 - 0.2); half-way along the second edge.
    let uv = uv_at(&e, Vec3A::ZERO, Vec3A::new(-0.998, -0.999, 3.0));
    assert!(
        (uv - Vec2::new(0.1, 0.8)).abs().max_element() < 2e-3,
        "{uv}"
    );
    let uv = uv_at(&e, Vec3A::ZERO, Vec3A::new(1.0 - 1e-4, 0.0, 3.0));
    assert!(
        (uv - Vec2::new(0.9, 0.5)).abs().max_element() < 1e-3,
        "{uv}"
    );
}

/// `entities` seen from above, lit by a sun straight down of irradiance pi under the Physical
/// model: on a Lambertian floor each pixel's radiance is exactly the `kd` at its centre.
fn floor_kd(entities: &str) -> rtis::render::film::Image {
    let text = format!(
        "Scene(film: (width: 8, height: 8, spp: 1), shader: Direct(), model: Physical,
               camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1),
                                    height: 4),
               entities: [{entities}
                 (light: Directional(direction: (0, -1, 0), irradiance: (3.14159265, 3.14159265, 3.14159265)))])"
    );
    crate::common::render_str(&text).image
}

/// The checkerboard on a floor (its coordinates `(x, z)` from the plane's point): `color0`
/// where the fractional parts are both below or both above 1/2, `color1` elsewhere, at every
/// pixel centre (one pixel is half a unit).
#[test]
fn checkerboard_at_known_points() {
    let img = floor_kd(
        "(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
          material: Phong(kd: Checkerboard(color0: (0.9, 0.8, 0.7), color1: (0.1, 0.2, 0.3)))),",
    );
    for row in 0..8u32 {
        for col in 0..8u32 {
            let (x, z) = (
                (col as f32 + 0.5 - 4.0) * 0.5,
                (4.0 - row as f32 - 0.5) * 0.5,
            );
            let (fx, fz) = (x - x.floor(), z - z.floor());
            let want = if (fx > 0.5) == (fz > 0.5) { 0.9 } else { 0.1 };
            let got = img.get(col, row).x;
            assert!(
                (got - want).abs() < 1e-5,
                "({col}, {row}) at ({x}, {z}): {got}"
            );
        }
    }
}

/// Write a `w x h` image of 8-bit codes `code(x, y)` (grey) as PNG, and return its path.
fn grey_png(name: &str, w: u32, h: u32, code: impl Fn(u32, u32) -> u8) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("rtis-tex-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("image.png");
    image::GrayImage::from_fn(w, h, |x, y| image::Luma([code(x, y)]))
        .save(&path)
        .unwrap();
    path
}

/// A rectangle filling the view from above, its corner at the picture's top left: texture
/// coordinates `((col + 1/2) / 8, (row + 1/2) / 8)` at pixel `(col, row)`.
fn rectangle(kd: &str) -> String {
    format!(
        "(shape: Rectangle(corner: (-2, 0, 2), u: (4, 0, 0), v: (0, 0, -4)),
          material: Phong(kd: {kd})),"
    )
}

/// An 8-bit PNG, nearest texel: each pixel is its texel's sRGB code decoded (IEC 61966-2-1),
/// the image's top row at `v = 0`; with `raw: true`, the code over 255.
#[test]
fn image_texels_decode_from_srgb_or_raw() {
    let codes = [[0u8, 10, 128, 255], [64, 200, 30, 100]];
    let path = grey_png("codes", 4, 2, |x, y| codes[y as usize][x as usize]);
    for raw in [false, true] {
        let kd = format!("Image(path: {path:?}, filter: Nearest, raw: {raw})");
        let img = floor_kd(&rectangle(&kd));
        for row in 0..8u32 {
            for col in 0..8u32 {
                let c = codes[(row / 4) as usize][(col / 2) as usize] as f32 / 255.0;
                let want = if raw {
                    c
                } else {
                    rtis::raster::srgb_to_linear(c)
                };
                let got = img.get(col, row).x;
                assert!(
                    (got - want).abs() < 1e-5,
                    "raw {raw}, ({col}, {row}): {got} vs {want}"
                );
            }
        }
    }
}

/// A texture's mean over its rectangle is the image's mean: with repeat, the bilinear
/// interpolant's integral over the unit square is the texels' mean, and the render of the
/// rectangle filling the view (16 stratified samples a pixel) estimates it.
#[test]
fn a_textures_mean_over_its_shape_is_the_images() {
    let code = |x: u32, y: u32| ((x * 37 + y * 101 + x * y * 13) % 256) as u8;
    let path = grey_png("mean", 16, 16, code);
    let want: f64 = (0..16)
        .flat_map(|y| (0..16).map(move |x| (x, y)))
        .map(|(x, y)| rtis::raster::srgb_to_linear(code(x, y) as f32 / 255.0) as f64)
        .sum::<f64>()
        / 256.0;
    let text = format!(
        "Scene(film: (width: 64, height: 64, spp: 16), shader: Direct(), model: Physical,
               camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), up: (0, 0, 1),
                                    height: 4),
               entities: [{}
                 (light: Directional(direction: (0, -1, 0), irradiance: (3.14159265, 3.14159265, 3.14159265)))])",
        rectangle(&format!("Image(path: {path:?})"))
    );
    let r = crate::common::render_str(&text);
    let (mean, _) = crate::common::mean_and_se(&r);
    assert!((mean - want).abs() < 2e-3 * want, "{mean} against {want}");
}

/// An image named by two materials is read once: both textures hold the same texels.
#[test]
fn an_image_is_read_once() {
    let path = grey_png("once", 2, 2, |x, _| (x * 100) as u8);
    let text = format!(
        "Scene(entities: [
            (shape: Sphere(center: (0, 0, 3), radius: 1), material: Phong(kd: Image(path: {path:?}))),
            (shape: Sphere(center: (3, 0, 3), radius: 1), material: Mirror(color: Image(path: {path:?}))),
            (light: Point(position: (0, 3, 0), intensity: (1, 1, 1)))])"
    );
    let s = scene(&text);
    let rasters: Vec<_> = s
        .world
        .query::<&rtis::texture::MaterialTextures>()
        .iter()
        .filter_map(|t| match &t.reflectance.as_ref()?.kind {
            rtis::texture::TextureKind::Image(i) => Some(i.raster.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(rasters.len(), 2);
    assert!(std::sync::Arc::ptr_eq(&rasters[0], &rasters[1]));
}

/// Located errors: a missing image names the file and the system's reason; a value that is
/// neither a reflectance nor a texture says what each looks like; a uv_transform beyond 1e9.
#[test]
fn texture_errors_are_located() {
    let err = |kd: &str| {
        let text = format!(
            "Scene(entities: [(shape: Sphere(center: (0, 0, 3), radius: 1),\n  material: Phong(kd: {kd}))])"
        );
        rtis::scene::load_str(&text, "t.ron", None)
            .err()
            .unwrap()
            .to_string()
    };
    let e = err("Image(path: \"no-such.png\")");
    assert!(e.contains("t.ron:2:") && e.contains("no-such.png"), "{e}");
    assert!(e.to_lowercase().contains("no such file"), "{e}");
    let e = err("Checkerboard()");
    assert!(e.contains("give one"), "{e}");
    let e = err("Checker(color0: (1, 1, 1))");
    assert!(e.contains("`Checkerboard` or `Image`"), "{e}");
    // An error inside a texture is its own.
    let e = err("Image(path: \"a.png\", wrap: Repet)");
    assert!(e.contains("`Repeat`, `Clamp`, or `Mirror`"), "{e}");
    let e = err("Checkerboard(color0: (2, 0, 0))");
    assert!(e.contains("reflectance (2, 0, 0) out of range"), "{e}");
    let e = err("Checkerboard(uv_transform: (scale: (0, 1)))");
    assert!(e.contains("flattens the texture"), "{e}");
    let e = err("(2, 0, 0)");
    assert!(
        e.contains("`kd`: reflectance (2, 0, 0) out of range"),
        "{e}"
    );
    let e = err("(0.5, 0.5)");
    assert!(e.contains("expected 3 values, found 2"), "{e}");
    let e = err("Checkerboard(uv_transform: (scale: (1e10, 1)))");
    assert!(e.contains("within 1e9"), "{e}");
}

/// Side by side with Mitsuba 3 (bench/mitsuba_texture_reference.py): a checkerboard floor, and
/// a sphere and a panel wearing tests/data/texture.png (bilinear, repeat, sRGB), under a
/// constant sky and a sun. Two renders of 64 spp agree with Mitsuba's 4096 spp on 4x4 blocks
/// within what noise explains, and in the mean within 1%: the coordinates of spheres and
/// rectangles, the image's orientation and its decoding are Mitsuba's. The same scene with
/// Mitsuba's default pixel filter (`gaussian`, stddev 0.5) agrees with Mitsuba's image of it,
/// and not with the box-filtered one (so the comparison sees the filter).
#[test]
fn textures_match_mitsuba() {
    let mean = Vec3A::new(0.382143, 0.425077, 0.420579);
    for (scene, reference, noise) in [
        (
            "texture.ron",
            "mitsuba_texture_160x120_spp4096.exr",
            0.002932,
        ),
        (
            "texture_gaussian.ron",
            "mitsuba_texture_gaussian_160x120_spp4096.exr",
            0.001655,
        ),
    ] {
        let (mse, explained, m) = crate::common::against_mitsuba(scene, reference, noise);
        eprintln!("{scene}: block MSE vs Mitsuba {mse:.3e}; noise explains {explained:.3e}");
        assert!(
            mse < 1.5 * explained,
            "{scene}: block MSE {mse:.3e} vs {explained:.3e}"
        );
        assert!(
            ((m - mean) / mean).abs().max_element() < 0.01,
            "{scene}: mean {m} vs {mean}"
        );
    }
    let (mse, explained, _) = crate::common::against_mitsuba(
        "texture_gaussian.ron",
        "mitsuba_texture_160x120_spp4096.exr",
        0.002932,
    );
    eprintln!("gaussian against box: block MSE {mse:.3e}; noise explains {explained:.3e}");
    assert!(
        mse > 1.5 * explained,
        "the filter is not seen: {mse:.3e} vs {explained:.3e}"
    );
}

/// Trilinear filtering by the footprint: a black and white checker image on a floor running to
/// the horizon, at one sample a pixel. Near the camera, where a pixel covers less than a
/// texel, trilinear reads level 0: the bilinear image, to the bit. Far away, where a pixel
/// covers many checks, trilinear gives their mean (1/2) with little spread from pixel to pixel,
/// while bilinear aliases (black or white by chance).
#[test]
fn trilinear_does_not_alias_at_the_horizon() {
    let path = grey_png(
        "checks",
        2,
        2,
        |x, y| if (x + y) % 2 == 0 { 0 } else { 255 },
    );
    let render = |filter: &str| {
        let text = format!(
            "Scene(film: (width: 64, height: 48, spp: 1), shader: Direct(), model: Physical,
                   camera: Perspective(position: (0, 1, 0), look_at: (0, 0.8, 10), fov: 40),
                   entities: [
                     (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                      material: Phong(kd: Image(path: {path:?}, filter: {filter}, raw: true))),
                     (light: Directional(direction: (0, -1, 0),
                                         irradiance: (3.14159265, 3.14159265, 3.14159265)))])"
        );
        crate::common::render_str(&text).image
    };
    let (tri, bi) = (render("Trilinear"), render("Bilinear"));
    // The bottom rows are near (a pixel there is a fraction of a texel): the same bits.
    for col in 0..64 {
        assert_eq!(tri.get(col, 47), bi.get(col, 47), "near, column {col}");
    }
    // The rows just below the horizon (near row 22.6): the floor 15 to 60 units away.
    let band = |img: &rtis::render::film::Image| {
        let v: Vec<f64> = (24..28)
            .flat_map(|r| (0..64).map(move |c| (c, r)))
            .map(|(c, r)| img.get(c, r).x as f64)
            .collect();
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt();
        (m, sd, v.len())
    };
    let (m_tri, sd_tri, n) = band(&tri);
    let (_, sd_bi, _) = band(&bi);
    assert_eq!(n, 256);
    assert!(
        (m_tri - 0.5).abs() < 0.05 && sd_tri < 0.1,
        "trilinear: mean {m_tri}, spread {sd_tri}"
    );
    eprintln!(
        "far band: trilinear mean {m_tri:.3}, spread {sd_tri:.3}; bilinear spread {sd_bi:.3}"
    );
    assert!(
        sd_bi > 0.15 && sd_bi > 3.0 * sd_tri,
        "bilinear should alias: spread {sd_bi}"
    );
}

/// The textured path changes nothing but the lookup: a checkerboard of one colour renders the
/// bits of that colour as a constant, under Direct and Path, the Course and Physical models,
/// and with `kd + ks` above 1 under Physical (scaled down at each hit as at extraction), on
/// Phong, a mirror and glass.
#[test]
fn a_one_colour_texture_renders_as_its_constant() {
    let scene = |kd: &str, ks: &str, color: &str, shader: &str, model: &str| {
        format!(
            "Scene(film: (width: 24, height: 18, spp: 4), shader: {shader}, model: {model},
                   camera: Perspective(position: (0, 1, -3), look_at: (0, 0.5, 2), fov: 50),
                   entities: [
                     (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)),
                      material: Phong(kd: {kd}, ks: {ks}, shininess: 20)),
                     (shape: Sphere(center: (-0.7, 0.5, 2), radius: 0.5), material: Mirror(color: {color})),
                     (shape: Sphere(center: (0.7, 0.5, 2), radius: 0.5), material: Transmissive(ior: 1.5, color: {color})),
                     (light: Point(position: (1, 3, -1), intensity: (10, 10, 10)))])"
        )
    };
    let tex = |c: &str| format!("Checkerboard(color0: {c}, color1: {c})");
    for (shader, model) in [
        ("Direct()", "Course"),
        ("Path(max_depth: 4)", "Physical"),
        ("Global(samples: 4, max_depth: 2)", "Course"),
    ] {
        for (kd, ks) in [
            ("(0.6, 0.5, 0.4)", "(0.2, 0.2, 0.2)"),
            ("(0.9, 0.9, 0.9)", "(0.5, 0.5, 0.5)"),
        ] {
            let color = "(0.9, 0.8, 0.7)";
            let plain = crate::common::render_str(&scene(kd, ks, color, shader, model));
            let textured =
                crate::common::render_str(&scene(&tex(kd), &tex(ks), &tex(color), shader, model));
            assert_eq!(
                crate::common::bits(&plain.image),
                crate::common::bits(&textured.image),
                "{shader} {model}, kd {kd}, ks {ks}"
            );
        }
    }
}

/// Every image form the issue names decodes to its values: a 16-bit grey PNG (code over 65535,
/// decoded from sRGB), an 8-bit RGBA PNG (alpha ignored), a flat grey JPEG (decoded from sRGB;
/// JPEG keeps a flat block exact) and a 1x1 and an 8192x1 image (repeat wraps them).
#[test]
fn image_forms_decode() {
    let dir = std::env::temp_dir().join(format!("rtis-forms-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let srgb = rtis::raster::srgb_to_linear;
    let p16 = dir.join("grey16.png");
    image::ImageBuffer::<image::Luma<u16>, _>::from_fn(2, 2, |_, _| image::Luma([40000u16]))
        .save(&p16)
        .unwrap();
    let rgba = dir.join("rgba.png");
    image::RgbaImage::from_fn(2, 2, |_, _| image::Rgba([200, 100, 50, 7]))
        .save(&rgba)
        .unwrap();
    let jpeg = dir.join("flat.jpg");
    image::GrayImage::from_fn(16, 16, |_, _| image::Luma([120]))
        .save(&jpeg)
        .unwrap();
    let one = dir.join("one.png");
    image::GrayImage::from_fn(1, 1, |_, _| image::Luma([77]))
        .save(&one)
        .unwrap();
    let wide = dir.join("wide.png");
    image::GrayImage::from_fn(8192, 1, |x, _| image::Luma([(x % 256) as u8]))
        .save(&wide)
        .unwrap();
    for (path, want) in [
        (&p16, [srgb(40000.0 / 65535.0); 3]),
        (
            &rgba,
            [srgb(200.0 / 255.0), srgb(100.0 / 255.0), srgb(50.0 / 255.0)],
        ),
        (&jpeg, [srgb(120.0 / 255.0); 3]),
        (&one, [srgb(77.0 / 255.0); 3]),
    ] {
        let img = floor_kd(&rectangle(&format!(
            "Image(path: {path:?}, filter: Nearest)"
        )));
        for row in 0..8 {
            for col in 0..8 {
                let got = img.get(col, row);
                let d = (got - glam::Vec3A::from_array(want)).abs().max_element();
                assert!(d < 1e-5, "{path:?} ({col}, {row}): {got} vs {want:?}");
            }
        }
    }
    // 8192 texels across 8 pixels: pixel `col`'s centre is texel 1024 col + 512.
    let img = floor_kd(&rectangle(&format!(
        "Image(path: {wide:?}, filter: Nearest)"
    )));
    for col in 0..8u32 {
        let want = srgb(((1024 * col + 512) % 256) as f32 / 255.0);
        let got = img.get(col, 3).x;
        assert!(
            (got - want).abs() < 1e-5,
            "wide, column {col}: {got} vs {want}"
        );
    }
}

/// Bad texture input, each located: an image of an unknown format, one above the size limit
/// (refused before it is decoded, saying how much memory it needs), a roughness texture's
/// constant out of range, a normal map around a `Named` material, and a texture where a
/// parameter takes none. A mesh without texture coordinates under a texture is a warning.
#[test]
fn more_texture_errors_are_located() {
    let dir = std::env::temp_dir().join(format!("rtis-bad-tex-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = dir.join("notes.png");
    std::fs::write(&text, "not an image").unwrap();
    let huge = dir.join("huge.png");
    image::GrayImage::new(65537, 1).save(&huge).unwrap();
    let load = |material: &str| {
        let text = format!(
            "Scene(model: Physical, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 3), radius: 1),\n  material: {material})])"
        );
        rtis::scene::load_str(&text, "t.ron", None)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let e = load(&format!("Phong(kd: Image(path: {text:?}))"));
    assert!(e.contains("t.ron:2:") && e.contains("notes.png"), "{e}");
    let e = load(&format!("Phong(kd: Image(path: {huge:?}))"));
    assert!(
        e.contains("t.ron:2:") && e.contains("65537x1") && e.contains("MiB"),
        "{e}"
    );
    let e = load("RoughConductor(alpha: 2)");
    assert!(
        e.contains("t.ron:2:") && e.contains("from 1e-4 to 1"),
        "{e}"
    );
    let e = load("RoughConductor(alpha: Image(path: \"r.png\", wrap: Repet))");
    assert!(e.contains("`Repeat`, `Clamp`, or `Mirror`"), "{e}");
    let e =
        load("NormalMap(normal_map: Checkerboard(color0: (0.5, 0.5, 1)), material: Named(\"x\"))");
    assert!(
        e.contains("t.ron:2:") && e.contains("written inline"),
        "{e}"
    );
    let e = load("Conductor(eta: Image(path: \"e.png\"), k: (1, 1, 1))");
    assert!(
        e.contains("t.ron:2:") && e.contains("`eta` takes no texture"),
        "{e}"
    );
    // An emitter's image brighter than a radiance may be.
    let bright = dir.join("bright.exr");
    image::Rgb32FImage::from_fn(2, 1, |x, _| image::Rgb([1e35 * x as f32, 1.0, 1.0]))
        .save(&bright)
        .unwrap();
    let text = format!(
        "Scene(entities: [(shape: Sphere(center: (0, 0, 3), radius: 1),\n  emitter: (radiance: Image(path: {bright:?})))])"
    );
    let e = rtis::scene::load_str(&text, "t.ron", None)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("t.ron:2:") && e.contains("above the limit of 1e30"),
        "{e}"
    );
    // A mesh without `vt` under a texture: rendered, with a warning.
    let obj = dir.join("tri.obj");
    std::fs::write(&obj, "v -1 -1 3\nv 1 -1 3\nv 0 1 3\nf 1 2 3\n").unwrap();
    let s = crate::common::scene(&format!(
        "Scene(entities: [(shape: Mesh(path: {obj:?}), material: Phong(kd: Checkerboard(color0: (1, 1, 1)))),
                          (light: Point(position: (0, 0, 0), intensity: (1, 1, 1)))])"
    ));
    let r = rtis::extract(&s);
    assert!(
        r.warnings
            .iter()
            .any(|w| w.contains("without texture coordinates")),
        "{:?}",
        r.warnings
    );
}
