//! Batched ray queries (`src/accel/batch.rs`): rays in the SIMD lanes (four with SSE, eight
//! with AVX2) against one primitive at a time give what the one-ray queries give, to the bit,
//! in every instruction set the CPU runs, on random scenes of spheres and planes (and, through
//! the BVH, triangles) at scales from 1e-3 to 1e5, for rays from anywhere and rays leaving a
//! hit, where the error bands decide; small scenes of triangles in AVX-512 lanes too
//! (`src/accel/small.rs`). Coherent rays in packets through the BVH
//! (`Geometry::intersect_coherent`, `src/accel/wide/packet.rs`) give the one-ray hits too,
//! shared edges and their ties included.

use glam::Vec3A;
use proptest::prelude::*;
use rtis::accel::{Geometry, Isa, Prim, SMALL_SCENE, Traversal, require_all_isas};
use rtis::geometry::{Hit, Ray};
use rtis::shape::{Plane, Shape, Sphere, Triangle};

fn unit() -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-degenerate", |(x, y, z)| x * x + y * y + z * z > 1e-3)
        .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize())
}

fn point(s: f32) -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(move |(x, y, z)| Vec3A::new(x, y, z) * s)
}

/// A scene at scale `s`: up to 16 spheres (packed) and up to 9 planes; with `triangles`, a few
/// triangles too, which put the scene in a BVH.
fn scene(s: f32, triangles: bool) -> impl Strategy<Value = Vec<Prim>> {
    let sphere = (point(s), 0.05f32..1.0)
        .prop_map(move |(c, r)| Prim::flat(Shape::Sphere(Sphere { c, r: r * s })));
    // Some planes oriented (a ray leaving their side within the band meets them), as
    // extraction orients a room's walls.
    let plane = (point(s), unit(), -1i32..=1).prop_map(|(p, n, side)| {
        let plane = Plane::through(p, n);
        let plane = if side == 0 {
            plane
        } else {
            plane.oriented(side as f32)
        };
        Prim::flat(Shape::Plane(plane))
    });
    let triangle = (point(s), point(s), point(s)).prop_filter_map("zero area", |(a, b, c)| {
        Triangle::new(a, b, c).map(|t| Prim::flat(Shape::Triangle(t)))
    });
    let tris = if triangles { 1..6usize } else { 0..1usize };
    (
        prop::collection::vec(sphere, 0..17),
        prop::collection::vec(plane, 0..10),
        prop::collection::vec(triangle, tris),
    )
        .prop_map(|(mut a, b, c)| {
            a.extend(b);
            a.extend(c);
            a
        })
}

fn scale() -> impl Strategy<Value = f32> {
    prop_oneof![Just(1e-3f32), Just(1.0), Just(1e3), Just(1e5)]
}

/// Rays from `origins` along `dirs`, each followed by a ray leaving its hit (if any) along the
/// next direction, on either side; every third one a segment, as shadow rays are.
fn rays(g: &Geometry, origins: &[Vec3A], dirs: &[Vec3A], s: f32) -> Vec<Ray> {
    let mut out = Vec::new();
    for (k, (&o, &d)) in origins.iter().zip(dirs).enumerate() {
        let t_max = if k % 3 == 0 {
            s * (k as f32 + 0.5) * 0.3
        } else {
            f32::INFINITY
        };
        let ray = Ray::segment(o, d, t_max);
        out.push(ray);
        if let Some(hit) = g.intersect(&Ray::new(o, d)) {
            let w = dirs[(k + 1) % dirs.len()];
            out.push(Ray::spawn(&hit, w, t_max));
        }
    }
    out
}

/// `g` with its queries in each instruction set this CPU runs.
fn each_isa(mut g: Geometry) -> impl Iterator<Item = (Isa, Geometry)> {
    require_all_isas();
    Isa::all_available().into_iter().map(move |isa| {
        assert!(g.bvh.set_isa(isa));
        (isa, g.clone())
    })
}

