//! Where spawned rays start (`src/geometry/ray.rs`'s `Origins`, and the same computation in the
//! Global shader's waves, `src/shader/global/waves.rs` and `waves/lanes.rs`): every ray that
//! leaves a surface, of every kind (reflection, refraction, shadow, indirect), from every code
//! that traces one (the one-ray shaders, the Global shader's depth-first walk, its waves in
//! lanes and its waves over a BVH), starts strictly on the side of the surface it leaves
//! towards, and never meets that surface again near its start.
//!
//! Each ray is seen through the tracer's audit (`rtis::shader::RayAudit`) as it is traced. The
//! surface it leaves is found in double precision from the primitives as stored (a plane's
//! `n.p = dist`, a sphere's centre and radius, a triangle's three vertices): those are the
//! exact surfaces the error bounds are about, so the side of an origin is a sign computed in
//! `f64` with room to spare (an origin is moved off its surface by the bound on its hit point's
//! error plus two roundings of its coordinates, some 1e-7 of the scene's scale, and `f64`
//! rounds at 1e-16 of it).

use crate::common;

use glam::{DVec3, Vec3A};
use rtis::RenderScene;
use rtis::accel::Prim;
use rtis::render::render_sample;
use rtis::shader::Shader;
use rtis::shader::global::Order;
use rtis::shape::{Shape, ShapeKind};
use rtis::stats::{RayKind, RayStats};
use std::collections::BTreeMap;

