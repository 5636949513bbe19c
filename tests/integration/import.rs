//! The Mitsuba importer (src/import/): XML mechanics (defaults and `$` substitution, `<ref>`,
//! includes and their cycles, transforms), each plugin converted field by field, located errors
//! for what rtis does not render, and Mitsuba 3's own image of an imported scene.

use crate::common;
use std::path::{Path, PathBuf};

/// A folder of its own for a test's files.
fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtis-import-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The rtis text of the Mitsuba scene `xml` (written to `name.xml` in its own folder).
fn import(name: &str, xml: &str) -> Result<String, String> {
    let d = dir(name);
    let path = d.join(format!("{name}.xml"));
    std::fs::write(&path, xml).unwrap();
    rtis::import::import(&path, &d)
        .map(|c| c.text)
        .map_err(|e| e.to_string())
}

/// A number as the importer writes it: 12 significant digits.
fn num(v: f64) -> String {
    let r: f64 = format!("{v:.11e}").parse().unwrap();
    format!("{r:?}")
}

/// A scene of `body`, version 3.0.0.
fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>\n")
}

/// The sensor: a lookat frame, a horizontal field of view made vertical for the film's aspect,
/// the film's size and filter, the sampler's count, and Mitsuba's handedness.
#[test]
fn sensor_film_and_sampler() {
    let text = import(
        "sensor",
        &scene(
            r#"<sensor type="perspective">
                 <float name="fov" value="90"/>
                 <transform name="to_world"><lookat origin="1, 2, 3" target="1, 2, 4" up="0, 1, 0"/></transform>
                 <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
                 <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/>
                   <rfilter type="gaussian"><float name="stddev" value="0.4"/></rfilter></film>
               </sensor>"#,
        ),
    )
    .unwrap();
    assert!(
        text.contains("film: (width: 200, height: 100, spp: 16, filter: Gaussian(stddev: 0.4))"),
        "{text}"
    );
    // tan(45) / 2 = 0.5 vertically: 2 atan(0.5) = 53.13 degrees.
    let fov = 2.0 * 0.5f64.atan().to_degrees();
    assert!(
        text.contains(&format!(
            "camera: Perspective(position: (1.0, 2.0, 3.0), look_at: (1.0, 2.0, 4.0), up: (0.0, 1.0, 0.0), fov: {}, handedness: Right)",
            num(fov)
        )),
        "{text}"
    );
    // Mitsuba's stratified and low-discrepancy samplers are rtis's Sobol' sampler, with the
    // sample counts Mitsuba 3.9 gives them (its `sample_count()` for the counts on the left);
    // another sampler is refused where it is written.
    let counts = [1, 2, 3, 5, 8, 10, 16, 17, 64, 100];
    for (kind, want, jitter) in [
        ("independent", [1, 2, 3, 5, 8, 10, 16, 17, 64, 100], false),
        ("stratified", [1, 4, 4, 9, 9, 16, 16, 25, 64, 100], true),
        ("multijitter", [1, 2, 3, 6, 8, 12, 16, 20, 64, 100], true),
        ("orthogonal", [4, 4, 4, 9, 9, 25, 25, 25, 121, 121], true),
        ("ldsampler", [4, 4, 4, 16, 16, 16, 16, 64, 64, 256], false),
    ] {
        for (n, want) in counts.into_iter().zip(want) {
            let jitter = if jitter {
                r#"<boolean name="jitter" value="false"/>"#
            } else {
                ""
            };
            let xml = scene(&format!(
                r#"<sensor type="perspective">
                     <sampler type="{kind}"><integer name="sample_count" value="{n}"/>{jitter}</sampler>
                   </sensor>"#
            ));
            let text = import(kind, &xml).unwrap();
            let sampler = if kind == "independent" {
                ""
            } else {
                ", sampler: Sobol"
            };
            assert!(
                text.contains(&format!(
                    "spp: {want}, filter: Gaussian(stddev: 0.5){sampler})"
                )),
                "{kind} {n}: {text}"
            );
        }
        let text = import(
            kind,
            &scene(
                r#"<sensor type="perspective"><sampler type="KIND"/></sensor>"#
                    .replace("KIND", kind)
                    .as_str(),
            ),
        )
        .unwrap();
        let s = rtis::extract(&crate::common::scene(&text));
        let want = match kind {
            "independent" => rtis::sampling::SamplerKind::Independent,
            _ => rtis::sampling::SamplerKind::Sobol,
        };
        assert_eq!(s.film.sampler, want, "{kind}");
    }
    // A count that Mitsuba's rounding takes past rtis's limit names both counts.
    let e = import(
        "orthogonal-cap",
        &scene(r#"<sensor type="perspective"><sampler type="orthogonal"><integer name="sample_count" value="1048576"/></sampler></sensor>"#),
    )
    .unwrap_err();
    assert!(
        e.contains("`sample_count` 1048576, which Mitsuba's `orthogonal` rounds up to 1062961"),
        "{e}"
    );
    // A count out of range as written is refused as written.
    let e = import(
        "stratified-over",
        &scene(r#"<sensor type="perspective"><sampler type="stratified"><integer name="sample_count" value="2097152"/></sampler></sensor>"#),
    )
    .unwrap_err();
    assert!(
        e.contains("`sample_count` 2097152: rtis takes 1 to 1048576") && !e.contains("rounds"),
        "{e}"
    );
    // `jitter` belongs to the stratified samplers: on an `ldsampler` it is not read.
    let e = import(
        "ld-jitter",
        &scene(r#"<sensor type="perspective"><sampler type="ldsampler"><boolean name="jitter" value="true"/></sampler></sensor>"#),
    )
    .unwrap_err();
    assert!(e.contains("jitter"), "{e}");
    let e = import(
        "other",
        &scene(r#"<sensor type="perspective"><sampler type="halton"/></sensor>"#),
    )
    .unwrap_err();
    assert!(e.contains("halton") && e.contains("ldsampler"), "{e}");
    // Mitsuba's default filter is a Gaussian, and a film 768x576.
    let text = import("defaults", &scene(r#"<sensor type="perspective"/>"#)).unwrap();
    assert!(
        text.contains("film: (width: 768, height: 576, spp: 4, filter: Gaussian(stddev: 0.5))"),
        "{text}"
    );
}

/// `<default>` values fill `$names`; an unknown name is an error at its attribute.
#[test]
fn defaults_and_substitution() {
    let text = import(
        "defaults",
        &scene(
            r#"<default name="n" value="7"/>
               <integrator type="path"><integer name="max_depth" value="$n"/></integrator>"#,
        ),
    )
    .unwrap();
    assert!(
        text.contains("shader: Path(max_depth: 6, rr_depth: 5)"),
        "{text}"
    );
    let e = import(
        "unknown",
        &scene(r#"<integrator type="path"><integer name="max_depth" value="$m"/></integrator>"#),
    )
    .unwrap_err();
    assert!(e.contains("unknown.xml:2:") && e.contains("`$m`"), "{e}");
}

/// Materials: a declared BSDF becomes a table entry named by its id, referenced as `Named`;
/// twosided unwraps; the Mitsuba defaults (Beckmann, alpha 0.1, BK7 in air) are written out.
#[test]
fn bsdfs_convert_field_by_field() {
    let text = import(
        "bsdfs",
        &scene(
            r#"<bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf></bsdf>
               <shape type="sphere" id="a"><ref id="white"/></shape>
               <shape type="sphere"><bsdf type="roughconductor"><string name="material" value="Au"/></bsdf></shape>
               <shape type="sphere"><bsdf type="roughdielectric"><float name="alpha" value="0.2"/></bsdf></shape>
               <shape type="sphere"><bsdf type="roughplastic"><string name="distribution" value="ggx"/></bsdf></shape>
               <shape type="sphere"><bsdf type="dielectric"><string name="int_ior" value="water"/></bsdf></shape>"#,
        ),
    )
    .unwrap();
    for want in [
        r#""white": Phong(kd: (0.8, 0.8, 0.8), ks: (0, 0, 0)),"#,
        r#"(name: "a", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), material: Named("white")),"#,
        r#"RoughConductor(distribution: Beckmann, alpha: 0.1, material: "Au", specular_reflectance: (1.0, 1.0, 1.0), sampling: Visible)"#,
        r#"RoughDielectric(distribution: Beckmann, alpha: 0.2, int_ior: 1.5046, ext_ior: 1.000277"#,
        r#"RoughPlastic(distribution: Ggx, alpha: 0.1, sampling: Visible, int_ior: 1.49, ext_ior: 1.000277, diffuse_reflectance: (0.5, 0.5, 0.5)"#,
        &format!("Transmissive(ior: {}", num(1.333 / 1.000277)),
    ] {
        assert!(text.contains(want), "{want}\nnot in\n{text}");
    }
}

/// Emitters: point, spot (its frame's +z), directional, constant and envmap (a rotation as
/// Euler angles), and an area emitter on a shape.
#[test]
fn emitters_convert() {
    let text = import(
        "emitters",
        &scene(
            r#"<emitter type="point"><point name="position" x="1" y="2" z="3"/><rgb name="intensity" value="5"/></emitter>
               <emitter type="spot"><transform name="to_world"><lookat origin="0, 3, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
                 <float name="cutoff_angle" value="30"/></emitter>
               <emitter type="directional"><vector name="direction" x="0" y="-1" z="0"/><rgb name="irradiance" value="2"/></emitter>
               <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
               <shape type="sphere"><emitter type="area"><rgb name="radiance" value="3, 2, 1"/></emitter></shape>"#,
        ),
    )
    .unwrap();
    for want in [
        "(light: Point(position: (1.0, 2.0, 3.0), intensity: (5.0, 5.0, 5.0))),",
        "(light: Spot(position: (0.0, 3.0, 0.0), direction: (0.0, -1.0, 0.0), intensity: (1.0, 1.0, 1.0), cutoff_angle: 30.0, beam_width: 22.5)),",
        "(light: Directional(direction: (0.0, -1.0, 0.0), irradiance: (2.0, 2.0, 2.0))),",
        "(light: Environment(radiance: (0.5, 0.5, 0.5))),",
        "emitter: (radiance: (3.0, 2.0, 1.0))",
    ] {
        assert!(text.contains(want), "{want}\nnot in\n{text}");
    }
}

/// Mitsuba's rotation, as rtis's Euler angles, rebuilds the same matrix.
#[test]
fn euler_angles_rebuild_the_rotation() {
    use glam::{DMat3, DVec3};
    for (axis, angle) in [
        (DVec3::new(1.0, 2.0, 3.0), 40.0f64),
        (DVec3::Y, -75.0),
        (DVec3::new(-1.0, 0.5, 0.2), 170.0),
    ] {
        let r = DMat3::from_axis_angle(axis.normalize(), angle.to_radians());
        let (x, y, z) = rtis::import::convert::euler_xyz(&r);
        let rebuilt = DMat3::from_rotation_z(z.to_radians())
            * DMat3::from_rotation_y(y.to_radians())
            * DMat3::from_rotation_x(x.to_radians());
        assert!(
            rebuilt.abs_diff_eq(r, 1e-9),
            "{axis} {angle}: {rebuilt} vs {r}"
        );
    }
}

/// Bad input: malformed XML, an unknown plugin, a missing `ref`, an unsupported property, an
/// include cycle; each a located error naming what is wrong.
#[test]
fn bad_input_is_located() {
    let e = import(
        "malformed",
        "<scene version=\"3.0.0\">\n<shape type=\"sphere\">\n</scene>",
    )
    .unwrap_err();
    assert!(
        e.contains("malformed.xml:") && e.contains("malformed XML"),
        "{e}"
    );
    let e = import("plugin", &scene(r#"<shape type="teapot"/>"#)).unwrap_err();
    assert!(
        e.contains("plugin.xml:2:") && e.contains("teapot") && e.contains("supported shapes"),
        "{e}"
    );
    let e = import(
        "ref",
        &scene(r#"<shape type="sphere"><ref id="nope"/></shape>"#),
    )
    .unwrap_err();
    assert!(e.contains("ref.xml:2:") && e.contains("nope"), "{e}");
    let e = import(
        "prop",
        &scene(r#"<shape type="sphere"><float name="wobble" value="1"/></shape>"#),
    )
    .unwrap_err();
    assert!(e.contains("prop.xml:2:") && e.contains("`wobble`"), "{e}");
    let d = dir("cycle");
    std::fs::write(d.join("a.xml"), scene(r#"<include filename="b.xml"/>"#)).unwrap();
    std::fs::write(d.join("b.xml"), scene(r#"<include filename="a.xml"/>"#)).unwrap();
    let e = rtis::import::import(&d.join("a.xml"), &d)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("b.xml:2:") && e.contains("include cycle"), "{e}");
}

/// Two renders of `spp` of the imported Mitsuba scene `xml` (in tests/data/import) against
/// Mitsuba's image `reference` of noise `noise` (bench/mitsuba_import_reference.py, Mitsuba's
/// orientation): block MSE within 1.5 times what noise explains, and the mean within 1% of
/// Mitsuba's `mean`.
fn matches_mitsuba(xml: &str, spp: u32, reference: &str, noise: f64, mean: [f32; 3]) {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let mut s =
        rtis::import::load_scene(&data.join("import").join(xml)).unwrap_or_else(|e| panic!("{e}"));
    s.settings.film.spp = spp;
    let a = common::render_scene(&s);
    s.settings.seed = 4321;
    let b = common::render_scene(&s);
    let r = rtis::render::output::load(&data.join(reference)).unwrap();
    let (mse, explained) = common::block_mse(&a.image, &b.image, &r, noise, &|_, _| false);
    let m = (a.image.mean() + b.image.mean()) * 0.5;
    eprintln!("{xml}: block MSE vs Mitsuba {mse:.3e}; noise explains {explained:.3e}; mean {m}");
    assert!(
        mse < 1.5 * explained,
        "{xml}: block MSE {mse:.3e} vs {explained:.3e}"
    );
    let want = glam::Vec3A::from_array(mean);
    assert!(
        ((m - want) / want).abs().max_element() < 0.01,
        "{xml}: mean {m} vs {want}"
    );
}

/// A Cornell box written in Mitsuba's XML (rectangles placed by transforms, a cube, a glass
/// sphere, a rectangle light, declared BSDFs, defaults), rendered by Mitsuba from the file and
/// by rtis from its import: the same image.
#[test]
fn imported_cornell_box_matches_mitsuba() {
    matches_mitsuba(
        "cbox.xml",
        64,
        "mitsuba_import_cbox_96x96_spp4096.exr",
        0.008883,
        [0.298009, 0.245842, 0.137712],
    );
}

/// Meshes: a binary little-endian PLY torus with normals and texture coordinates (a
/// checkerboard), a big-endian PLY strip without normals (smooth normals computed as
/// Mitsuba's), a transformed OBJ pyramid, and both meshes of a serialized file (by
/// `shape_index`), under a sky and a sun: the same image.
#[test]
fn imported_meshes_match_mitsuba() {
    matches_mitsuba(
        "meshes.xml",
        64,
        "mitsuba_import_meshes_128x96_spp4096.exr",
        0.002765,
        [0.413711, 0.389392, 0.396722],
    );
}

/// One of each remaining kind: a thin lens (in an included file), an envmap turned by its
/// to_world, a point light given as a spectrum, a spot light, a conductor, a rough dielectric,
/// a plastic, a rough plastic on a bitmap, and a normal-mapped panel seen from its back: the
/// same image.
#[test]
fn imported_kinds_match_mitsuba() {
    matches_mitsuba(
        "kinds.xml",
        64,
        "mitsuba_import_kinds_128x96_spp4096.exr",
        0.006118,
        [0.195765, 0.20019, 0.213298],
    );
}

/// Veach's multiple importance sampling scene (four plates of growing roughness reflecting four
/// lights of equal power and growing size, written in Mitsuba's XML): the same image. Its
/// small bright lights make both renderers' pixels noisy (Mitsuba's reference has a noise RMSE
/// of 0.13 per pixel at 4096 spp), so rtis renders 1024 spp here.
#[test]
fn imported_veach_mis_matches_mitsuba() {
    matches_mitsuba(
        "veach_mis.xml",
        1024,
        "mitsuba_import_veach_mis_128x96_spp4096.exr",
        0.129406,
        [0.204953, 0.204953, 0.204953],
    );
}

mod fuzz {
    use crate::scene_fuzz::{Mutation, apply, cases, mutation};
    use proptest::prelude::*;
    use std::panic::{AssertUnwindSafe, catch_unwind};
    use std::path::Path;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(cases(600)))]

        /// Mutated Mitsuba scenes (bytes flipped, cut short, numbers swapped or replaced by
        /// extreme ones, brackets deleted, lines duplicated or deleted, punctuation inserted)
        /// import to a scene or fail with a located message, and never panic.
        #[test]
        fn mutated_xml_imports_or_fails_located(
            mutations in proptest::collection::vec(mutation(), 1..4),
        ) {
            let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/import/cbox.xml");
            let mut bytes = std::fs::read(&source).unwrap();
            for m in &mutations {
                apply(&mut bytes, m);
            }
            let d = super::dir(&format!("fuzz-{:?}", std::thread::current().id()).replace(|c: char| !c.is_ascii_alphanumeric(), ""));
            let path = d.join("cbox.xml");
            std::fs::write(&path, &bytes).unwrap();
            let shown = String::from_utf8_lossy(&bytes).into_owned();
            let result = catch_unwind(AssertUnwindSafe(|| rtis::import::load_scene(&path)));
            let result = result.map_err(|p| {
                let why = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                TestCaseError::fail(format!("import panicked ({why}) after {mutations:?}:\n{shown}"))
            })?;
            if let Err(e) = result {
                let located = e.at.is_some() || e.message.starts_with("cannot read");
                prop_assert!(located, "not located: {e} after {:?}", mutations as Vec<Mutation>);
            }
        }
    }
}

/// `rtis import -o` writes a scene file that `rtis check` reads, and what check prints reads
/// back as the same scene; the written file loads as the XML does (the same render, bit for
/// bit, at a few samples).
#[test]
fn import_writes_a_scene_that_reads_back() {
    let bin = env!("CARGO_BIN_EXE_rtis");
    let d = dir("roundtrip");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/import");
    for xml in ["cbox.xml", "meshes.xml", "kinds.xml"] {
        let ron = d.join(xml.replace(".xml", ".ron"));
        let out = std::process::Command::new(bin)
            .args([
                "import",
                src.join(xml).to_str().unwrap(),
                "-o",
                ron.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let check = |path: &Path| {
            let out = std::process::Command::new(bin)
                .args(["check", path.to_str().unwrap()])
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            String::from_utf8_lossy(&out.stdout)
                .lines()
                .filter(|l| !l.starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        let first = check(&ron);
        let again = d.join(xml.replace(".xml", "-checked.ron"));
        std::fs::write(&again, &first).unwrap();
        assert_eq!(first, check(&again), "{xml}");
        // The file and the XML render the same bits.
        let mut a = rtis::import::load_scene(&src.join(xml)).unwrap();
        let mut b = rtis::scene::load_path(&ron).unwrap();
        for s in [&mut a, &mut b] {
            s.settings.film.spp = 2;
        }
        assert_eq!(
            common::bits(&common::render_scene(&a).image),
            common::bits(&common::render_scene(&b).image),
            "{xml}"
        );
    }
}

/// A mesh file that is missing, cut short, or whose face refers beyond its vertices, is an
/// error located at the converted scene's mesh path that names the file's problem.
#[test]
fn bad_meshes_are_located() {
    let d = dir("badmesh");
    std::fs::write(
        d.join("bad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
    )
    .unwrap();
    std::fs::write(
        d.join("cut.ply"),
        b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\0\0\0\0",
    )
    .unwrap();
    for (file, why) in [
        ("missing.obj", "cannot read"),
        ("bad.ply", "vertex 7"),
        ("cut.ply", "truncated"),
    ] {
        let xml = d.join(format!("{file}.xml"));
        std::fs::write(
            &xml,
            scene(&format!(
                r#"<shape type="{}"><string name="filename" value="{file}"/></shape>"#,
                if file.ends_with("ply") { "ply" } else { "obj" }
            )),
        )
        .unwrap();
        let e = rtis::import::load_scene(&xml).err().unwrap().to_string();
        assert!(
            e.contains(file) && e.contains(why) && e.contains(":"),
            "{e}"
        );
        // A broken file the converter cannot see is reported in the converted text, which the
        // message says how to print.
        if file == "cut.ply" {
            assert!(
                e.contains("(as imported)") && e.contains("rtis import"),
                "{e}"
            );
        }
    }
}

/// A disk light imported as a fan of triangles: a point at distance 1 below the centre of a
/// disk of radius 0.5 and radiance 2, on a white floor, receives `E = pi L r^2 / (h^2 + r^2)`
/// and sends back `E / pi = 0.4`, within 5 standard errors and the fan's 1e-4.
#[test]
fn an_imported_disk_light_lights_as_a_disk() {
    let d = dir("disk");
    let xml = d.join("disk.xml");
    std::fs::write(
        &xml,
        scene(
            r#"<integrator type="direct"/>
               <sensor type="perspective">
                 <float name="fov" value="0.01"/>
                 <transform name="to_world"><lookat origin="0, 0.5, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
                 <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
                 <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
               </sensor>
               <shape type="rectangle">
                 <transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
                 <bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf>
               </shape>
               <shape type="disk">
                 <transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="1"/></transform>
                 <emitter type="area"><rgb name="radiance" value="2"/></emitter>
               </shape>"#,
        ),
    )
    .unwrap();
    let s = rtis::import::load_scene(&xml).unwrap_or_else(|e| panic!("{e}"));
    let (mean, se) = common::mean_and_se(&common::render_scene(&s));
    let want = 2.0 * 0.25 / (1.0 + 0.25);
    assert!(
        (mean - want).abs() < 5.0 * se + 1e-3,
        "{mean} +- {se} vs {want}"
    );
}

/// A scene of version 0.6 is upgraded as Mitsuba 3 upgrades it: camelCase names become
/// snake_case (`sampleCount`, `maxDepth`, `intIOR`, `fovAxis`), a diffuse BSDF's
/// `diffuseReflectance` its `reflectance`, `uscale`/`voffset` a `to_uv`, `<lookAt>` a
/// `<lookat>`: the same rtis scene as the 3.0 file written with the new names.
#[test]
fn version_0_6_is_upgraded() {
    let old = r#"<scene version="0.6.0">
        <integrator type="path"><integer name="maxDepth" value="4"/></integrator>
        <sensor type="perspective">
          <float name="fov" value="40"/><string name="fovAxis" value="y"/>
          <transform name="toWorld"><lookAt origin="0, 1, -3" target="0, 0, 0" up="0, 1, 0"/></transform>
          <sampler type="independent"><integer name="sampleCount" value="8"/></sampler>
        </sensor>
        <shape type="sphere"><bsdf type="dielectric"><float name="intIOR" value="1.33"/></bsdf></shape>
        <shape type="sphere"><bsdf type="diffuse">
          <texture type="checkerboard" name="diffuseReflectance">
            <float name="uscale" value="4"/><float name="voffset" value="0.5"/>
          </texture></bsdf></shape>
      </scene>"#;
    let new = r#"<scene version="3.0.0">
        <integrator type="path"><integer name="max_depth" value="4"/></integrator>
        <sensor type="perspective">
          <float name="fov" value="40"/><string name="fov_axis" value="y"/>
          <transform name="to_world"><lookat origin="0, 1, -3" target="0, 0, 0" up="0, 1, 0"/></transform>
          <sampler type="independent"><integer name="sample_count" value="8"/></sampler>
        </sensor>
        <shape type="sphere"><bsdf type="dielectric"><float name="int_ior" value="1.33"/></bsdf></shape>
        <shape type="sphere"><bsdf type="diffuse">
          <texture type="checkerboard" name="reflectance">
            <transform name="to_uv"><translate y="0.5"/><scale x="4"/></transform>
          </texture></bsdf></shape>
      </scene>"#;
    let body = |t: String| t.lines().skip(1).collect::<Vec<_>>().join("\n");
    let (a, b) = (import("old", old).unwrap(), import("new", new).unwrap());
    assert!(a.contains("uv_transform: (scale: (4.0, 1.0)"), "{a}");
    assert_eq!(body(a), body(b));
}

/// `--lenient` skips what rtis cannot render, with a warning naming each place: an unknown
/// shape, an unknown property, a BSDF rtis lacks (declared: its shapes keep Mitsuba's default
/// diffuse); strict import stops at the first.
#[test]
fn lenient_import_skips_with_warnings() {
    let xml = scene(
        r#"<bsdf type="hair" id="h"/>
           <shape type="teapot"/>
           <shape type="sphere"><float name="wobble" value="1"/><ref id="h"/></shape>"#,
    );
    let d = dir("lenient");
    let path = d.join("lenient.xml");
    std::fs::write(&path, &xml).unwrap();
    assert!(rtis::import::import(&path, &d).is_err());
    let c = rtis::import::import_with(&path, &d, true).unwrap();
    let w = c.warnings.join("\n");
    for want in [
        "lenient.xml:2:",
        "hair",
        "lenient.xml:3:",
        "teapot",
        "lenient.xml:4:",
        "wobble",
    ] {
        assert!(w.contains(want), "{want} not in\n{w}");
    }
    assert!(
        c.text.contains(r#""h": Phong(kd: (0.5, 0.5, 0.5)"#),
        "{}",
        c.text
    );
    assert!(c.text.contains(r#"material: Named("h")"#), "{}", c.text);
    rtis::scene::load_str(&c.text, "lenient.ron", Some(&d)).unwrap_or_else(|e| panic!("{e}"));
}

/// Shapes and textures field by field: a rectangle by a composed transform (scale, then
/// rotate, then translate, Mitsuba's order), a `matrix` step, a sphere's uniform scale, a
/// mesh's transform as rtis's scale, rotation and translation with `flip_normals` and
/// `face_normals`, a bitmap's filter, wrap, raw and `to_uv`; and what rtis refuses in them
/// (a sphere scaled unevenly, a sheared mesh, a mirrored `to_uv`).
#[test]
fn shapes_and_textures_convert_field_by_field() {
    for d in ["shapes", "refused"] {
        std::fs::write(dir(d).join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    }
    let text = import(
        "shapes",
        &scene(
            r#"<shape type="rectangle" id="r">
                 <transform name="to_world"><scale x="2" y="3"/><rotate z="1" angle="90"/><translate x="1"/></transform>
               </shape>
               <shape type="sphere" id="s">
                 <transform name="to_world"><matrix value="2 0 0 1  0 2 0 2  0 0 2 3  0 0 0 1"/></transform>
               </shape>
               <shape type="obj" id="m">
                 <string name="filename" value="m.obj"/>
                 <boolean name="flip_normals" value="true"/>
                 <boolean name="face_normals" value="true"/>
                 <transform name="to_world"><scale value="2"/><rotate y="1" angle="30"/><translate z="4"/></transform>
                 <bsdf type="diffuse">
                   <texture type="bitmap" name="reflectance">
                     <string name="filename" value="wood.png"/>
                     <string name="filter_type" value="nearest"/>
                     <string name="wrap_mode" value="mirror"/>
                     <boolean name="raw" value="true"/>
                     <transform name="to_uv"><scale x="2" y="4"/><translate x="0.5"/></transform>
                   </texture>
                 </bsdf>
               </shape>"#,
        ),
    )
    .unwrap();
    for want in [
        // Corner (-1, -1) scaled to (-2, -3), turned to (3, -2), moved to (4, -2).
        r#"(name: "r", shape: Rectangle(corner: (4.0, -2.0, 0.0), u: (0.0, 4.0, 0.0), v: (-6.0, 0.0, 0.0))"#,
        r#"(name: "s", shape: Sphere(center: (1.0, 2.0, 3.0), radius: 2.0)"#,
        r#"(name: "m", shape: Mesh(path: "m.obj", normals: Faces, flip_normals: true), transform: (scale: (2.0, 2.0, 2.0), rotate: (0.0, 30.0, 0.0), translate: (0.0, 0.0, 4.0))"#,
        r#"Image(path: "wood.png", filter: Nearest, wrap: Mirror, raw: true, uv_transform: (scale: (2.0, 4.0), rotate: 0.0, offset: (0.5, 0.0)))"#,
    ] {
        assert!(text.contains(want), "{want}\nnot in\n{text}");
    }
    for (body, why) in [
        (
            r#"<shape type="sphere"><transform name="to_world"><scale x="1" y="2"/></transform></shape>"#,
            "rtis's spheres are round",
        ),
        (
            r#"<shape type="obj"><string name="filename" value="m.obj"/><transform name="to_world"><matrix value="1 1 0 0  0 1 0 0  0 0 1 0  0 0 0 1"/></transform></shape>"#,
            "shears the mesh",
        ),
        (
            r#"<shape type="sphere"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance"><transform name="to_uv"><scale x="-1"/></transform></texture></bsdf></shape>"#,
            "shears or mirrors",
        ),
    ] {
        let e = import("refused", &scene(body)).unwrap_err();
        assert!(e.contains("refused.xml:2:") && e.contains(why), "{e}");
    }
}

/// `flip_normals` on a mesh emitter turns the side it emits from: a one-sided square light
/// facing up lights nothing below it until flipped.
#[test]
fn a_flipped_mesh_light_emits_from_its_other_side() {
    let d = dir("flip");
    std::fs::write(
        d.join("quad.obj"),
        "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 4 3 2\n",
    )
    .unwrap();
    let lit = |flip: bool| {
        let xml = d.join(format!("flip{flip}.xml"));
        std::fs::write(
            &xml,
            scene(&format!(
                r#"<integrator type="direct"/>
                   <sensor type="perspective">
                     <float name="fov" value="0.01"/>
                     <transform name="to_world"><lookat origin="0, 0.5, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
                     <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
                     <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film>
                   </sensor>
                   <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform></shape>
                   <shape type="obj">
                     <string name="filename" value="quad.obj"/>
                     <boolean name="flip_normals" value="{flip}"/>
                     <transform name="to_world"><translate y="1"/></transform>
                     <emitter type="area"><rgb name="radiance" value="1"/></emitter>
                   </shape>"#
            )),
        )
        .unwrap();
        let s = rtis::import::load_scene(&xml).unwrap_or_else(|e| panic!("{e}"));
        common::mean_and_se(&common::render_scene(&s)).0
    };
    // The quad's faces (1, 4, 3, 2) wind to face +y: away from the floor.
    assert_eq!(lit(false), 0.0);
    assert!(lit(true) > 0.05, "{}", lit(true));
}

/// What a review found: deep nesting is a located error (not a stack overflow); an inline BSDF
/// with an id converts inline; an unnamed texture in a BSDF, a BSDF in a point light and a
/// twosided's own property are refused, not dropped; a conductor's `eta` needs its `k`;
/// includes resolve from the including file's folder; without `fov` the field of view is
/// Mitsuba's 50 mm lens (46.8 degrees across the diagonal: 29.1 vertically at 4:3).
#[test]
fn review_cases() {
    let deep = format!(
        "{}{}{}",
        "<bsdf type=\"twosided\">".repeat(100),
        "<bsdf type=\"diffuse\"/>",
        "</bsdf>".repeat(100)
    );
    let e = import(
        "deep",
        &scene(&format!("<shape type=\"sphere\">{deep}</shape>")),
    )
    .unwrap_err();
    assert!(
        e.contains("deep.xml:") && e.contains("nested more than"),
        "{e}"
    );
    let text = import(
        "inline",
        &scene(r#"<shape type="sphere"><bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.7, 0.1, 0.1"/></bsdf></shape>"#),
    )
    .unwrap();
    assert!(
        text.contains("material: Phong(kd: (0.7, 0.1, 0.1)"),
        "{text}"
    );
    for (body, why) in [
        (
            r#"<shape type="sphere"><bsdf type="diffuse"><texture type="checkerboard"/></bsdf></shape>"#,
            "without a name",
        ),
        (
            r#"<emitter type="point"><bsdf type="diffuse"/></emitter>"#,
            "without a name",
        ),
        (
            r#"<shape type="sphere"><bsdf type="twosided"><rgb name="reflectance" value="1"/><bsdf type="diffuse"/></bsdf></shape>"#,
            "`reflectance`",
        ),
        (
            r#"<shape type="sphere"><bsdf type="conductor"><rgb name="eta" value="1"/></bsdf></shape>"#,
            "go together",
        ),
    ] {
        let e = import("refused2", &scene(body)).unwrap_err();
        assert!(
            e.contains("refused2.xml:2:") && e.contains(why),
            "{why}: {e}"
        );
    }
    let d = dir("nested-include");
    std::fs::create_dir_all(d.join("sub")).unwrap();
    std::fs::write(
        d.join("top.xml"),
        scene(r#"<include filename="sub/a.xml"/>"#),
    )
    .unwrap();
    std::fs::write(d.join("sub/a.xml"), scene(r#"<include filename="b.xml"/>"#)).unwrap();
    std::fs::write(d.join("sub/b.xml"), scene(r#"<emitter type="constant"/>"#)).unwrap();
    let c = rtis::import::import(&d.join("top.xml"), &d).unwrap_or_else(|e| panic!("{e}"));
    assert!(c.text.contains("Environment(radiance"), "{}", c.text);
    let text = import(
        "lens",
        &scene(r#"<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="400"/><integer name="height" value="300"/></film></sensor>"#),
    )
    .unwrap();
    let diag = (43.266615305567875f64 / 100.0).atan();
    let want = 2.0
        * (diag.tan() / (1.0f64 + (4.0f64 / 3.0).powi(2)).sqrt())
            .atan()
            .to_degrees();
    assert!(
        text.contains(&format!("fov: {}", num(want))),
        "{want} in {text}"
    );
    assert!((want - 29.11).abs() < 0.01, "{want}");
}