fn bits(h: &Option<Hit>) -> Option<(u32, [u32; 9])> {
    h.map(|h| {
        let v = [
            h.t,
            h.p.x,
            h.p.y,
            h.p.z,
            h.n.x,
            h.n.y,
            h.n.z,
            h.err,
            h.err_along,
        ];
        (h.prim, v.map(f32::to_bits))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// The nearest hit of each ray of a batch is the one-ray query's, field for field.
    #[test]
    fn batched_nearest_hits_are_the_one_ray_hits(
        (s, prims, origins, dirs, triangles) in (scale(), any::<bool>()).prop_flat_map(|(s, tri)| (
            Just(s),
            scene(s, tri),
            prop::collection::vec(point(2.0 * s), 1..24),
            prop::collection::vec(unit(), 24),
            Just(tri),
        ))
    ) {
        let g = Geometry::build(prims, Vec::new());
        let rays = rays(&g, &origins, &dirs, s);
        for (isa, g) in each_isa(g) {
            let mut hits = Vec::new();
            g.intersect_batch(&rays, &mut hits);
            prop_assert_eq!(hits.len(), rays.len());
            for (k, (ray, hit)) in rays.iter().zip(&hits).enumerate() {
                prop_assert_eq!(bits(hit), bits(&g.intersect(ray)), "{:?}: ray {} of {} (triangles: {})", isa, k, rays.len(), triangles);
            }
        }
    }

    /// Each shadow ray of a batch is blocked exactly when the one-ray query says so, with the
    /// planes tested or skipped.
    #[test]
    fn batched_shadow_rays_are_the_one_ray_answers(
        (s, prims, origins, dirs, planes) in (scale(), any::<bool>()).prop_flat_map(|(s, tri)| (
            Just(s),
            scene(s, tri),
            prop::collection::vec(point(2.0 * s), 1..24),
            prop::collection::vec(unit(), 24),
            any::<bool>(),
        ))
    ) {
        let g = Geometry::build(prims, Vec::new());
        let rays = rays(&g, &origins, &dirs, s);
        for (isa, g) in each_isa(g) {
            let mut blocked = Vec::new();
            g.occluded_batch(&rays, planes, &mut blocked);
            prop_assert_eq!(blocked.len(), rays.len());
            for (k, ray) in rays.iter().enumerate() {
                let one = if planes { g.occluded(ray) } else { g.occluded_in_room(ray) };
                prop_assert_eq!(blocked[k], one, "{:?}: ray {} of {}", isa, k, rays.len());
            }
        }
    }
}

/// Triangles only (a BVH scene): up to 300 at scale `s`, many small ones so that the tree has
/// levels.
fn triangles(s: f32) -> impl Strategy<Value = Vec<Prim>> {
    let small = (point(s), point(0.1 * s), point(0.1 * s))
        .prop_filter_map("zero area", |(a, b, c)| {
            Triangle::new(a, a + b, a + c).map(|t| Prim::flat(Shape::Triangle(t)))
        });
    prop::collection::vec(small, 1..300)
}

/// Rays from one origin (a pinhole) through a `w` x `h` grid of directions spanning `[-f, f]`
/// around `axis`, row by row, as a camera's; every fifth a segment of reach `t_max`.
fn camera_rays(o: Vec3A, axis: Vec3A, f: f32, (w, h): (u32, u32), t_max: f32) -> Vec<Ray> {
    let frame = rtis::geometry::Frame::from_normal(axis);
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            let local = Vec3A::new(
                f * (2.0 * x / w as f32 - 1.0),
                f * (2.0 * y / h as f32 - 1.0),
                1.0,
            );
            let d = frame.to_world(local.normalize());
            if i % 5 == 0 {
                Ray::segment(o, d, t_max)
            } else {
                Ray::new(o, d)
            }
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Coherent rays traced in packets find the one-ray hits, field for field: a camera's
    /// rays from anywhere (some crossing octants within a packet, some segments), and the
    /// rays leaving their hits.
    #[test]
    fn coherent_packets_find_the_one_ray_hits(
        (s, prims, o, axis, f, t) in scale().prop_flat_map(|s| (
            Just(s),
            triangles(s),
            point(2.0 * s),
            unit(),
            0.01f32..1.5,
            0.1f32..3.0,
        ))
    ) {
        let g = Geometry::build(prims, Vec::new());
        let mut rays = camera_rays(o, axis, f, (13, 9), t * s);
        let dirs: Vec<Vec3A> = rays.iter().map(|r| r.d).collect();
        rays.extend(rays.clone().iter().zip(dirs.iter().rev()).filter_map(|(r, &w)| {
            g.intersect(r).map(|hit| Ray::spawn(&hit, w, f32::INFINITY))
        }));
        for (isa, g) in each_isa(g) {
            let mut hits = Vec::new();
            g.intersect_coherent(&rays, &mut hits);
            prop_assert_eq!(hits.len(), rays.len());
            for (k, (ray, hit)) in rays.iter().zip(&hits).enumerate() {
                prop_assert_eq!(bits(hit), bits(&g.intersect(ray)), "{:?}: ray {} of {}", isa, k, rays.len());
            }
        }
    }
}

/// A tessellated square on z = 0, `n` x `n` squares of side 1 from `at`, two triangles each.
fn grid(n: u32, at: Vec3A) -> Vec<Prim> {
    let v = |i: u32, j: u32| at + Vec3A::new(i as f32, j as f32, 0.0);
    let mut prims = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for (a, b, c) in [
                (v(i, j), v(i + 1, j), v(i + 1, j + 1)),
                (v(i, j), v(i + 1, j + 1), v(i, j + 1)),
            ] {
                prims.push(Prim::flat(Shape::Triangle(Triangle::new(a, b, c).unwrap())));
            }
        }
    }
    prims
}