/// A room of planes at scale `s` and offset `o` (every point `p` placed at `s p + o`): a mirror
/// wall, a glossy back wall, a mirror ball, a glass ball and a Phong ball, two point lights;
/// with `bvh`, also a glass prism, a mirror of two triangles, a loose triangle and a smooth OBJ
/// blob (the BVH's meshes), and with `area`, a rectangle emitter under the ceiling.
fn room(s: f64, o: f64, model: &str, shader: &str, bvh: bool, area: bool) -> String {
    let p = |x: f64, y: f64, z: f64| format!("({}, {}, {})", s * x + o, s * y + o, s * z + o);
    let v = |x: f64, y: f64, z: f64| format!("({}, {}, {})", s * x, s * y, s * z);
    let mut e = vec![
        format!(
            "(shape: InfinitePlane(point: {}, normal: (1, 0, 0)), material: Phong(kd: (0.7, 0.2, 0.3)))",
            p(-3.0, 0.0, 0.0)
        ),
        format!(
            "(shape: InfinitePlane(point: {}, normal: (-1, 0, 0)), material: Mirror(color: (0.9, 0.9, 0.9)))",
            p(3.0, 0.0, 0.0)
        ),
        format!(
            "(shape: InfinitePlane(point: {}, normal: (0, -1, 0)), material: Phong(kd: (0.8, 0.8, 0.8)))",
            p(0.0, 3.0, 0.0)
        ),
        format!(
            "(shape: InfinitePlane(point: {}, normal: (0, 1, 0)), material: Phong(kd: (0.8, 0.8, 0.8)))",
            p(0.0, -3.0, 0.0)
        ),
        format!(
            "(shape: InfinitePlane(point: {}, normal: (0, 0, -1)), material: Phong(kd: (0.3, 0.2, 0.7), ks: (0.5, 0.5, 0.5), shininess: 20))",
            p(0.0, 0.0, 9.0)
        ),
        format!(
            "(shape: Sphere(center: {}, radius: {}), material: Mirror(color: (1, 0.9, 0.85)))",
            p(-2.0, -2.0, 3.5),
            1.5 * s
        ),
        format!(
            "(shape: Sphere(center: {}, radius: {}), material: Transmissive(ior: 1.5, color: (1, 1, 1)))",
            p(1.0, 0.0, 2.0),
            s
        ),
        format!(
            "(shape: Sphere(center: {}, radius: {}), material: Phong(kd: (0.7, 0.2, 0.3), ks: (0.7, 0.7, 0.2), shininess: 100))",
            p(0.3, -2.0, 5.0),
            s
        ),
        format!(
            "(light: Point(position: {}, intensity: (7, 7, 7)))",
            p(0.0, 2.0, 0.0)
        ),
        format!(
            "(light: Point(position: {}, intensity: (7, 7, 7)))",
            p(-1.0, 2.0, 6.0)
        ),
    ];
    if bvh {
        e.push(format!(
            "(shape: TriangleMesh(vertices: [{}, {}, {}, {}, {}, {}], faces: [(0, 1, 2), (3, 5, 4), (0, 3, 4), (0, 4, 1), (1, 4, 5), (1, 5, 2), (2, 5, 3), (2, 3, 0)]), material: Transmissive(ior: 1.3, color: (0.9, 1, 0.95)))",
            p(-1.6, -3.0, 1.0), p(-0.4, -3.0, 1.0), p(-1.0, -3.0, 2.0), p(-1.6, -1.6, 1.0), p(-0.4, -1.6, 1.0), p(-1.0, -1.6, 2.0)
        ));
        e.push(format!(
            "(shape: TriangleMesh(vertices: [{}, {}, {}, {}], faces: [(0, 1, 2), (0, 2, 3)]), material: Mirror(color: (0.95, 0.95, 0.95)))",
            p(0.5, -3.0, 7.5), p(2.8, -3.0, 6.5), p(2.8, 0.0, 6.5), p(0.5, 0.0, 7.5)
        ));
        e.push(format!(
            "(shape: Triangle(a: {}, b: {}, c: {}), material: Phong(kd: (0.9, 0.9, 0.2)))",
            p(-2.5, -2.99, 0.5),
            p(-1.0, -2.99, 0.0),
            p(-1.8, -2.99, 1.2)
        ));
        e.push(format!(
            "(shape: Mesh(path: \"assets/blob.obj\"), material: Phong(kd: (0.6, 0.6, 0.3), ks: (0.3, 0.3, 0.3), shininess: 30), transform: (scale: {}, translate: {}))",
            v(0.8, 0.8, 0.8), p(1.8, -2.0, 5.0)
        ));
    }
    if area {
        e.push(format!(
            "(shape: Rectangle(corner: {}, u: {}, v: {}), emitter: Emitter(radiance: (5, 5, 5)))",
            p(-0.5, 2.9, 2.5),
            v(1.0, 0.0, 0.0),
            v(0.0, 0.0, 1.0)
        ));
    }
    format!(
        "Scene(film: (width: 10, height: 8, spp: 2), model: {model},
           camera: Perspective(position: {}, look_at: {}, up: (0, 1, 0), fov: 70),
           shader: {shader}, background: (0.2, 0.3, 0.4), seed: 3,
           entities: [{}])",
        p(0.0, 0.0, -2.9),
        p(0.0, -0.5, 1.0),
        e.join(",\n")
    )
}

/// A primitive's surface in double precision, as stored.
#[derive(Clone, Copy, Debug)]
enum Exact {
    /// `{x : n.x = dist}`.
    Plane { n: DVec3, dist: f64 },
    /// Centre and radius.
    Sphere { c: DVec3, r: f64 },
    /// Three vertices.
    Triangle([DVec3; 3]),
}

impl Exact {
    fn of(prim: &Prim) -> Self {
        let d = |v: Vec3A| v.as_dvec3();
        match prim.shape {
            Shape::Plane(p) => Exact::Plane {
                n: d(p.n),
                dist: p.dist as f64,
            },
            Shape::Sphere(s) => Exact::Sphere {
                c: d(s.c),
                r: s.r as f64,
            },
            Shape::Triangle(t) => Exact::Triangle(t.v.map(d)),
        }
    }

