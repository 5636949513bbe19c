//! Oriented planes (`Plane::side`, `Plane::facing`): rays stay in the room the
//! camera is in, and shadow rays towards a light in that room skip the planes without changing
//! a pixel.

use crate::common;

use crate::common::{scene, scenes_dir};
use glam::{DVec3, Vec3A};
use rtis::geometry::{Origins, Ray};
use rtis::light::Light;
use rtis::render::{RenderScene, render};
use rtis::sampling::Sampler;
use rtis::shape::Shape;

/// The course's box (five planes, open behind the camera) scaled by `s` and moved by `t`,
/// with the Global shader, a point light inside and `spheres` (0 to 2 of the course's: the
/// mirror ball that cuts into the left wall and the floor, then a ball touching the right wall).
fn room(s: f64, t: DVec3, spheres: usize) -> String {
    let p = |x: f64, y: f64, z: f64| {
        let q = t + s * DVec3::new(x, y, z);
        format!("({:e}, {:e}, {:e})", q.x, q.y, q.z)
    };
    let plane = |pt: String, n: &str| {
        format!(
            "(shape: InfinitePlane(point: {pt}, normal: {n}), material: Phong(kd: (0.7, 0.7, 0.7))),"
        )
    };
    let balls = [
        format!(
            "(shape: Sphere(center: {}, radius: {:e}), material: Mirror()),",
            p(-2.0, -2.0, 3.5),
            1.5 * s
        ),
        format!(
            "(shape: Sphere(center: {}, radius: {:e}), material: Phong(kd: (0.5, 0.5, 0.5))),",
            p(2.0, 0.0, 5.0),
            s
        ),
    ];
    format!(
        "Scene(film: (width: 8, height: 8), shader: Global(samples: 4, max_depth: 3),
          camera: Perspective(position: {}, look_at: {}, fov: 60),
          entities: [{} {} {} {} {} {} (light: Point(position: {}, intensity: (7, 7, 7)))])",
        p(0.0, 0.0, -3.0),
        p(0.0, 0.0, 1.0),
        plane(p(-3.0, 0.0, 0.0), "(1, 0, 0)"),
        plane(p(3.0, 0.0, 0.0), "(-1, 0, 0)"),
        plane(p(0.0, 3.0, 0.0), "(0, -1, 0)"),
        plane(p(0.0, -3.0, 0.0), "(0, 1, 0)"),
        plane(p(0.0, 0.0, 9.0), "(0, 0, -1)"),
        balls[..spheres].concat(),
        p(0.0, 2.0, 3.0),
    )
}

fn prepared(text: &str) -> RenderScene {
    rtis::extract(&scene(text))
}

/// The planes of a prepared scene.
fn planes(r: &RenderScene) -> Vec<rtis::shape::Plane> {
    (r.geometry.prims())
        .filter_map(|p| match p.shape {
            Shape::Plane(pl) => Some(pl),
            _ => None,
        })
        .collect()
}

/// Every wall of the course's box faces the camera's side, and its three lights are in the
/// room; glass planes and planes the camera stands on are not oriented.
#[test]
fn planes_are_oriented_towards_the_camera() {
    let cornell = rtis::extract(
        &rtis::scene::load_path(&scenes_dir().join("cornell.ron"))
            .unwrap_or_else(|e| panic!("{e}")),
    );
    let walls = planes(&cornell);
    assert_eq!(walls.len(), 5);
    for w in &walls {
        // The camera (the origin of render coordinates) is on the oriented side.
        assert_eq!(w.side, (w.n.dot(Vec3A::ZERO) - w.dist).signum(), "{w:?}");
    }
    assert!(cornell.lights.iter().all(Light::in_room));

    let glass = prepared(
        "Scene(entities: [
            (shape: InfinitePlane(point: (0, 0, 5), normal: (0, 0, 1)), material: Transmissive(ior: 1.5)),
            (shape: InfinitePlane(point: (0, -1, 0), normal: (0, 1, 0)), material: Mirror()),
            (light: Point(position: (0, 1, 9), intensity: (1, 1, 1)))])",
    );
    let sides: Vec<f32> = planes(&glass).iter().map(|p| p.side).collect();
    assert_eq!(sides, [0.0, 1.0], "glass is crossed; the floor is not");
    assert!(!glass.lights[0].in_room(), "a plane is not oriented");

    let on = prepared(
        "Scene(camera: Perspective(position: (0, 0, 0), look_at: (0, 0, 1)), entities: [
            (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), material: Mirror())])",
    );
    assert_eq!(planes(&on)[0].side, 0.0, "the camera stands on the plane");

    // An orthographic camera starts its rays across its image rectangle (4 units tall, 5
    // wide, centred at the origin): a plane that cuts the rectangle has rays on both sides.
    let ortho = |x: f32| {
        prepared(&format!(
            "Scene(film: (width: 50, height: 40),
              camera: Orthographic(position: (0, 0, 0), look_at: (0, 0, 1), height: 4),
              entities: [(shape: InfinitePlane(point: ({x}, 0, 0), normal: (1, 0, 0)), material: Mirror())])"
        ))
    };
    assert_eq!(
        planes(&ortho(3.0))[0].side,
        -1.0,
        "the rectangle ends at x = 2.5"
    );
    assert_eq!(
        planes(&ortho(2.0))[0].side,
        0.0,
        "the plane cuts the rectangle"
    );

    let behind = prepared(
        "Scene(entities: [
            (shape: InfinitePlane(point: (0, -1, 0), normal: (0, 1, 0)), material: Mirror()),
            (light: Point(position: (0, -2, 0), intensity: (1, 1, 1)))])",
    );
    assert!(!behind.lights[0].in_room(), "the light is under the floor");
}