/// Rays straight down (`-z`, its `x` and `y` negative zeros) through a `(2n + 1)^2` lattice
/// of step 1/2 from the origin: the vertices, edges' midpoints and diagonals' midpoints of
/// [`grid`]`(n, 0)`, row by row.
fn lattice_rays(n: u32) -> Vec<Ray> {
    (0..(2 * n + 1) * (2 * n + 1))
        .map(|k| {
            let (x, y) = (
                (k % (2 * n + 1)) as f32 * 0.5,
                (k / (2 * n + 1)) as f32 * 0.5,
            );
            Ray::new(Vec3A::new(x, y, 3.0), -Vec3A::Z)
        })
        .collect()
}

/// A tessellated square seen straight on through its vertices and edges, with rays parallel
/// to two axes: each edge belongs to one of its triangles (the top-left rule), and every ray
/// inside the square meets one, in packets as alone. The node test once dropped these: an
/// origin exactly on a box's side along a parallel direction gave the exit `0 * MAX = 0`
/// (`RayBox::o_exit`), and a packet's bounds inherit the one-ray arithmetic.
#[test]
fn rays_along_edges_meet_the_triangle_that_owns_the_edge() {
    let n = 16;
    let rays = lattice_rays(n);
    let w = 2 * n as usize + 1;
    for (isa, g) in each_isa(Geometry::build(grid(n, Vec3A::ZERO), Vec::new())) {
        for len in [rays.len(), 3] {
            let rays = &rays[..len];
            let mut hits = Vec::new();
            g.intersect_coherent(rays, &mut hits);
            assert_eq!(hits.len(), len);
            for (k, (ray, hit)) in rays.iter().zip(&hits).enumerate() {
                assert_eq!(bits(hit), bits(&g.intersect(ray)), "{isa:?}: ray {k}");
                let inside = (1..w - 1).contains(&(k % w)) && (1..w - 1).contains(&(k / w));
                if inside {
                    assert!(hit.is_some(), "{isa:?}: ray {k} fell through");
                    assert_eq!(hit.unwrap().t, 3.0);
                }
            }
        }
    }
}

/// Two tessellated squares in one plane, the second shifted by a quarter square: every ray
/// meets a triangle of each at the same distance, often in two leaves, where the one-ray rule
/// keeps the one it visited last. The packet traversal sees these ties (the test counts
/// them) and sends those rays to the one-ray query, so every hit is the one-ray hit.
#[test]
fn packets_send_their_ties_to_the_one_ray_query() {
    use rtis::accel::wide::packet::{PACKET, octant};
    use rtis::geometry::BvhRay;
    let n = 16;
    let mut prims = grid(n, Vec3A::ZERO);
    prims.extend(grid(n - 1, Vec3A::new(0.25, 0.25, 0.0)));
    let rays = lattice_rays(n);
    for (isa, g) in each_isa(Geometry::build(prims, Vec::new())) {
        let mut hits = Vec::new();
        g.intersect_coherent(&rays, &mut hits);
        for (k, (ray, hit)) in rays.iter().zip(&hits).enumerate() {
            assert_eq!(bits(hit), bits(&g.intersect(ray)), "{isa:?}: ray {k}");
        }
        // The ties, counted from the packets themselves.
        let mut tied = 0;
        for chunk in rays.chunks(PACKET) {
            let boxes: Vec<BvhRay> = chunk.iter().map(|r| BvhRay::boxes(*r)).collect();
            let refs: [&BvhRay; PACKET] = std::array::from_fn(|i| &boxes[i.min(boxes.len() - 1)]);
            let live = (1 << chunk.len()) - 1;
            let found = g.bvh.closest_packet(
                &refs,
                live,
                octant(refs[0]),
                |i: usize, b: u32, t_max: f32| {
                    let full = refs[i].sheared();
                    let br = rtis::accel::block::BlockRay::new(&full);
                    g.blocks[b as usize]
                        .closest(&g.others, &br, &full, t_max)
                        .map(|(lane, t, _)| (4 * b + lane, t))
                },
                &(),
            );
            tied += found.tied.count_ones();
        }
        assert!(tied > 100, "{isa:?}: only {tied} ties");
    }
}

