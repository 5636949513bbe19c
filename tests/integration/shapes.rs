//! Property tests of the ray-shape intersections.

use glam::Vec3A;
use proptest::prelude::*;
use rtis::accel::{Geometry, Prim};
use rtis::geometry::{BvhRay, Hit, Ray};
use rtis::shape::{Plane, Shape, Sphere, Triangle};

fn unit() -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-degenerate", |(x, y, z)| x * x + y * y + z * z > 1e-3)
        .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize())
}

/// Scene scale: from 1e-3 to 1e5.
fn scale() -> impl Strategy<Value = f32> {
    prop_oneof![Just(1e-3f32), Just(1.0), Just(1e3), Just(1e5)]
}

fn point(s: f32) -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(move |(x, y, z)| Vec3A::new(x, y, z) * s)
}

fn hit_of(shape: &Shape, ray: &Ray) -> Option<Hit> {
    shape.intersect(ray).map(|t| {
        let s = shape.surface(ray, t);
        Hit {
            t,
            p: s.p,
            n: s.n,
            err: s.err,
            err_along: s.err_along,
            prim: 0,
        }
    })
}

/// Distance from a point to the shape's surface.
fn distance_to_surface(shape: &Shape, p: Vec3A) -> f32 {
    match shape {
        Shape::Sphere(s) => ((p - s.c).length() - s.r).abs(),
        Shape::Plane(pl) => (pl.n.dot(p) - pl.dist).abs(),
        Shape::Triangle(t) => t.n.dot(p - t.v[0]).abs(),
    }
}

fn shapes(s: f32) -> impl Strategy<Value = Shape> {
    prop_oneof![
        (point(s), 0.05f32..1.0).prop_map(move |(c, r)| Shape::Sphere(Sphere { c, r: r * s })),
        (point(s), unit()).prop_map(|(p, n)| Shape::Plane(Plane::through(p, n))),
        (point(s), point(s), point(s))
            .prop_filter_map("zero area", |(a, b, c)| Triangle::new(a, b, c)
                .map(Shape::Triangle)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// A reported hit lies on the surface, within a tolerance relative to the scene's size (or
    /// the hit's distance from the origin, when larger),
    /// and a ray leaving the hit on the side it arrived from never hits the same surface again
    /// (planes and triangles: nothing; spheres: not near the start).
    #[test]
    fn hits_lie_on_the_surface_and_secondary_rays_do_not_rehit(
        (s, shape, o, d, w) in scale().prop_flat_map(|s| (Just(s), shapes(s), point(3.0 * s), unit(), unit()))
    ) {
        let ray = Ray::new(o, d);
        if let Some(hit) = hit_of(&shape, &ray) {
            prop_assert!(hit.p.is_finite() && hit.n.is_finite() && hit.t.is_finite());
            // Single precision holds |p| to about 6e-8 |p|: a grazing ray can hit a plane far
            // beyond the scene's size, so the tolerance follows the larger of the two.
            let size = s.max(hit.p.abs().max_element());
            prop_assert!(distance_to_surface(&shape, hit.p) <= 1e-5 * 4.0 * size,
                "distance {} at scale {s}, |p| {size}", distance_to_surface(&shape, hit.p));
            // Leave towards the side the ray came from (outward for the viewer).
            let n = if hit.n.dot(d) < 0.0 { hit.n } else { -hit.n };
            let w = if w.dot(n) > 0.0 { w } else { -w };
            if w.dot(n) > 1e-3 {
                let back = Ray::spawn(&hit, w, f32::INFINITY);
                match shape {
                    Shape::Sphere(sp) => {
                        // A ray leaving a sphere outward cannot meet it again; leaving inward
                        // it meets the far side, never the start point.
                        if let Some(t) = shape.intersect(&back) {
                            prop_assert!(t > 1e-3 * sp.r, "re-hit at t = {t}, r = {}", sp.r);
                        }
                    }
                    _ => prop_assert!(shape.intersect(&back).is_none(), "re-hit of a flat surface"),
                }
            }
        }
    }

    /// Rays parallel to a plane give no hit and no NaN.
    #[test]
    fn rays_parallel_to_a_plane_miss(p in point(10.0), n in unit(), o in point(10.0), t in unit()) {
        let d = (t - n * t.dot(n)).normalize_or_zero();
        prop_assume!(d != Vec3A::ZERO);
        let plane = Plane::through(p, n);
        // Make the direction exactly parallel in floating point where possible.
        let d = if n.dot(d) == 0.0 { d } else { return Ok(()) };
        prop_assert!(Shape::Plane(plane).intersect(&Ray::new(o, d)).is_none());
    }

}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, max_global_rejects: 1_000_000, ..ProptestConfig::default() })]

    /// A ray through the edge shared by two triangles, seen with the two faces on opposite
    /// sides of the edge (as in any mesh surface crossed by the ray), hits exactly one of them:
    /// watertight, and no double hit. (Seen edge-on with both faces on one side, the ray really
    /// does touch both faces at the edge, so that view is not asserted.)
    #[test]
    fn shared_edge_is_hit_exactly_once(
        a in point(1.0), b in point(1.0), c in point(1.0), dpt in point(1.0),
        f in 0.01f32..0.99, o in point(5.0)
    ) {
        let t1 = Triangle::new(a, b, c);
        let t2 = Triangle::new(b, a, dpt);
        prop_assume!(t1.is_some() && t2.is_some());
        let (t1, t2) = (t1.unwrap(), t2.unwrap());
        let target = a + f * (b - a);
        let d = (target - o).normalize_or_zero();
        prop_assume!(d != Vec3A::ZERO && (target - o).length() > 1e-2);
        // Sides of c and dpt relative to the plane through the ray and the edge.
        let m = (b - a).cross(d);
        let (sc, sd) = (m.dot(c - a), m.dot(dpt - a));
        prop_assume!(sc * sd < 0.0 && sc.abs() > 1e-3 && sd.abs() > 1e-3);
        let ray = BvhRay::new(Ray::new(o, d));
        let hits = [t1, t2].iter().filter(|t| t.intersect(&ray).is_some()).count();
        prop_assert_eq!(hits, 1);
    }
}