    /// The signed distance of `x` from the surface along `normal(x)` (positive on the side the
    /// normal points to), and the distance from `x` to the surface itself (for a triangle, to
    /// its nearest point, which may lie on an edge).
    fn side_and_distance(&self, x: DVec3) -> (f64, f64) {
        match *self {
            Exact::Plane { n, dist } => {
                let s = (n.dot(x) - dist) / n.length();
                (s, s.abs())
            }
            Exact::Sphere { c, r } => {
                let s = (x - c).length() - r;
                (s, s.abs())
            }
            Exact::Triangle(v) => {
                let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
                (n.dot(x - v[0]), (x - closest_on_triangle(x, v)).length())
            }
        }
    }

    /// The unit normal at (or nearest to) `x` that the signed distance is measured along.
    fn normal(&self, x: DVec3) -> DVec3 {
        match *self {
            Exact::Plane { n, .. } => n.normalize(),
            Exact::Sphere { c, .. } => (x - c).normalize(),
            Exact::Triangle(v) => (v[1] - v[0]).cross(v[2] - v[0]).normalize(),
        }
    }

    /// The distances `t > 0` at which the line `x + t d` meets the surface, in double precision.
    fn crossings(&self, x: DVec3, d: DVec3) -> Vec<f64> {
        match *self {
            Exact::Sphere { c, r } => {
                let (oc, d) = (x - c, d.normalize());
                let b = d.dot(oc);
                let disc = b * b - (oc.length_squared() - r * r);
                if disc < 0.0 {
                    return Vec::new();
                }
                let q = disc.sqrt();
                [-b - q, -b + q].into_iter().filter(|&t| t > 0.0).collect()
            }
            _ => Vec::new(),
        }
    }
}