/// The batches cover every length, not only multiples of four, and an empty batch.
#[test]
fn batches_of_every_length() {
    let prims = vec![
        Prim::flat(Shape::Sphere(Sphere {
            c: Vec3A::new(0.0, 0.0, 5.0),
            r: 1.0,
        })),
        Prim::flat(Shape::Plane(Plane::through(
            Vec3A::new(0.0, 0.0, 9.0),
            Vec3A::Z,
        ))),
    ];
    for (_, g) in each_isa(Geometry::build(prims, Vec::new())) {
        for n in 0..18 {
            let rays: Vec<Ray> = (0..n)
                .map(|k| {
                    Ray::new(
                        Vec3A::ZERO,
                        Vec3A::new(k as f32 * 0.1, 0.0, 1.0).normalize(),
                    )
                })
                .collect();
            let (mut hits, mut blocked) = (Vec::new(), Vec::new());
            g.intersect_batch(&rays, &mut hits);
            g.occluded_batch(&rays, true, &mut blocked);
            assert_eq!((hits.len(), blocked.len()), (n, n));
            for (k, ray) in rays.iter().enumerate() {
                assert_eq!(bits(&hits[k]), bits(&g.intersect(ray)));
                assert_eq!(blocked[k], g.occluded(ray));
            }
        }
    }
}

/// Two copies of a primitive meet a ray at the same distance: the later one wins, in a batch
/// as in the one-ray query.
#[test]
fn equal_distances_go_to_the_later_primitive() {
    let sphere = Shape::Sphere(Sphere {
        c: Vec3A::new(0.0, 0.0, 5.0),
        r: 1.0,
    });
    let plane = Shape::Plane(Plane::through(Vec3A::new(0.0, 0.0, 9.0), Vec3A::Z));
    let g = Geometry::build(
        [sphere, sphere, plane, plane].map(Prim::flat).to_vec(),
        Vec::new(),
    );
    // Through the spheres, and past them onto the planes.
    let rays: Vec<Ray> = [0.0, 0.1, 0.5, 0.9, 0.05, 0.7, 0.2, 0.3, 0.6]
        .iter()
        .map(|&x| Ray::new(Vec3A::ZERO, Vec3A::new(x, 0.0, 1.0).normalize()))
        .collect();
    for (isa, g) in each_isa(g) {
        let mut hits = Vec::new();
        g.intersect_batch(&rays, &mut hits);
        let mut seen = std::collections::BTreeSet::new();
        for (ray, hit) in rays.iter().zip(&hits) {
            let one = g.intersect(ray);
            assert_eq!(bits(hit), bits(&one), "{isa:?}");
            seen.insert(one.expect("every ray hits").prim);
        }
        // The later copy of each took every hit: the second sphere (1) and the second plane (3),
        // at their index among the packed primitives (spheres first).
        let offset = g.attrs.len() as u32;
        let want: std::collections::BTreeSet<u32> = [offset + 1, offset + 3].into();
        assert_eq!(seen, want, "{isa:?}");
    }
}

