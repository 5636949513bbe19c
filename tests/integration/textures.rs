//! Texture coordinates (src/accel/mod.rs, `Geometry::uv`), Mitsuba 3's conventions: exact
//! values at known points of every shape, through a ray that hits there.

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
    let e = "(shape: Sphere(center: (1, 2, 3), radius: 2), material: Phong(kd: (1, 1, 1)))";
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
                 material: Phong(kd: (1, 1, 1)))";
    for (s, t) in [(0.25f32, 0.5f32), (0.75, 0.25), (0.1, 0.9)] {
        let p = Vec3A::new(-1.0 + 2.0 * s, -1.0 + 3.0 * t, 5.0);
        let uv = uv_at(rect, Vec3A::ZERO, p);
        assert!(close(uv, Vec2::new(s, t)), "({s}, {t}): {uv}");
    }
    let mirrored = "(shape: Rectangle(corner: (-1, -1, 5), u: (2, 0, 0), v: (0, 3, 0)),
                     material: Phong(kd: (1, 1, 1)),
                     transform: (scale: (-1, 1, 1)))";
    // Mirrored in x, the point (s, t) lands at x = -(-1 + 2 s).
    let p = Vec3A::new(1.0 - 2.0 * 0.25, -1.0 + 3.0 * 0.5, 5.0);
    let uv = uv_at(mirrored, Vec3A::ZERO, p);
    assert!(close(uv, Vec2::new(0.25, 0.5)), "mirrored: {uv}");

    let tri = "(shape: Triangle(a: (0, 0, 4), b: (2, 0, 4), c: (0, 2, 4)),
                material: Phong(kd: (1, 1, 1)))";
    let p = Vec3A::new(2.0 * 0.2, 2.0 * 0.3, 4.0);
    let uv = uv_at(tri, Vec3A::ZERO, p);
    assert!(close(uv, Vec2::new(0.2, 0.3)), "triangle: {uv}");
}

/// An infinite plane: the offset from its point along the two world axes other than the
/// normal's largest (`x, z` for a floor).
#[test]
fn plane_coordinates() {
    let floor = "(shape: InfinitePlane(point: (1, -1, 2), normal: (0, 1, 0)),
                  material: Phong(kd: (1, 1, 1)))";
    let uv = uv_at(floor, Vec3A::new(3.0, 1.0, -1.0), -Vec3A::Y);
    assert!(close(uv, Vec2::new(2.0, -3.0)), "floor: {uv}");
    let wall = "(shape: InfinitePlane(point: (5, 0, 0), normal: (-1, 0.2, 0)),
                 material: Phong(kd: (1, 1, 1)))";
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
        "(shape: Mesh(path: {:?}), material: Phong(kd: (1, 1, 1)))",
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