/// The point of triangle `v` nearest to `x` (Ericson, "Real-Time Collision Detection", 5.1.5).
fn closest_on_triangle(x: DVec3, [a, b, c]: [DVec3; 3]) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, x - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = x - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = x - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// What the checks found.
#[derive(Default, Debug)]
struct Tally {
    /// Rays checked, by the order of tracing that made them, their kind and the kind of shape
    /// they leave.
    checked: BTreeMap<(&'static str, String, String), usize>,
    /// Rays whose start lies near two surfaces that disagree (a crease), or whose direction
    /// grazes the surface (`|d.n| < 1e-3`, where the side rule's `f32` normal may decide
    /// otherwise than the exact one): not checked, only counted.
    skipped: usize,
    /// What went wrong, one line a ray, for the first ten.
    wrong: Vec<String>,
    /// How many rays went wrong.
    wrong_count: usize,
}

impl Tally {
    /// Count a wrong ray, keeping the message of the first ten.
    fn wrong(&mut self, message: impl FnOnce() -> String) {
        self.wrong_count += 1;
        if self.wrong.len() < 10 {
            self.wrong.push(message());
        }
    }
}

/// Render `rs` on this thread with the audit on, and check every ray that leaves a surface.
/// `order` names the code that traces it.
fn check(rs: &RenderScene, tally: &mut Tally, order: &'static str, what: &str) {
    let mut stats = RayStats::default();
    let seen = common::rays_traced(rs, |rs| {
        for row in 0..rs.film.height {
            for col in 0..rs.film.width {
                for s in 0..rs.film.spp {
                    render_sample(rs, col, row, s, &mut stats);
                }
            }
        }
    });
    // The audit saw every ray counted, kind by kind.
    let mut audited = RayStats::default();
    for (_, kind) in &seen {
        audited.count(*kind);
    }
    assert_eq!(
        (
            audited.camera,
            audited.shadow,
            audited.reflection,
            audited.refraction,
            audited.indirect
        ),
        (
            stats.camera,
            stats.shadow,
            stats.reflection,
            stats.refraction,
            stats.indirect
        ),
        "{what}: the audit saw every ray counted"
    );
    let prims: Vec<(u32, Prim, Exact, [f32; 6])> = rs
        .geometry
        .indices()
        .map(|i| {
            let p = rs.geometry.prim(i);
            let b = p
                .shape
                .bounds()
                .map_or([f32::NEG_INFINITY, f32::INFINITY].repeat(3), |b| {
                    vec![b.min.x, b.max.x, b.min.y, b.max.y, b.min.z, b.max.z]
                });
            (i, p, Exact::of(&p), b.try_into().unwrap())
        })
        .collect();
    for (ray, kind) in seen {
        if kind == RayKind::Camera {
            assert_eq!(ray.o_err, 0.0, "{what}: a camera ray starts exactly");
            continue;
        }
        let x = ray.o.as_dvec3();
        // The surfaces within reach of the origin's error bound (per coordinate, so sqrt(3)
        // along any line, and twice that for room).
        let reach = 4.0 * ray.o_err as f64;
        assert!(
            reach > 0.0,
            "{what}: a {kind:?} ray with no origin error: {ray:?}"
        );
        // Each with its signed distance and its distance from the start.
        let near: Vec<(u32, ShapeKind, Exact, f64, f64)> = prims
            .iter()
            .filter(|(.., b)| {
                let r = reach as f32;
                (0..3).all(|k| ray.o[k] >= b[2 * k] - r && ray.o[k] <= b[2 * k + 1] + r)
            })
            .filter_map(|(i, p, e, _)| {
                let (s, dist) = e.side_and_distance(x);
                (dist <= reach).then_some((*i, p.shape.kind(), *e, s, dist))
            })
            .collect();
        // The surface it leaves: the nearest.
        let Some(&(_, shape, surface, s, _)) = near.iter().min_by(|a, b| a.4.total_cmp(&b.4))
        else {
            tally.wrong(|| format!("{what}: a {kind:?} ray starts on no surface: {ray:?}"));
            continue;
        };
        let d = ray.d.as_dvec3();
        let cos = d.dot(surface.normal(x));
        // Two near surfaces that would put the start on different sides (a crease), or a
        // grazing direction: counted, not checked.
        let disagree = near.iter().any(|&(_, _, e, s2, _)| {
            (s2 > 0.0) != (s > 0.0) || (d.dot(e.normal(x)) > 0.0) != (cos > 0.0)
        });
        if disagree || cos.abs() < 1e-3 {
            tally.skipped += 1;
            continue;
        }
        *tally
            .checked
            .entry((order, format!("{kind:?}"), format!("{shape:?}")))
            .or_default() += 1;
        // The start is strictly on the side the ray leaves towards.
        if s * cos <= 0.0 || (s * cos).is_nan() {
            tally.wrong(|| {
                format!(
                    "{what}: a {kind:?} ray leaving a {shape:?} towards side {cos:+.3} starts at \
                     signed distance {s:e} (error bound {:e}): {ray:?}",
                    ray.o_err
                )
            });
            continue;
        }
        // It never meets the surfaces at its start again near it (every one of them, the one
        // it leaves and any neighbour within reach, lies behind it): a plane or triangle not
        // at all, a sphere only where the line crosses it away from the start. The nearest hit
        // is asked of the one-ray query; the batches and lanes the waves trace with give its
        // answers field for field (`tests/integration/batch.rs`, on rays leaving hits among others).
        if let Some(hit) = rs.geometry.intersect(&ray)
            && let Some(&(_, shape, surface, ..)) = near.iter().find(|n| n.0 == hit.prim)
        {
            let far = surface.crossings(x, d);
            let ok = far
                .iter()
                .any(|&t| t > 1e3 * reach && (hit.t as f64 - t).abs() <= 1e-4 * t.max(reach));
            if !ok {
                tally.wrong(|| {
                    format!(
                        "{what}: a {kind:?} ray leaving a {shape:?} meets it again at t = {:e} \
                         (crossings {far:?}, error bound {:e}): {ray:?}",
                        hit.t, ray.o_err
                    )
                });
            }
        }
    }
}

/// The shaders, and the order of tracing each is meant to take.
const SHADERS: [(&str, &str); 5] = [
    ("Direct", "Direct()"),
    (
        "Global waves",
        "Global(samples: 6, max_depth: 2, ambient: (0.1, 0.1, 0.1))",
    ),
    (
        "Global walk",
        "Global(samples: 2, max_depth: 9, ambient: (0.1, 0.1, 0.1))",
    ),
    ("Path", "Path(max_depth: 8)"),
    (
        "Path one light",
        "Path(max_depth: 8, lights_per_vertex: One)",
    ),
];

/// Every spawned ray, in every shader and order of tracing, in packed scenes and scenes with a
/// BVH, under both models and at scales 1e-3 to 1e3 (and far from the origin): strictly on its
/// side, and no re-hit near its start. Each kind of ray is seen leaving each kind of shape it
/// can leave here, through each code that traces it; grazing rays and creases (not checked)
/// stay rare. Flipping the side in `Origins::ray`, in the waves' light pass or in the lanes'
/// children fails it, as does an offset of zero.
#[test]
fn spawned_rays_start_on_the_side_they_leave_towards() {
    let _limit = common::deadline(600);
    let mut tally = Tally::default();
    let mut orders = BTreeMap::<&str, usize>::new();
    for (scale, offset) in [(1.0, 0.0), (1e-3, 0.0), (1e3, 0.0), (1.0, 100.0)] {
        for (name, shader) in SHADERS {
            for (bvh, area) in [(false, false), (true, false), (true, true)] {
                if area && name.starts_with("Global") {
                    continue;
                }
                // Both models: the Course model's Path where the scene is packed.
                let model = if name == "Path" && !bvh {
                    "Course"
                } else {
                    "Physical"
                };
                let text = room(scale, offset, model, shader, bvh, area);
                let rs = rtis::extract(&common::scene(&text));
                // The order this render takes.
                let order = match rs.shader {
                    Shader::Global(g) => {
                        let mut stats = RayStats::default();
                        let tr = rs.tracer(rtis::sampling::Sampler::new(0, 0, 0), &mut stats);
                        match (Order::Waves.applies(&tr, &g), rs.geometry.bvh.is_empty()) {
                            (true, true) => "waves in lanes",
                            (true, false) => "waves over the BVH",
                            (false, _) => "depth-first walk",
                        }
                    }
                    _ => "one ray at a time",
                };
                *orders.entry(order).or_default() += 1;
                let what = format!(
                    "{name} ({order}), scale {scale}, offset {offset}, bvh {bvh}, area {area}"
                );
                check(&rs, &mut tally, order, &what);
            }
        }
    }
    assert!(
        tally.wrong_count == 0,
        "{} rays wrong, the first:\n{}",
        tally.wrong_count,
        tally
            .wrong
            .iter()
            .take(10)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
    let total: usize = tally.checked.values().sum();
    eprintln!(
        "checked {total} rays, skipped {}: {:?}; orders {orders:?}",
        tally.skipped, tally.checked
    );
    // Every code that traces was used.
    for order in [
        "waves in lanes",
        "waves over the BVH",
        "depth-first walk",
        "one ray at a time",
    ] {
        assert!(
            orders.get(order).copied().unwrap_or(0) > 0,
            "no render took the {order}"
        );
    }
    // Through every code that traces, every kind of ray left every kind of shape it can
    // leave here (the packed scenes, which the waves in lanes take, have no triangles).
    let all = ["Plane", "Sphere", "Triangle"].as_slice();
    let want = [
        ("Reflection", all),
        ("Refraction", ["Sphere", "Triangle"].as_slice()),
        ("Shadow", all),
        ("Indirect", all),
    ];
    for order in [
        "waves in lanes",
        "waves over the BVH",
        "depth-first walk",
        "one ray at a time",
    ] {
        for (kind, shapes) in want {
            for &shape in shapes {
                if order == "waves in lanes" && shape == "Triangle" {
                    continue;
                }
                let n = tally
                    .checked
                    .get(&(order, kind.to_string(), shape.to_string()))
                    .copied()
                    .unwrap_or(0);
                assert!(
                    n >= 20,
                    "only {n} {kind} rays leaving a {shape} were checked in the {order}"
                );
            }
        }
    }
    assert!(
        tally.skipped * 100 < total,
        "{} of {total} rays skipped as grazing or at a crease",
        tally.skipped
    );
}
