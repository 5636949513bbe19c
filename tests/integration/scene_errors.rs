//! Each invalid input gives its specific, located message. The messages are snapshotted so a
//! change in wording shows up in review.

use rtis::scene::{SceneError, load_path, load_str};
use std::path::Path;

fn error_of(text: &str) -> SceneError {
    // Tests run in the package root: relative paths keep the messages machine-independent.
    match load_str(text, "bad.ron", Some(Path::new(""))) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

const CASES: &[(&str, &str)] = &[
    ("malformed RON", "Scene(film: (width: 10,, height: 10))"),
    ("unknown field", "Scene(film: (width: 10, hieght: 10))"),
    ("unknown top-level field", "Scene(lights: [])"),
    (
        "unknown shape",
        "Scene(entities: [(shape: Cube(size: 1), material: Mirror())])",
    ),
    (
        "unknown material name",
        "Scene(\n  materials: { \"red\": Phong(kd: (1, 0, 0)), \"blue\": Phong(kd: (0, 0, 1)) },\n  entities: [\n    (shape: Sphere(center: (0, 0, 5), radius: 1), material: Named(\"green\")),\n  ],\n)",
    ),
    (
        "non-finite number",
        "Scene(entities: [(shape: Sphere(center: (0, inf, 5), radius: 1), material: Mirror())])",
    ),
    ("NaN", "Scene(background: (NaN, 0, 0))"),
    (
        "unknown metal",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Conductor(material: \"Gold\"))])",
    ),
    (
        "conductor with a metal and eta",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Conductor(material: \"Au\", eta: (1, 1, 1), k: (2, 2, 2)))])",
    ),
    (
        "conductor with eta alone",
        "Scene(materials: { \"metal\": Conductor(eta: (1, 1, 1)) }, entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Named(\"metal\"))])",
    ),
    (
        "conductor eta negative",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Conductor(eta: (-1, 1, 1), k: (1, 1, 1)))])",
    ),
    (
        "camera looking straight down with the default up",
        "Scene(camera: Orthographic(position: (0, 5, 0), look_at: (0, 0, 0), height: 2))",
    ),
    (
        "roughness below its range",
        "Scene(model: Physical, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: RoughConductor(alpha: 1e-5))])",
    ),
    (
        "roughness above its range",
        "Scene(model: Physical, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: RoughDielectric(alpha_u: 0.1, alpha_v: 1.5))])",
    ),
    (
        "alpha with alpha_u",
        "Scene(model: Physical, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: RoughConductor(alpha: 0.1, alpha_u: 0.2, alpha_v: 0.3))])",
    ),
    (
        "alpha_u alone",
        "Scene(model: Physical, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: RoughDielectric(alpha_u: 0.2))])",
    ),
    (
        "unknown distribution",
        "Scene(model: Physical, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: RoughPlastic(distribution: Phong))])",
    ),
    (
        "equal indices",
        "Scene(model: Physical, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Plastic(int_ior: 1.3, ext_ior: 1.3))])",
    ),
    (
        "rough material under Global",
        "Scene(model: Physical, shader: Global(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: RoughPlastic())])",
    ),
    (
        "rough material under the Course model",
        "Scene(materials: { \"frosted\": RoughDielectric() }, shader: Path(), entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Named(\"frosted\"))])",
    ),
    // Finite as doubles, beyond what single-precision render data holds.
    (
        "shininess beyond f32",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Phong(kd: (0.5, 0.5, 0.5), ks: (0.5, 0.5, 0.5), shininess: 3.4e38))])",
    ),
    (
        "kd beyond f32",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Phong(kd: (3.4e38, 0.5, 0.5)))])",
    ),
    (
        "reflectance above one",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Mirror(color: (1.5, 1, 1)))])",
    ),
    (
        "intensity beyond f32",
        "Scene(entities: [(light: Point(position: (0, 2, 0), intensity: (3.4e38, 1, 1)))])",
    ),
    ("background beyond range", "Scene(background: (1e31, 0, 0))"),
    (
        "coordinate beyond range",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 1e12), radius: 1), material: Mirror())])",
    ),
    (
        "radius beyond range",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1e10), material: Mirror())])",
    ),
    (
        "scale beyond range",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Mirror(), transform: (scale: (1e7, 1e7, 1e7)))])",
    ),
    (
        "ior beyond range",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Transmissive(ior: 1000))])",
    ),
    (
        "radius zero",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 0), material: Mirror())])",
    ),
    (
        "radius negative",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: -2), material: Mirror())])",
    ),
    (
        "zero-length normal",
        "Scene(entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 0, 0)), material: Mirror())])",
    ),
    (
        "zero-length up",
        "Scene(camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), up: (0, 0, 0)))",
    ),
    (
        "look_at equals position",
        "Scene(camera: Perspective(position: (1, 2, 3), look_at: (1, 2, 3)))",
    ),
    (
        "up parallel to view",
        "Scene(camera: Perspective(position: (0, 0, 0), look_at: (0, 5, 0), up: (0, 1, 0)))",
    ),
    (
        "fov 0",
        "Scene(camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), fov: 0))",
    ),
    (
        "fov 180",
        "Scene(camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), fov: 180))",
    ),
    (
        "orthographic height 0",
        "Scene(camera: Orthographic(position: (0, 0, 0), look_at: (0, 0, 1), height: 0))",
    ),
    ("zero film width", "Scene(film: (width: 0, height: 10))"),
    (
        "absurd film size",
        "Scene(film: (width: 30000, height: 30000))",
    ),
    (
        "film side too large",
        "Scene(film: (width: 100000, height: 1))",
    ),
    ("samples 0", "Scene(film: (spp: 0))"),
    ("global samples 0", "Scene(shader: Global(samples: 0))"),
    (
        "ior zero",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Transmissive(ior: 0))])",
    ),
    (
        "ior negative",
        "Scene(materials: { \"glass\": Transmissive(ior: -1.5) })",
    ),
    (
        "negative colour",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Phong(kd: (0.5, -0.1, 0)))])",
    ),
    (
        "negative intensity",
        "Scene(entities: [(light: Point(position: (0, 2, 0), intensity: (7, -7, 7)))])",
    ),
    (
        "shape without material",
        "Scene(entities: [(name: \"ball\", shape: Sphere(center: (0, 0, 5), radius: 1))])",
    ),
    (
        "material without shape",
        "Scene(entities: [(material: Mirror())])",
    ),
    ("empty entity", "Scene(entities: [()])"),
    (
        "mesh index out of range",
        "Scene(entities: [(shape: TriangleMesh(vertices: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], faces: [(0, 1, 3)]), material: Mirror())])",
    ),
    (
        "named material in table",
        "Scene(materials: { \"a\": Named(\"b\") })",
    ),
    ("missing base scene", "Scene(extends: \"no-such-file.ron\")"),
    (
        "negative shininess",
        "Scene(materials: { \"p\": Phong(kd: (1, 1, 1), shininess: -3) })",
    ),
    (
        "global depth too large",
        "Scene(shader: Global(max_depth: 17))",
    ),
    (
        "non-uniform sphere scale",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Mirror(), transform: (scale: (1, 2, 1)))])",
    ),
    (
        "zero scale",
        "Scene(entities: [(shape: Triangle(a: (0, 0, 0), b: (1, 0, 0), c: (0, 1, 0)), material: Mirror(), transform: (scale: (1, 0, 1)))])",
    ),
    (
        "normals count",
        "Scene(entities: [(shape: TriangleMesh(vertices: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], faces: [(0, 1, 2)], normals: [(0, 0, 1)]), material: Mirror())])",
    ),
    (
        "missing mesh file",
        "Scene(entities: [(shape: Mesh(path: \"tests/data/no-such-mesh.obj\"), material: Mirror())])",
    ),
    (
        "malformed mesh file",
        "Scene(entities: [(shape: Mesh(path: \"tests/data/malformed.obj\"), material: Mirror())])",
    ),
    (
        "mesh path is a folder",
        "Scene(entities: [(shape: Mesh(path: \"scenes\"), material: Mirror())])",
    ),
    ("base scene is a folder", "Scene(extends: \"scenes\")"),
    // Parser messages that say what was meant, not what the parser wanted next.
    (
        "fractional film width",
        "Scene(film: (width: 100.5, height: 10))",
    ),
    ("negative film width", "Scene(film: (width: -5))"),
    ("fractional seed", "Scene(seed: 1.5)"),
    (
        "fractional face index",
        "Scene(entities: [(shape: TriangleMesh(vertices: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], faces: [(0, 1.5, 2)]), material: Mirror())])",
    ),
    ("unit shader with parentheses", "Scene(shader: Normal())"),
    ("model with parentheses", "Scene(model: Physical())"),
    ("struct shader without parentheses", "Scene(shader: Direct)"),
    (
        "material without parentheses",
        "Scene(materials: { \"m\": Mirror })",
    ),
    ("misspelt shader", "Scene(shader: Normals)"),
    ("lower-case model", "Scene(model: physical)"),
    ("misspelt shader field", "Scene(shader: Global(sample: 16))"),
    (
        "emitter without a shape",
        "Scene(entities: [(name: \"glow\", emitter: Emitter(radiance: (1, 1, 1)))])",
    ),
    (
        "emitting infinite plane",
        "Scene(entities: [(shape: InfinitePlane(point: (0, 3, 0), normal: (0, -1, 0)), emitter: Emitter(radiance: (1, 1, 1)))])",
    ),
    (
        "rectangle with parallel edges",
        "Scene(entities: [(shape: Rectangle(corner: (0, 0, 5), u: (1, 0, 0), v: (2, 0, 0)), material: Mirror())])",
    ),
    (
        "negative radiance",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), emitter: Emitter(radiance: (1, -1, 1)))])",
    ),
    (
        "unknown emitter field",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), emitter: Emitter(radiance: (1, 1, 1), twosided: true))])",
    ),
    (
        "unknown light strategy",
        "Scene(shader: Path(lights: Both))",
    ),
    (
        "zero light samples",
        "Scene(shader: Direct(light_samples: 0))",
    ),
    ("lights at the top level", "Scene(lights: [])"),
    (
        "missing required field",
        "Scene(materials: { \"m\": Phong(ks: (1, 1, 1)) })",
    ),
    (
        "missing camera field",
        "Scene(camera: Perspective(position: (0, 0, 0)))",
    ),
    (
        "colour as one number",
        "Scene(materials: { \"m\": Phong(kd: 0.5) })",
    ),
    (
        "colour with two channels",
        "Scene(materials: { \"m\": Phong(kd: (0.5, 0.5)) })",
    ),
    (
        "colour with four channels",
        "Scene(background: (0, 0, 0, 1))",
    ),
    ("colour as a list", "Scene(background: [0, 0, 0])"),
    (
        "material as a string",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: \"red\")])",
    ),
    (
        "Named without quotes",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1), material: Named(red))])",
    ),
    (
        "variant name in quotes",
        "Scene(shader: Path(sampling: \"Cosine\"))",
    ),
    (
        "camera without its kind",
        "Scene(camera: (position: (0, 0, 0), look_at: (0, 0, 1)))",
    ),
    ("materials as a list", "Scene(materials: [Mirror()])"),
    ("boolean as a word", "Scene(effects: (shadows: no))"),
    (
        "missing comma",
        "Scene(entities: [(shape: Sphere(center: (0, 0, 5), radius: 1) material: Mirror())])",
    ),
    (
        "file ends early",
        "Scene(\n  entities: [\n    (shape: Sphere(center: (0, 0, 5), radius: 1), material: Mirror()),\n",
    ),
    ("one bracket too many", "Scene(background: (0, 0, 0)))"),
    ("field written twice", "Scene(film: (width: 10, width: 20))"),
    ("not a scene", "Film(width: 10)"),
    ("unclosed comment", "Scene(seed: 1, /* a comment\n)"),
    ("unclosed string", "Scene(extends: \"cornell.ron)"),
    // Accepted silently before: now located errors.
    (
        "duplicate material",
        "Scene(\n  materials: {\n    \"red\": Mirror(),\n    \"red\": Phong(kd: (1, 0, 0)),\n  },\n)",
    ),
    (
        "duplicate entity name",
        "Scene(entities: [\n  (name: \"ball\", shape: Sphere(center: (0, 0, 5), radius: 1), material: Mirror()),\n  (name: \"ball\", shape: Sphere(center: (2, 0, 5), radius: 1), material: Mirror()),\n])",
    ),
    (
        "transform on a light",
        "Scene(entities: [(name: \"lamp\", light: Point(position: (0, 2, 0), intensity: (7, 7, 7)), transform: (translate: (1, 0, 0)))])",
    ),
    (
        "aperture negative",
        "Scene(camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), aperture_radius: -0.1))",
    ),
    (
        "spot beam wider than cutoff",
        "Scene(entities: [(light: Spot(position: (0, 2, 0), direction: (0, -1, 0), intensity: (1, 1, 1),\n  cutoff_angle: 20, beam_width: 30))])",
    ),
    (
        "spot cutoff beyond 90",
        "Scene(entities: [(light: Spot(position: (0, 2, 0), direction: (0, -1, 0), intensity: (1, 1, 1), cutoff_angle: 120))])",
    ),
    (
        "spot zero direction",
        "Scene(entities: [(light: Spot(position: (0, 2, 0), direction: (0, 0, 0), intensity: (1, 1, 1)))])",
    ),
    (
        "sun without a direction",
        "Scene(entities: [(light: Directional(direction: (0, 0, 0), irradiance: (1, 1, 1)))])",
    ),
    (
        "empty triangle mesh",
        "Scene(entities: [(shape: TriangleMesh(vertices: [], faces: []), material: Mirror())])",
    ),
];

