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
];

#[test]
fn every_invalid_input_has_its_located_message() {
    let mut report = String::new();
    for (label, text) in CASES {
        let e = error_of(text);
        if !label.contains("missing base") {
            assert!(e.at.is_some(), "{label}: no line and column in {e}");
        }
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