/// A ray that starts at a crease, on the floor within the error band of the left wall, and
/// heads through that wall meets it at once, instead of leaking out of the room; one that
/// heads into the room does not meet it.
#[test]
fn a_ray_from_a_crease_does_not_leave_the_room() {
    let r = prepared(&room(1.0, DVec3::ZERO, 0));
    let g = &r.geometry;
    // Camera-relative coordinates: the room's corner is at x = -3, y = -3 (z from -3 on).
    let o = Vec3A::new(-3.0 + 1e-6, -3.0 + 1e-6, 6.0);
    let out = Ray {
        o_err: 1e-5,
        ..Ray::new(o, Vec3A::new(-1.0, 0.2, 0.1).normalize())
    };
    let hit = g.intersect(&out).expect("the wall stops it");
    assert!(hit.t < 1e-4, "at once: t = {}", hit.t);
    assert_eq!(hit.n, Vec3A::X, "on the left wall");
    let inward = Ray {
        o_err: 1e-5,
        ..Ray::new(o, Vec3A::new(1.0, 0.2, 0.1).normalize())
    };
    let far = g.intersect(&inward).expect("the right wall");
    assert!(far.t > 1.0, "t = {}", far.t);
}

/// Random walks in the room, with and without a mirror ball that cuts into a wall and the
/// floor and a ball touching a wall: each ray leaves its hit from the hit's [`Origins`], as the
/// shaders' rays do, in a direction on the viewer's side, biased towards grazing ones (which run
/// along walls into creases). Every hit is on the room's side of every wall (within its error
/// band), at scales from 1e-3 to 1e3 and far from the origin. Before the planes were oriented,
/// rays leaving from a crease went through the wall and hit the other walls' planes outside
/// the room.
#[test]
fn random_walks_stay_in_the_room() {
    let mut rng = Sampler::new(7, 0, 0);
    for s in [1e-3, 1.0, 1e3] {
        for (t, spheres) in [
            (DVec3::ZERO, 0),
            (DVec3::new(1e5, -3e5, 2e4), 0),
            (DVec3::ZERO, 2),
        ] {
            let r = prepared(&room(s, t, spheres));
            let walls = planes(&r);
            let mut outside = 0;
            for _ in 0..20_000 {
                let (u, v) = (rng.next_f32(), rng.next_f32());
                let mut ray = r
                    .camera
                    .ray(u, v, || panic!("a pinhole draws no lens sample"));
                for _ in 0..8 {
                    let Some(hit) = r.geometry.intersect(&ray) else {
                        break;
                    };
                    let origins = Origins::new(&hit);
                    // The camera's side (the camera is the origin of render coordinates).
                    let out =
                        |w: &rtis::shape::Plane| w.side_of(hit.p, origins.o_err) == w.dist.signum();
                    if walls.iter().any(out) {
                        outside += 1;
                        break;
                    }
                    // A direction on the viewer's side, biased towards grazing ones.
                    let n = if hit.n.dot(ray.d) < 0.0 {
                        hit.n
                    } else {
                        -hit.n
                    };
                    let w = Vec3A::new(
                        rng.next_f32() - 0.5,
                        rng.next_f32() - 0.5,
                        rng.next_f32() - 0.5,
                    );
                    let w = (w - w.dot(n) * n * 0.999).normalize_or(n);
                    let w = if w.dot(n) <= 0.0 {
                        (w + 1e-3 * n).normalize()
                    } else {
                        w
                    };
                    ray = origins.ray(w, f32::INFINITY);
                }
            }
            assert_eq!(
                outside, 0,
                "scale {s} offset {t} spheres {spheres}: hits outside"
            );
        }
    }
}

/// Skipping the planes on shadow rays towards lights in the room changes no pixel: the course's
/// box under every shader that traces shadow rays, rendered with the lights marked in the room
/// and not.
#[test]
fn skipping_planes_on_shadow_rays_changes_no_pixel() {
    for file in [
        "cornell-n-bounce.ron",
        "cornell-direct.ron",
        "cornell-physical.ron",
    ] {
        let loaded =
            rtis::scene::load_path(&scenes_dir().join(file)).unwrap_or_else(|e| panic!("{e}"));
        let mut r = rtis::extract(&loaded);
        r.film.width = 50;
        r.film.height = 40;
        assert!(r.lights.iter().all(Light::in_room), "{file}");
        let skipped = render(&r, &|| {});
        common::lights_out_of_room(&mut r);
        let tested = render(&r, &|| {});
        assert!(tested.stats.shadow > 1000);
        let differ = (skipped.image.pixels.iter())
            .zip(&tested.image.pixels)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "{file}: pixels differ");
    }
}
