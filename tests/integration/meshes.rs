//! Meshes: OBJ loading, smooth shading, transforms, watertightness and the BVH.

use crate::common;

use crate::common::{render_str, scene};
use glam::{Vec3, Vec3A};
use rtis::RenderScene;
use rtis::geometry::Ray;
use rtis::mesh::{displaced_sphere, load_obj, write_obj};
use rtis::sampling::{Sampler, hemisphere};

fn temp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("rtis-mesh-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn generator_makes_closed_meshes_of_the_asked_size() {
    for n in [1_000usize, 10_000, 100_000] {
        let m = displaced_sphere(n, Vec3::ZERO, 1.0, 0.05);
        let ratio = m.faces.len() as f64 / n as f64;
        assert!((0.9..1.1).contains(&ratio), "{n}: {} faces", m.faces.len());
        // Closed: every edge is shared by exactly two faces, in opposite directions.
        let mut edges = std::collections::HashMap::new();
        for f in &m.faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(
            edges
                .iter()
                .all(|(&(a, b), &c)| c == 1 && edges.get(&(b, a)) == Some(&1))
        );
    }
}

#[test]
fn obj_round_trip_and_scene_loading() {
    let d = temp("roundtrip");
    let m = displaced_sphere(500, Vec3::new(0.0, 0.0, 5.0), 1.0, 0.05);
    write_obj(&m, &d.join("blob.obj")).unwrap();
    let back = load_obj(&d.join("blob.obj")).unwrap();
    // tobj renumbers vertices (one index for position and normal), so compare each face's
    // corners.
    assert_eq!(back.faces.len(), m.faces.len());
    for (f, g) in back.faces.iter().zip(&m.faces) {
        for k in 0..3 {
            let (a, b) = (back.positions[f[k] as usize], m.positions[g[k] as usize]);
            assert!((a - b).length() < 1e-5, "{a} vs {b}");
            let (na, nb) = (back.normals[f[k] as usize], m.normals[g[k] as usize]);
            assert!((na - nb).length() < 1e-5);
        }
    }
    // Loaded through a scene, relative to the scene file's folder.
    std::fs::write(
        d.join("s.ron"),
        "Scene(film: (width: 32, height: 24), entities: [(name: \"blob\", shape: Mesh(path: \"blob.obj\"), material: Phong(kd: (0.8, 0.5, 0.3))), (light: Point(position: (2, 3, 0), intensity: (9, 9, 9)))])",
    )
    .unwrap();
    let s = rtis::scene::load_path(&d.join("s.ron")).unwrap();
    let p = rtis::extract(&s);
    assert_eq!(
        p.geometry.count(rtis::shape::ShapeKind::Triangle),
        m.faces.len()
    );
    assert!(
        p.geometry.prims().all(|q| q.smooth != rtis::accel::FLAT),
        "every triangle is smooth"
    );
    let r = common::render_scene(&s);
    assert!(r.image.all_finite() && r.image.mean().x > 0.0);
    std::fs::remove_dir_all(&d).unwrap();
}

/// Smooth shading interpolates vertex normals: on a coarse sphere it differs from flat shading,
/// and it is closer to the analytic sphere's shading (mean absolute difference), since the
/// vertex normals are the sphere's.
#[test]
fn smooth_normals_approach_the_true_sphere() {
    let m = displaced_sphere(300, Vec3::new(0.0, 0.0, 4.0), 1.0, 0.0);
    let verts: Vec<String> = m
        .positions
        .iter()
        .map(|p| format!("({}, {}, {})", p.x, p.y, p.z))
        .collect();
    let faces: Vec<String> = m
        .faces
        .iter()
        .map(|f| format!("({}, {}, {})", f[0], f[1], f[2]))
        .collect();
    let normals: Vec<String> = m
        .normals
        .iter()
        .map(|n| format!("({}, {}, {})", n.x, n.y, n.z))
        .collect();
    let with = |shape: String| {
        render_str(&format!(
            "Scene(film: (width: 48, height: 48), camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1), fov: 40),
             entities: [(shape: {shape}, material: Phong(kd: (0.8, 0.8, 0.8))), (light: Point(position: (-3, 3, 0), intensity: (9, 9, 9)))])"
        ))
    };
    let mesh = |n: &str| {
        format!(
            "TriangleMesh(vertices: [{}], faces: [{}]{n})",
            verts.join(","),
            faces.join(",")
        )
    };
    let flat = with(mesh(""));
    let smooth = with(mesh(&format!(", normals: [{}]", normals.join(","))));
    let truth = with("Sphere(center: (0, 0, 4), radius: 1)".into());
    let diff = |a: &rtis::render::Rendered| {
        a.image
            .pixels
            .iter()
            .zip(&truth.image.pixels)
            .map(|(p, q)| (*p - *q).abs().element_sum())
            .sum::<f32>()
    };
    assert_ne!(flat.image, smooth.image);
    assert!(
        diff(&smooth) < 0.7 * diff(&flat),
        "smooth {} flat {}",
        diff(&smooth),
        diff(&flat)
    );
}