/// Rays aimed at points of a flat quad's diagonal always hit exactly one of its two triangles:
/// no crack, no double hit.
#[test]
fn flat_quad_diagonal_has_no_crack() {
    let (a, b, c, d) = (
        Vec3A::new(-1.0, -1.0, 0.0),
        Vec3A::new(1.0, 1.0, 0.0),
        Vec3A::new(1.0, -1.0, 0.0),
        Vec3A::new(-1.0, 1.0, 0.0),
    );
    let t1 = Triangle::new(a, c, b).unwrap();
    let t2 = Triangle::new(a, b, d).unwrap();
    let mut n = 0;
    // Interior points of the diagonal (its ends are corners of the quad's outer boundary).
    for i in 1..1000 {
        let f = i as f32 / 1000.0;
        let target = a + f * (b - a);
        for o in [
            Vec3A::new(0.3, -0.2, -5.0),
            Vec3A::new(-2.0, 1.7, 3.0),
            Vec3A::new(1e-3, 2e-3, -1e-2),
        ] {
            let ray = BvhRay::new(Ray::new(o, (target - o).normalize()));
            let hits = [t1, t2]
                .iter()
                .filter(|t| t.intersect(&ray).is_some())
                .count();
            assert_eq!(hits, 1, "ray to {target} from {o}");
            n += 1;
        }
    }
    assert_eq!(n, 2997);
}