/// Shadow rays built in lanes (`Geometry::occluded_lanes`, as the Global shader's light pass
/// builds them): each live lane answers as the one-ray query does, the others answer false,
/// in each instruction set, with and without the planes, also for zero and NaN directions.
#[test]
fn rays_in_lanes_answer_as_one_ray_queries_and_only_where_live() {
    let prims = vec![
        Prim::flat(Shape::Sphere(Sphere {
            c: Vec3A::new(0.0, 0.0, 5.0),
            r: 1.0,
        })),
        Prim::flat(Shape::Sphere(Sphere {
            c: Vec3A::new(2.0, 1.0, 4.0),
            r: 0.5,
        })),
        Prim::flat(Shape::Plane(
            Plane::through(Vec3A::new(0.0, 0.0, 9.0), -Vec3A::Z).oriented(1.0),
        )),
    ];
    let rays: Vec<Ray> = (0..16)
        .map(|k| {
            // The upper eight mix rays blocked by either sphere with rays that miss both.
            let d = match k {
                6 => Vec3A::ZERO,
                7 => Vec3A::NAN,
                8 => Vec3A::new(-0.1, 0.0, 5.0).normalize(),
                9 => Vec3A::new(0.9, -0.5, 1.0).normalize(),
                10 => Vec3A::new(1.9, 1.0, 4.0).normalize(),
                11 => Vec3A::new(-0.8, 0.6, 1.0).normalize(),
                12 => Vec3A::new(0.3, 0.5, 5.0).normalize(),
                13 => -Vec3A::Z,
                14 => Vec3A::new(0.85, 0.0, 5.0).normalize(),
                15 => Vec3A::new(0.0, 1.0, 0.2).normalize(),
                _ => Vec3A::new(k as f32 * 0.12 - 0.3, 0.05 * k as f32, 1.0).normalize(),
            };
            Ray {
                o_err: 1e-6 * k as f32,
                ..Ray::segment(Vec3A::new(0.1, 0.0, 0.0), d, 4.0 + k as f32)
            }
        })
        .collect();
    let lane = |f: fn(&Ray) -> f32| -> [f32; 16] { std::array::from_fn(|i| f(&rays[i])) };
    let parts = [
        lane(|r| r.o.x),
        lane(|r| r.o.y),
        lane(|r| r.o.z),
        lane(|r| r.d.x),
        lane(|r| r.d.y),
        lane(|r| r.d.z),
        lane(|r| r.o_err),
        lane(|r| r.t_max),
    ];
    for (_, g) in each_isa(Geometry::build(prims.clone(), Vec::new())) {
        for planes in [false, true] {
            let one: Vec<bool> = rays
                .iter()
                .map(|r| {
                    if planes {
                        g.occluded(r)
                    } else {
                        g.occluded_in_room(r)
                    }
                })
                .collect();
            assert!(one.iter().any(|&b| b) && one.iter().any(|&b| !b), "{one:?}");
            // Both answers in the upper half too, so that its lanes are told apart.
            let upper = &one[8..];
            assert!(
                upper.iter().any(|&b| b) && upper.iter().any(|&b| !b),
                "{one:?}"
            );
            // Four SSE lanes: rays 0 to 3, 4 to 7 and so on; lanes 1 and 2 not live.
            for first in [0, 4, 8, 12] {
                // SAFETY: `Vec4` runs on every CPU.
                unsafe { in_lanes::<glam::Vec4>(&g, &parts, first, 0b1001, planes, &one) };
            }
            // Eight AVX2 lanes, rays 0 to 7 then 8 to 15; lanes 1 and 4 not live.
            #[cfg(target_arch = "x86_64")]
            if rtis::accel::Isa::Avx2.available() {
                for first in [0, 8] {
                    let live = 0b1110_1101;
                    // SAFETY: AVX2 is present (checked just above).
                    unsafe { in_lanes::<rtis::accel::F8>(&g, &parts, first, live, planes, &one) };
                }
            }
            // Sixteen AVX-512 lanes; lanes 1, 4, 8 and 11 not live.
            #[cfg(target_arch = "x86_64")]
            if rtis::accel::Isa::Avx512.available() {
                let live = 0b1111_0110_1110_1101;
                // SAFETY: AVX-512F is present (checked just above).
                unsafe { in_lanes::<rtis::accel::F16>(&g, &parts, 0, live, planes, &one) };
            }
        }
    }
}