/// A transform places a shape exactly where writing it there would: a unit sphere scaled by 2,
/// rotated and moved renders the same bits as the sphere written at its final place.
#[test]
fn transforms_place_shapes() {
    let a = render_str(
        "Scene(film: (width: 24, height: 24), camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1)),
         entities: [(shape: Sphere(center: (0, 0, 0), radius: 0.5), material: Phong(kd: (1, 1, 1)),
                     transform: (scale: (2, 2, 2), rotate: (0, 90, 0), translate: (0.5, 0, 6))),
                    (light: Point(position: (0, 3, 0), intensity: (9, 9, 9)))])",
    );
    let b = render_str(
        "Scene(film: (width: 24, height: 24), camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1)),
         entities: [(shape: Sphere(center: (0.5, 0, 6), radius: 1), material: Phong(kd: (1, 1, 1))),
                    (light: Point(position: (0, 3, 0), intensity: (9, 9, 9)))])",
    );
    assert_eq!(a.image, b.image);
    // A plane rotated by 90 degrees about z turns its normal from +y to -x.
    let s = scene(
        "Scene(entities: [(shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Mirror(),
                           transform: (rotate: (0, 0, 90), translate: (2, 0, 0)))])",
    );
    let p = rtis::extract(&s);
    let rtis::shape::Shape::Plane(pl) = p.geometry.prim(0).shape else {
        panic!()
    };
    assert!(
        (pl.n - Vec3A::new(-1.0, 0.0, 0.0)).length() < 1e-6 && (pl.dist.abs() - 2.0).abs() < 1e-6
    );
}

fn mesh_scene(n: usize) -> RenderScene {
    let d = temp(&format!("m{n}"));
    let m = displaced_sphere(n, Vec3::ZERO, 1.0, 0.08);
    write_obj(&m, &d.join("m.obj")).unwrap();
    let s = rtis::scene::load_str(
        "Scene(entities: [(shape: Mesh(path: \"m.obj\"), material: Phong(kd: (1, 1, 1)))])",
        "m.ron",
        Some(&d),
    )
    .unwrap();
    std::fs::remove_dir_all(&d).unwrap();
    rtis::extract(&s)
}

/// Watertight on a real mesh: 200000 rays from inside a closed mesh, in every direction, all
/// hit it (a crack between triangles would let one escape).
#[test]
fn closed_mesh_has_no_cracks() {
    let p = mesh_scene(20_000);
    let mut s = Sampler::new(5, 0, 0);
    for i in 0..200_000 {
        let (a, b) = s.next_2d();
        let mut d = hemisphere::uniform(a, b);
        if i % 2 == 1 {
            d.z = -d.z;
        }
        let o = Vec3A::new(0.01 * (i % 7) as f32, -0.013 * (i % 5) as f32, 0.0);
        assert!(
            p.geometry.intersect(&Ray::new(o, d)).is_some(),
            "ray {i} {o} {d} escaped"
        );
    }
}

/// The BVH finds the same nearest hit as testing every triangle.
#[test]
fn bvh_agrees_with_brute_force() {
    let p = mesh_scene(5_000);
    let mut s = Sampler::new(9, 0, 0);
    let mut hits = 0;
    for _ in 0..3000 {
        let (a, b) = s.next_2d();
        let o = Vec3A::new(a * 6.0 - 3.0, b * 6.0 - 3.0, -4.0);
        let (c, e) = s.next_2d();
        let target = Vec3A::new(c * 2.0 - 1.0, e * 2.0 - 1.0, 0.0);
        let ray = Ray::new(o, (target - o).normalize());
        let brute = p
            .geometry
            .prims()
            .filter_map(|q| q.shape.intersect(&ray))
            .fold(f32::INFINITY, f32::min);
        match p.geometry.intersect(&ray) {
            Some(h) => {
                hits += 1;
                assert_eq!(h.t, brute);
            }
            None => assert!(brute.is_infinite()),
        }
        assert_eq!(p.geometry.occluded(&ray), brute.is_finite());
    }
    assert!(hits > 1000);
}

/// Smooth shading by hand: on a triangle with vertex normals n0, n1, n2, the shading normal is
/// n1 at the second vertex, the normalised mean of the three at the centroid, and the
/// normalised mean of n0 and n2 at the middle of their edge.
#[test]
fn smooth_normals_interpolate_barycentrically() {
    use rtis::accel::{Geometry, Prim};
    use rtis::shape::{Shape, Triangle};
    let (a, b, c) = (
        Vec3A::new(0.0, 0.0, 0.0),
        Vec3A::new(2.0, 0.0, 0.0),
        Vec3A::new(0.0, 3.0, 0.0),
    );
    let t = Triangle::new(a, b, c).unwrap();
    let (n0, n1, n2) = (
        Vec3A::new(0.0, 0.0, 1.0),
        Vec3A::new(0.6, 0.0, 0.8),
        Vec3A::new(0.0, 0.6, 0.8),
    );
    let g = Geometry::build(
        vec![Prim {
            shape: Shape::Triangle(t),
            material: 0,
            smooth: 0,
            light: rtis::light::NO_LIGHT,
        }],
        vec![[n0, n1, n2]],
    );
    let prim = &g.prim(0);
    let at = |p: Vec3A| g.shading_normal(prim, p, t.n);
    let near = |x: Vec3A, y: Vec3A| (x - y).length() < 1e-5;
    assert!(near(at(b), n1), "{}", at(b));
    assert!(
        near(at((a + b + c) / 3.0), (n0 + n1 + n2).normalize()),
        "{}",
        at((a + b + c) / 3.0)
    );
    assert!(
        near(at((a + c) / 2.0), (n0 + n2).normalize()),
        "{}",
        at((a + c) / 2.0)
    );
}