#[test]
fn every_invalid_input_has_its_located_message() {
    let mut report = String::new();
    for (label, text) in CASES {
        let e = error_of(text);
        assert!(e.at.is_some(), "{label}: no line and column in {e}");
        report.push_str(&format!("## {label}\n{e}\n\n"));
    }
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path(Path::new(env!("CARGO_MANIFEST_DIR")).join("snapshots"));
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| insta::assert_snapshot!("scene_errors", report));
}

#[test]
fn unknown_material_lists_the_known_ones_with_its_position() {
    let e = error_of(CASES[4].1);
    assert_eq!(e.at, Some((4, 67)));
    assert!(
        e.message.contains("\"green\"") && e.message.contains("\"blue\", \"red\""),
        "{e}"
    );
}

#[test]
fn extends_cycle_and_missing_file_are_reported() {
    let dir = std::env::temp_dir().join(format!("rtis-cycle-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("a.ron"), "Scene(extends: \"b.ron\")").unwrap();
    std::fs::write(dir.join("b.ron"), "Scene(\n  extends: \"a.ron\",\n)").unwrap();
    let e = load_path(&dir.join("a.ron")).err().expect("cycle");
    assert!(e.message.contains("cycle"), "{e}");
    assert!(e.file.ends_with("b.ron") && e.at == Some((2, 12)), "{e}");
    let e = load_path(&dir.join("missing.ron")).err().expect("missing");
    assert!(e.message.contains("cannot read scene file"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene may extend a base and override parts of it; entities and materials merge.
#[test]
fn extends_overrides_and_merges() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let s = load_str(
        "Scene(extends: \"cornell.ron\", shader: Direct(), film: (width: 10, height: 8),
           materials: { \"mirror\": Mirror(color: (0.5, 0.5, 0.5)) },
           entities: [(light: Point(position: (0, 0, 0), intensity: (1, 1, 1)))])",
        "child.ron",
        Some(&base),
    )
    .unwrap();
    assert_eq!(s.settings.film.width, 10);
    assert!(matches!(
        s.settings.shader,
        rtis::shader::Shader::Direct { .. }
    ));
    assert_eq!(s.world.len(), 12);
    let mirrors: Vec<_> = s
        .world
        .query::<&rtis::world::Material>()
        .iter()
        .filter_map(|m| match m {
            rtis::world::Material::Mirror(m) => Some(m.color),
            _ => None,
        })
        .collect();
    assert_eq!(mirrors, vec![glam::Vec3A::splat(0.5)]);
}

/// A multi-megabyte line with an error shows a window around the column, not the line.
#[test]
fn an_error_on_a_huge_line_shows_a_bounded_window() {
    let pad = " ".repeat(2 << 20);
    let text =
        format!("Scene({pad}seed: 1,{pad}film: (width: 100.5), background: (0, 0, 0),{pad})");
    assert!(text.len() > 4 << 20);
    let e = error_of(&text);
    let shown = e.to_string();
    assert!(shown.len() < 500, "{} bytes:\n{shown}", shown.len());
    let (_, col) = e.at.unwrap();
    assert_eq!(text.chars().nth(col - 1), Some('1'));
    // The caret line's `^` is under the character at the column.
    let lines: Vec<&str> = shown.lines().collect();
    let window = lines[2].strip_prefix("1 | ").unwrap();
    let caret = lines[3].strip_prefix("  | ").unwrap();
    assert_eq!(window.chars().nth(caret.chars().count() - 1), Some('1'));
    assert!(window.starts_with('…') && window.ends_with('…'), "{window}");
    assert!(window[window.find("width").unwrap()..].starts_with("width: 100.5)"));
    // A huge unknown name is clipped in the message too.
    let e = error_of(&format!("Scene({}: 1)", "x".repeat(4 << 20)));
    assert!(e.to_string().len() < 1500, "{}", e.to_string().len());
}

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("rtis-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Bytes that are not UTF-8 are reported at the line and column of the first one, in the file
/// loaded or in a base scene.
#[test]
fn invalid_utf8_is_located_at_its_first_bad_byte() {
    let dir = temp_dir("utf8");
    let mut bytes = b"Scene(\n  // caf\xC3\xA9\n  seed: 1, // \xFF\xFE here\n)".to_vec();
    std::fs::write(dir.join("bad.ron"), &bytes).unwrap();
    let e = load_path(&dir.join("bad.ron")).err().expect("not UTF-8");
    assert_eq!(e.at, Some((3, 15)), "{e}");
    assert!(
        e.message.contains("UTF-8") && e.message.contains("0xFF"),
        "{e}"
    );
    assert!(e.to_string().contains("\u{FFFD}"), "{e}");
    // In a base scene: located in the base.
    bytes.truncate(0);
    bytes.extend_from_slice(b"Scene(seed: 2, \x80)");
    std::fs::write(dir.join("base.ron"), &bytes).unwrap();
    std::fs::write(dir.join("child.ron"), "Scene(extends: \"base.ron\")").unwrap();
    let e = load_path(&dir.join("child.ron"))
        .err()
        .expect("base not UTF-8");
    assert!(e.file.ends_with("base.ron") && e.at == Some((1, 16)), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file may have at most MAX_EXTENDS bases, whether it is loaded from a path or as text; the
/// error is at the `extends` one too many.
#[test]
fn extends_chain_depth_boundary() {
    let dir = temp_dir("chain");
    let n = rtis::scene::MAX_EXTENDS;
    // f0 extends f1 ... extends f{n+1}; f{k} with k = n + 1 has no base.
    for k in 0..=n + 1 {
        let text = if k == n + 1 {
            "Scene(seed: 7)".to_string()
        } else {
            format!("Scene(\n  extends: \"f{}.ron\",\n)", k + 1)
        };
        std::fs::write(dir.join(format!("f{k}.ron")), text).unwrap();
    }
    // f1 has n bases: allowed, from a path and as text.
    let s = load_path(&dir.join("f1.ron")).unwrap();
    assert_eq!(s.settings.seed, 7);
    let text = std::fs::read_to_string(dir.join("f1.ron")).unwrap();
    assert!(load_str(&text, "f1.ron", Some(&dir)).is_ok());
    // f0 has n + 1: the error is at the extends of the file n levels down.
    let e = load_path(&dir.join("f0.ron")).err().expect("too deep");
    assert!(e.message.contains("more than 16 nested `extends`"), "{e}");
    assert!(
        e.file.ends_with(&format!("f{n}.ron")) && e.at == Some((2, 12)),
        "{e}"
    );
    let text = std::fs::read_to_string(dir.join("f0.ron")).unwrap();
    let e = load_str(&text, "f0.ron", Some(&dir))
        .err()
        .expect("too deep");
    assert!(e.file.ends_with(&format!("f{n}.ron")), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Duplicates are errors at the second occurrence that name the first's place.
#[test]
fn duplicates_point_at_the_second_and_name_the_first() {
    let e = error_of(
        "Scene(\n  materials: {\n    \"red\": Mirror(),\n    \"blue\": Mirror(),\n    \"red\": Phong(kd: (1, 0, 0)),\n  },\n)",
    );
    assert_eq!(e.at, Some((5, 5)), "{e}");
    assert!(e.message.contains("line 3, column 5"), "{e}");
    let e = error_of(
        "Scene(entities: [\n  (name: \"lamp\", light: Point(position: (0, 1, 0), intensity: (1, 1, 1))),\n  (name: \"lamp\", light: Point(position: (0, 2, 0), intensity: (1, 1, 1))),\n])",
    );
    assert_eq!(e.at, Some((3, 10)), "{e}");
    assert!(e.message.contains("line 2, column 10"), "{e}");
    // A raw string and an escaped one naming the same material are the same key.
    let e = error_of("Scene(materials: { \"a\\u{62}\": Mirror(), r#\"ab\"#: Mirror() })");
    assert_eq!(e.at, Some((1, 41)), "{e}");
}

/// A mesh file that cannot be read gives the system's reason at the path in the scene; the same
/// path written twice is located at the entity that failed.
#[test]
fn unreadable_mesh_gives_the_os_reason_at_its_path() {
    let e = error_of(
        "Scene(entities: [\n  (shape: Mesh(path: \"scenes/assets/blob.obj\"), material: Mirror()),\n  (shape: Mesh(path: \"scenes\"), material: Mirror()),\n])",
    );
    assert_eq!(e.at, Some((3, 22)), "{e}");
    assert!(e.message.contains("Is a directory"), "{e}");
    let e = error_of(
        "Scene(entities: [(shape: Mesh(path: \"tests/data/no-such-mesh.obj\"), material: Mirror())])",
    );
    assert!(e.message.contains("No such file or directory"), "{e}");
}

/// The warnings for scenes that render but cannot show what was meant, each located at the
/// entity to blame: shapes lit by nothing, and a point light inside a sphere. Neither fires
/// when the scene is lit (a light, an emitter, a sky, or Global's ambient term), nor for a
/// light outside the sphere or a shader that does not shade.
#[test]
fn silent_mistakes_are_warned_at_their_place() {
    let warnings = |text: &str| {
        load_str(text, "w.ron", Some(Path::new("")))
            .unwrap_or_else(|e| panic!("{e}"))
            .warnings
    };
    let dark = "Scene(shader: Path(), model: Physical, entities: [\n  (shape: Sphere(center: (0, 0, 5), radius: 1), material: Mirror()),\n])";
    let w = warnings(dark);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "w.ron:2:11: the scene has shapes but no light, no emitter and a black background"
        ),
        "{w:?}"
    );
    for lit in [
        dark.replace("entities: [", "background: (0.1, 0.1, 0.1), entities: ["),
        dark.replace(
            "])",
            "  (light: Point(position: (0, 3, 5), intensity: (1, 1, 1))),\n])",
        ),
        dark.replace(
            "radius: 1), material: Mirror())",
            "radius: 1), emitter: Emitter(radiance: (1, 1, 1)))",
        ),
        dark.replace(
            "shader: Path(), model: Physical",
            "shader: Global(ambient: (0.2, 0.2, 0.2))",
        ),
        dark.replace("shader: Path()", "shader: Depth(max_distance: 10)"),
    ] {
        assert!(warnings(&lit).is_empty(), "{lit}: {:?}", warnings(&lit));
    }
    // A sky or an emitter switched off lights nothing.
    for dark_again in [
        dark.replace(
            "entities: [",
            "background: (0.1, 0.1, 0.1), effects: (background: false), entities: [",
        ),
        dark.replace(
            "radius: 1), material: Mirror())",
            "radius: 1), emitter: Emitter(radiance: (1, 1, 1)))",
        )
        .replace("entities: [", "effects: (emission: false), entities: ["),
    ] {
        assert_eq!(warnings(&dark_again).len(), 1, "{dark_again}");
    }
    let inside = "Scene(entities: [\n  (shape: Sphere(center: (0, 0, 5), radius: 1), material: Mirror()),\n  (light: Point(position: (0, 0.5, 5), intensity: (1, 1, 1))),\n])";
    // Not where no shadow ray is traced.
    for quiet in ["effects: (shadows: false), ", "shader: Normal, "] {
        let text = inside.replace("Scene(", &format!("Scene({quiet}"));
        assert!(warnings(&text).is_empty(), "{text}: {:?}", warnings(&text));
    }
    let w = warnings(inside);
    assert_eq!(
        w,
        [
            "w.ron:3:11: this light is inside the sphere at w.ron:2:11: only the sphere's inside \
          sees it, and its shadow rays are wasted elsewhere"
        ],
    );
    assert!(warnings(&inside.replace("(0, 0.5, 5)", "(0, 1.5, 5)")).is_empty());
    // A spot inside the sphere too.
    let spot = inside.replace(
        "Point(position: (0, 0.5, 5),",
        "Spot(position: (0, 0.5, 5), direction: (0, 0, 1),",
    );
    assert_eq!(warnings(&spot).len(), 1, "{spot}");
}

/// The repository's scenes load without a warning.
#[test]
fn the_scenes_load_without_warnings() {
    for entry in std::fs::read_dir("scenes").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ron") {
            let scene = load_path(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(
                scene.warnings.is_empty(),
                "{}: {:?}",
                path.display(),
                scene.warnings
            );
        }
    }
}