/// `occluded_lanes` on rays `first..first + L::LANES` of `parts` (their origin, direction,
/// origin error and `t_max`, a row each) with the lanes of `live` asked: the live lanes answer
/// as the one-ray queries (`one`), the others false.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
unsafe fn in_lanes<L: rtis::accel::Floats>(
    g: &Geometry,
    parts: &[[f32; 16]; 8],
    first: usize,
    live: u32,
    planes: bool,
    one: &[bool],
) {
    let v = |k: usize| {
        let mut row = [0.0; 16];
        row[..L::LANES].copy_from_slice(&parts[k][first..first + L::LANES]);
        // SAFETY: the caller vouches for the instruction set.
        unsafe { L::from_array(row) }
    };
    let flags: [f32; 16] = std::array::from_fn(|i| (live >> i & 1) as f32);
    // SAFETY: as above.
    let live_mask = unsafe { L::from_array(flags).cmpne(L::splat(0.0)) };
    let m = g.occluded_lanes(
        ([v(0), v(1), v(2)], [v(3), v(4), v(5)], v(6), v(7)),
        planes,
        live_mask,
        &(),
    );
    let want: u32 = (0..L::LANES)
        .filter(|&i| live >> i & 1 == 1 && one[first + i])
        .map(|i| 1 << i)
        .sum();
    assert_eq!(
        L::bitmask(m),
        want,
        "{} lanes from ray {first}, planes {planes}",
        L::LANES
    );
}

/// A unit direction with two or three coordinates of equal magnitude, the largest.
fn tied_unit() -> impl Strategy<Value = Vec3A> {
    (0usize..3, -1i32..=1, any::<bool>(), any::<bool>()).prop_map(|(axis, third, s1, s2)| {
        let sign = |s: bool| if s { -1.0 } else { 1.0 };
        let mut v = [third as f32; 3];
        v[axis] = sign(s1);
        v[(axis + 1) % 3] = sign(s2);
        Vec3A::from_array(v).normalize()
    })
}

/// A small scene (`src/accel/small.rs`): up to [`SMALL_SCENE`] triangles at scale `s`, large
/// and small, some sharing an edge.
fn small_scene(s: f32) -> impl Strategy<Value = Vec<Prim>> {
    let triangle = (point(s), point(s), point(s), 0.05f32..1.0).prop_filter_map(
        "zero area",
        move |(a, b, c, size)| {
            let (b, c) = (a + (b - a) * size, a + (c - a) * size);
            let t = Triangle::new(a, b, c)?;
            // Its neighbour across the edge `bc`, folded a little.
            let d = b + c - a + t.n * (0.3 * size * s);
            let pair = [t, Triangle::new(c, b, d)?];
            Some(pair.map(|t| Prim::flat(Shape::Triangle(t))))
        },
    );
    prop::collection::vec(triangle, 1..=SMALL_SCENE / 2).prop_map(|v| v.concat())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// In a small scene, rays in lanes meet every triangle (not the BVH), and each ray's
    /// nearest hit and shadow answer are the one-ray query's, field for field; directions
    /// with two equal largest coordinates included, where the axes' choice breaks a tie. In
    /// AVX-512 lanes, no ray of these was left to the one-ray query (the BVH's node tests
    /// count those: each tests one node at least).
    #[test]
    fn small_scenes_answer_in_lanes_as_one_ray_queries(
        (s, prims, origins, dirs) in scale().prop_flat_map(|s| (
            Just(s),
            small_scene(s),
            prop::collection::vec(point(2.0 * s), 1..40),
            prop::collection::vec(prop_oneof![unit(), tied_unit()], 40),
        ))
    ) {
        let g = Geometry::build(prims, Vec::new());
        let rays = rays(&g, &origins, &dirs, s);
        for (isa, g) in each_isa(g) {
            prop_assert_eq!(g.is_small(), isa == Isa::Avx512);
            let (mut hits, mut blocked) = (Vec::new(), Vec::new());
            let (near, shadow) = (Traversal::default(), Traversal::default());
            g.intersect_batch_tallied(&rays, &mut hits, Some(&near));
            g.occluded_batch_tallied(&rays, true, &mut blocked, Some(&shadow));
            if g.is_small() && rays.len() >= 20 {
                let alone = near.nodes.get() + shadow.nodes.get();
                prop_assert!(alone < rays.len() as u64, "{} node tests", alone);
            }
            prop_assert_eq!(hits.len(), rays.len());
            prop_assert_eq!(blocked.len(), rays.len());
            for (k, (ray, hit)) in rays.iter().zip(&hits).enumerate() {
                prop_assert_eq!(bits(hit), bits(&g.intersect(ray)), "{:?}: ray {} of {}", isa, k, rays.len());
                prop_assert_eq!(blocked[k], g.occluded(ray), "{:?}: shadow ray {} of {}", isa, k, rays.len());
            }
        }
    }
}