/// Grazing rays on a sphere: tangent and near-tangent rays give finite results or misses.
#[test]
fn grazing_sphere_rays_are_finite() {
    let s = Shape::Sphere(Sphere {
        c: Vec3A::new(0.0, 0.0, 10.0),
        r: 1.0,
    });
    for i in 0..10_000 {
        let y = 1.0 - 1e-7 * i as f32;
        let ray = Ray::new(Vec3A::new(-10.0, y, 10.0), Vec3A::X);
        if let Some(t) = s.intersect(&ray) {
            let surf = s.surface(&ray, t);
            assert!(t.is_finite() && surf.p.is_finite() && surf.n.is_finite());
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// Every path that intersects spheres and planes agrees: the scalar shape test, the SIMD
    /// packets (a scene of at most 16 spheres), and the BVH (a scene of more), for camera rays
    /// and for rays spawned off a first hit (the start rule included).
    #[test]
    fn scalar_packets_and_bvh_agree(
        (s, spheres, o, d, w) in scale().prop_flat_map(|s| (
            Just(s),
            proptest::collection::vec((point(s), 0.05f32..1.0), 1..4),
            point(3.0 * s),
            unit(),
            unit(),
        ))
    ) {
        let shapes: Vec<Shape> = spheres
            .iter()
            .map(|&(c, r)| Shape::Sphere(Sphere { c, r: r * s }))
            .chain([Shape::Plane(Plane::through(Vec3A::new(0.0, -2.0 * s, 0.0), Vec3A::Y))])
            .collect();
        let prims = |shapes: &[Shape]| -> Vec<Prim> {
            shapes.iter().map(|&shape| Prim::flat(shape)).collect()
        };
        let packed = Geometry::build(prims(&shapes), Vec::new());
        // Padding the scene to 17 spheres (far away) sends its spheres to the BVH.
        let mut many = shapes.clone();
        for i in 0..17 {
            many.push(Shape::Sphere(Sphere { c: Vec3A::new(1e3 * s, i as f32 * s, 0.0), r: 0.01 * s }));
        }
        let bvh = Geometry::build(prims(&many), Vec::new());
        prop_assert!(!packed.spheres.packs.is_empty() && bvh.in_bvh > 0);
        // The BVH in every other instruction set this CPU runs gives the baseline's answers to
        // the bit.
        let mut baseline = bvh.clone();
        assert!(baseline.bvh.set_isa(rtis::accel::Isa::Baseline));
        let isas: Vec<Geometry> = rtis::accel::Isa::all_available()
            .into_iter()
            .skip(1)
            .map(|isa| {
                let mut g = bvh.clone();
                assert!(g.bvh.set_isa(isa));
                g
            })
            .collect();
        let scalar = |ray: &Ray| -> Option<(usize, f32)> {
            shapes.iter().enumerate().filter_map(|(i, sh)| sh.intersect(ray).map(|t| (i, t)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        let camera = Ray::new(o, d);
        let mut rays = vec![camera];
        if let Some(h) = packed.intersect(&camera) {
            let w = if w.dot(h.n) * h.n.dot(-d) >= 0.0 { w } else { -w };
            rays.push(Ray::spawn(&h, w, f32::INFINITY));
        }
        for ray in rays {
            let want = scalar(&ray).map(|(_, t)| t);
            let got_packed = packed.intersect(&ray).map(|h| h.t);
            let got_bvh = bvh.intersect(&ray).map(|h| h.t);
            // The whole record, to the bit: its point and normal are made in each set's body.
            let bits = |h: Hit| {
                let v = |v: Vec3A| v.to_array().map(f32::to_bits);
                (h.prim, h.t.to_bits(), v(h.p), v(h.n), h.err.to_bits(), h.err_along.to_bits())
            };
            let want_bits = baseline.intersect(&ray).map(bits);
            for g in &isas {
                let hit = g.intersect(&ray).map(bits);
                prop_assert_eq!(hit, want_bits, "{:?}", g.bvh.isa());
                prop_assert_eq!(g.occluded(&ray), baseline.occluded(&ray), "{:?}", g.bvh.isa());
            }
            prop_assert_eq!(want, got_packed, "packets");
            prop_assert_eq!(want.is_some(), got_bvh.is_some(), "BVH");
            if let (Some(a), Some(b)) = (want, got_bvh) {
                prop_assert!((a - b).abs() <= 1e-6 * a.abs().max(s), "BVH t {} vs {}", b, a);
            }
        }
    }
}

/// A ray from (0, 0, -5) along +z meets the unit sphere at the origin at t = 4 exactly, in the
/// scalar test, the SIMD packets and the BVH; and the near root, not the far one.
#[test]
fn unit_sphere_is_hit_at_four_in_every_path() {
    let sphere = Shape::Sphere(Sphere {
        c: Vec3A::ZERO,
        r: 1.0,
    });
    let ray = Ray::new(Vec3A::new(0.0, 0.0, -5.0), Vec3A::Z);
    assert_eq!(sphere.intersect(&ray), Some(4.0));
    let prim = Prim::flat(sphere);
    let packed = Geometry::build(vec![prim], Vec::new());
    assert_eq!(packed.intersect(&ray).map(|h| h.t), Some(4.0));
    let far = |i: usize| {
        Prim::flat(Shape::Sphere(Sphere {
            c: Vec3A::new(100.0, i as f32, 0.0),
            r: 0.1,
        }))
    };
    let bvh = Geometry::build(
        std::iter::once(prim).chain((0..20).map(far)).collect(),
        Vec::new(),
    );
    assert!(bvh.in_bvh > 0);
    assert_eq!(bvh.intersect(&ray).map(|h| h.t), Some(4.0));
}

fn tri(a: (f32, f32), b: (f32, f32), c: (f32, f32)) -> Triangle {
    let p = |(x, y): (f32, f32)| Vec3A::new(x, y, 0.0);
    Triangle::new(p(a), p(b), p(c)).unwrap()
}

/// Which of `tris` a ray along `dz` (+1 or -1) through `(x, y)` meets.
fn owners(tris: &[Triangle], x: f32, y: f32, dz: f32) -> Vec<usize> {
    let ray = Ray::new(Vec3A::new(x, y, -dz), Vec3A::new(0.0, 0.0, dz));
    (0..tris.len())
        .filter(|&i| Shape::Triangle(tris[i]).intersect(&ray).is_some())
        .collect()
}

/// A ray exactly through an edge shared by two triangles meets exactly one of them, from both
/// sides, and the owner is the triangle for which the edge is a top or left edge in the ray's
/// sheared frame. Worked by hand for a ray along +z through (0.5, 0.5), on the diagonal of
/// the unit square split into A = (0,0),(1,0),(1,1) and B = (0,0),(1,1),(0,1): both
/// determinants are -1; A's edge function on the diagonal is zero with the edge vector
/// (1, 1) after the sign flip, a left edge (y up), so A keeps it; B sees the edge as (-1, -1)
/// and drops it. A horizontal edge, (0,0)-(1,0), shared by A' above and B' below: A' sees it
/// as (-1, 0), a top edge; B' as (1, 0), not one. Vertices shared by a fan of triangles belong
/// to exactly one of them too.
#[test]
fn shared_edges_and_vertices_have_exactly_one_owner() {
    let diagonal = [
        tri((0., 0.), (1., 0.), (1., 1.)),
        tri((0., 0.), (1., 1.), (0., 1.)),
    ];
    let horizontal = [
        tri((0., 0.), (1., 0.), (0.5, 1.)),
        tri((1., 0.), (0., 0.), (0.5, -1.)),
    ];
    // From below, the owner worked by hand; from above, exactly one.
    for (name, pair, below, above) in [
        ("diagonal", diagonal, (0.5, 0.5), (0.25, 0.25)),
        ("horizontal edge", horizontal, (0.5, 0.0), (0.25, 0.0)),
    ] {
        assert_eq!(
            owners(&pair, below.0, below.1, 1.0),
            vec![0],
            "{name} from below"
        );
        assert_eq!(
            owners(&pair, above.0, above.1, -1.0).len(),
            1,
            "{name} from above"
        );
    }
    // A 2 x 2 grid of squares, each split on its diagonal: 8 triangles around (1, 1), with
    // shared edges along x, along y and diagonal, crossed from both sides at dyadic points.
    let mut grid = Vec::new();
    for (i, j) in [(0., 0.), (1., 0.), (0., 1.), (1., 1.)] {
        grid.push(tri((i, j), (i + 1., j), (i + 1., j + 1.)));
        grid.push(tri((i, j), (i + 1., j + 1.), (i, j + 1.)));
    }
    for dz in [1.0, -1.0] {
        for (x, y) in [
            (1.0, 1.0),
            (0.5, 1.0),
            (1.5, 1.0),
            (1.0, 0.5),
            (1.0, 1.5),
            (0.5, 0.5),
            (1.25, 1.25),
            (0.75, 1.75),
        ] {
            let hit = owners(&grid, x, y, dz);
            assert_eq!(hit.len(), 1, "({x}, {y}) along z {dz}: met by {hit:?}");
        }
    }
}

/// Hits are accepted in `(0, t_max]`: a ray whose `t_max` is exactly the distance to a shape
/// still meets it (a shadow ray may end on its light), and one a hair shorter does not.
#[test]
fn t_max_is_inclusive() {
    let shapes = [
        Shape::Triangle(
            Triangle::new(
                Vec3A::new(-1., -1., 4.),
                Vec3A::new(1., -1., 4.),
                Vec3A::new(0., 1., 4.),
            )
            .unwrap(),
        ),
        Shape::Plane(Plane::through(Vec3A::new(0., 0., 4.), Vec3A::Z)),
        Shape::Sphere(Sphere {
            c: Vec3A::new(0., 0., 5.),
            r: 1.0,
        }),
    ];
    for shape in shapes {
        let at = |t_max: f32| shape.intersect(&Ray::segment(Vec3A::ZERO, Vec3A::Z, t_max));
        assert_eq!(at(4.0), Some(4.0), "{shape:?}");
        assert_eq!(at(4.0f32.next_down()), None, "{shape:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// An oriented plane (`Plane::side`) is tested alike by the scalar code and the packets,
    /// for origins on the plane (within its band), just off it on either side, and away from
    /// it; and within the band only a ray leaving the plane's side meets it, at once.
    #[test]
    fn oriented_planes_agree_in_scalar_and_packets(
        (s, p0, n, d, parallel, side, off, o_err) in scale().prop_flat_map(|s| (
            Just(s),
            point(s),
            unit(),
            unit(),
            any::<bool>(),
            prop_oneof![Just(-1.0f32), Just(0.0), Just(1.0)],
            prop_oneof![Just(0.0f32), -1e-6f32..1e-6, -1e-3f32..1e-3, -1.0f32..1.0],
            prop_oneof![Just(0.0f32), 0.0f32..1e-5],
        ))
    ) {
        let plane = Plane::through(p0, n).oriented(side);
        // Some rays run parallel to the plane (`n.d` zero or nearly).
        let d = if parallel { (d - d.dot(n) * n).normalize_or(n.any_orthonormal_vector()) } else { d };
        let ray = Ray {
            o_err: o_err * s,
            ..Ray::new(p0 + off * s * n, d)
        };
        let scalar = Shape::Plane(plane).intersect(&ray);
        let g = Geometry::build(vec![Prim::flat(Shape::Plane(plane))], Vec::new());
        prop_assert_eq!(scalar, g.intersect(&ray).map(|h| h.t));
        let signed = plane.n.dot(ray.o) - plane.dist;
        if signed.abs() <= plane.band(&ray) {
            // On the plane: met at once exactly when leaving the oriented side.
            let leaving = side * plane.n.dot(d) < 0.0;
            prop_assert_eq!(scalar.is_some(), leaving);
            if let Some(t) = scalar {
                prop_assert!(t > 0.0 && t <= 2.0 * plane.band(&ray) / plane.n.dot(d).abs());
            }
        }
    }
}

/// Degenerate rays get the same answer from the scalar test and the packets, oriented or not:
/// a NaN or infinite origin, a NaN direction, and a direction along the plane (`n.d = 0`),
/// which never meets it.
#[test]
fn oriented_planes_treat_degenerate_rays_alike() {
    for side in [-1.0, 0.0, 1.0] {
        let plane = Plane::through(Vec3A::ZERO, Vec3A::Y).oriented(side);
        let g = Geometry::build(vec![Prim::flat(Shape::Plane(plane))], Vec::new());
        let rays = [
            Ray::new(Vec3A::new(f32::NAN, 0.0, 0.0), -Vec3A::Y),
            Ray::new(Vec3A::new(0.0, f32::INFINITY, 0.0), -Vec3A::Y),
            Ray::new(Vec3A::new(0.0, f32::NAN, 0.0), Vec3A::Y),
            Ray::new(Vec3A::ZERO, Vec3A::X),
            Ray::new(Vec3A::ZERO, Vec3A::new(f32::NAN, 0.0, 0.0)),
        ];
        for ray in &rays {
            let scalar = Shape::Plane(plane).intersect(ray);
            assert_eq!(
                scalar.map(f32::to_bits),
                g.intersect(ray).map(|h| h.t.to_bits())
            );
        }
        assert_eq!(
            Shape::Plane(plane).intersect(&rays[3]),
            None,
            "along the plane"
        );
    }
}