/// A small scene seen straight down through the vertices, edges and diagonals of a
/// tessellated square, with a second one a quarter square aside in the same plane: its rays
/// meet edges (an edge function exactly zero, which the lanes leave to the one-ray test's
/// top-left rule) and two triangles at the same distance (a tie, which they leave to the
/// one-ray walk's order). Every answer is the one-ray query's, and every ray inside the first
/// square meets it at 3.
#[test]
fn small_scenes_leave_edges_and_ties_to_the_one_ray_query() {
    let n = 4;
    let (first, second) = (
        grid(n, Vec3A::ZERO),
        grid(n - 1, Vec3A::new(0.25, 0.25, 0.0)),
    );
    assert_eq!(first.len() + second.len(), 32 + 18);
    let mut rays = lattice_rays(n);
    let w = 2 * n as usize + 1;
    let on_lattice = rays.len();
    // Rays off every edge of both squares, through both where they overlap: ties.
    for i in 0..4 * n {
        for j in 0..4 * n - 1 {
            let (x, y) = (0.1 + 0.25 * i as f32, 0.3 + 0.25 * j as f32);
            rays.push(Ray::new(Vec3A::new(x, y, 3.0), -Vec3A::Z));
        }
    }
    // Both orders of the two squares: the lanes keep the later triangle of a tie, the walk
    // the one it visits last.
    let scenes = [[&first, &second], [&second, &first]].map(|[a, b]| [a.as_slice(), b].concat());
    for (isa, g) in scenes
        .into_iter()
        .flat_map(|s| each_isa(Geometry::build(s, Vec::new())))
    {
        assert_eq!(g.is_small(), isa == Isa::Avx512);
        let (mut hits, mut blocked) = (Vec::new(), Vec::new());
        let alone = Traversal::default();
        g.intersect_batch_tallied(&rays, &mut hits, Some(&alone));
        g.occluded_batch(&rays, true, &mut blocked);
        // The lanes left edges and ties to the one-ray query (its node tests count them).
        if g.is_small() {
            assert!(alone.nodes.get() > 0, "{isa:?}: no ray alone");
        }
        for (k, (ray, hit)) in rays.iter().zip(&hits).enumerate() {
            assert_eq!(bits(hit), bits(&g.intersect(ray)), "{isa:?}: ray {k}");
            assert_eq!(blocked[k], g.occluded(ray), "{isa:?}: shadow ray {k}");
            let inside =
                k >= on_lattice || (1..w - 1).contains(&(k % w)) && (1..w - 1).contains(&(k / w));
            if inside {
                let t = hit.map_or(0.0, |h| h.t);
                assert!((t - 3.0).abs() <= 1e-6, "{isa:?}: ray {k} at {t}");
                assert!(blocked[k], "{isa:?}: shadow ray {k}");
            }
        }
    }
}

/// A scene is small with up to [`SMALL_SCENE`] triangles and nothing else, where its queries
/// run in AVX-512 lanes.
#[test]
fn small_scenes_hold_few_triangles_and_nothing_else() {
    require_all_isas();
    if !Isa::Avx512.available() {
        let mut g = Geometry::build(grid(2, Vec3A::ZERO), Vec::new());
        for isa in Isa::all_available() {
            assert!(g.bvh.set_isa(isa));
            assert!(!g.is_small(), "{isa:?}");
        }
        return;
    }
    let square = |n: u32| grid(n, Vec3A::ZERO);
    let small = |prims: Vec<Prim>| {
        let mut g = Geometry::build(prims, Vec::new());
        assert!(g.bvh.set_isa(Isa::Avx512));
        g.is_small()
    };
    assert_eq!(square(5).len() + 14, SMALL_SCENE);
    let mut most = square(5);
    most.extend(square(2).into_iter().take(6));
    most.extend(grid(2, Vec3A::Z));
    assert_eq!(most.len(), SMALL_SCENE);
    assert!(small(most.clone()));
    most.push(grid(1, Vec3A::X * 9.0)[0]);
    assert!(!small(most));
    let mut with_sphere = square(2);
    with_sphere.push(Prim::flat(Shape::Sphere(Sphere {
        c: Vec3A::new(0.5, 0.5, 2.0),
        r: 0.25,
    })));
    assert!(!small(with_sphere));
    assert!(!small(Vec::new()));
}
