//! Leaf blocks (src/accel/block.rs): four primitives tested in lanes give exactly what the
//! scalar loop over them gives (the same primitive at the bit-identical distance, the same
//! any-hit answer), on rays aimed at random points, vertices and edges, rays that start on a
//! triangle of the block, and blocks that mix spheres with triangles.

use crate::common;

use glam::{Vec3, Vec3A};
use rtis::accel::Prim;
use rtis::accel::block::{Block, BlockRay, lane_triangle};
use rtis::geometry::{BvhRay, Hit, Ray};
use rtis::mesh::displaced_sphere;
use rtis::sampling::Sampler;
use rtis::sampling::warp::uniform_sphere;
use rtis::shape::{Shape, Sphere, Triangle};

/// The scalar loop the block stands for.
fn scalar(prims: &[Prim], r: &Ray) -> Option<(u32, f32)> {
    common::nearest(prims, r)
}

thread_local! {
    /// Hits on lane triangles that [`closest`] saw, and how many came with their normal.
    static LANE_HITS: std::cell::Cell<(usize, usize)> = const { std::cell::Cell::new((0, 0)) };
}

/// [`Block::closest`]'s lane and distance, after checking the normal it returns: present only
/// for a lane that holds a triangle, and then [`Block::triangle`]'s normal to the bit; a lane
/// triangle without one was decided by the scalar test, which must find the same distance.
/// Counts both kinds in `LANE_HITS`.
fn closest(block: &Block, others: &[Prim], r: &BvhRay, t_max: f32) -> Option<(u32, f32)> {
    let (lane, t, n) = block.closest(others, &BlockRay::new(r), r, t_max)?;
    let Some(tri) = block.triangle(lane as usize) else {
        assert!(
            n.is_none(),
            "a normal for lane {lane}, which holds no triangle"
        );
        return Some((lane, t));
    };
    LANE_HITS.with(|c| {
        let (hits, normals) = c.get();
        c.set((hits + 1, normals + n.is_some() as usize));
    });
    if let Some(n) = n {
        // The triangle rebuilt with the normal handed over is the lane's, to the bit.
        let bits =
            |t: Triangle| [t.v[0], t.v[1], t.v[2], t.n].map(|v| v.to_array().map(f32::to_bits));
        let with = block.triangle_with_normal(lane as usize, n);
        assert_eq!(bits(with), bits(tri), "lane {lane}: {tri:?}");
    } else {
        // Left to the scalar test: a ray through an edge or a vertex of its triangle (an edge
        // function exactly zero there).
        let reach = BvhRay {
            ray: Ray { t_max, ..r.ray },
            ..*r
        };
        assert_eq!(
            tri.intersect(&reach),
            Some(t),
            "lane {lane} decided by the scalar test"
        );
    }
    Some((lane, t))
}

/// Check one ray against the block of all of `prims` (at most four); returns whether it hit.
fn agree(prims: &[Prim], ray: &Ray) -> bool {
    let r = ray.for_bvh(ray.t_max).sheared();
    let (block, others) = block_of(prims);
    let br = BlockRay::new(&r);
    let expect = scalar(prims, &r);
    assert_eq!(
        closest(&block, &others, &r, r.t_max),
        expect,
        "{r:?} {prims:?}"
    );
    // The reach comes from the argument alone, for triangle and scalar lanes: the ray's own
    // `t_max` (the query's first reach, in the renderer) is not read.
    for own in [f32::INFINITY, f32::MIN_POSITIVE] {
        let other = BvhRay {
            ray: Ray {
                t_max: own,
                ..r.ray
            },
            ..r
        };
        let found = closest(&block, &others, &other, r.t_max);
        assert_eq!(found, expect, "own t_max {own}: {r:?} {prims:?}");
    }
    assert_eq!(block.any(&others, &br, &r), expect.is_some(), "{r:?}");
    expect.is_some()
}

/// The block of `prims` and the array that holds its lanes' whole primitives.
fn block_of(prims: &[Prim]) -> (Block, Vec<Prim>) {
    let others = prims
        .iter()
        .filter(|p| lane_triangle(p).is_none())
        .copied()
        .collect();
    let leaf: Vec<&Prim> = prims.iter().collect();
    (Block::new(&leaf, 0), others)
}

/// A block gives back each triangle with the same vertices and normal, to the bit (the
/// renderer keeps BVH triangles nowhere else), and no triangle for other lanes.
#[test]
fn blocks_give_back_their_triangles_exactly() {
    let mesh = displaced_sphere(2_000, Vec3::ZERO, 1.0, 0.05);
    let all = Prim::flat_triangles(&mesh);
    for chunk in all.chunks(4) {
        let (block, _) = block_of(chunk);
        for (lane, p) in chunk.iter().enumerate() {
            let Shape::Triangle(t) = p.shape else {
                unreachable!()
            };
            let back = block.triangle(lane).expect("a triangle lane");
            let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
            assert_eq!(t.v.map(bits), back.v.map(bits));
            assert_eq!(bits(t.n), bits(back.n));
            // The normal the lanes compute for the band test.
            let n = block.normals().map(|a| a.to_array()[lane]);
            assert_eq!(bits(t.n), bits(Vec3A::from_array(n)), "lane normal");
        }
        assert!(block.triangle(chunk.len()).is_none() || chunk.len() == 4);
    }
    let sphere = Prim::flat(Shape::Sphere(Sphere {
        c: Vec3A::ZERO,
        r: 1.0,
    }));
    let (block, others) = block_of(&[sphere, all[0], sphere]);
    assert!(block.triangle(0).is_none() && block.triangle(1).is_some());
    assert_eq!((block.other_index(0), block.other_index(2)), (0, 1));
    assert_eq!(others.len(), 2);
    // A triangle built through its fields with another normal than `Triangle::new` gives is
    // kept whole, for the scalar test, as is one of zero area.
    let Shape::Triangle(mut odd) = all[0].shape else {
        unreachable!()
    };
    odd.n = -odd.n;
    let flat = Triangle {
        v: [Vec3A::ZERO, Vec3A::X, Vec3A::X],
        n: Vec3A::Z,
    };
    for t in [odd, flat] {
        let p = Prim::flat(Shape::Triangle(t));
        assert!(lane_triangle(&p).is_none());
        let (block, others) = block_of(&[all[1], p]);
        assert!(block.triangle(1).is_none() && block.scalar == 0b10);
        assert_eq!(others.len(), 1);
    }
}

fn tri(a: Vec3A, b: Vec3A, c: Vec3A) -> Prim {
    Prim::flat(Shape::Triangle(Triangle::new(a, b, c).unwrap()))
}

/// Rays from random points at distances 1e-3 to 10 towards random points of a random
/// triangle of the block, its vertices and its edges' midpoints, and rays spawned from the hit
/// points (which start on a triangle of the block), over blocks of 1 to 4 neighbouring
/// triangles of a mesh.
#[test]
fn blocks_agree_with_the_scalar_loop_on_aimed_and_spawned_rays() {
    let mesh = displaced_sphere(4_000, Vec3::ZERO, 1.0, 0.05);
    let all = Prim::flat_triangles(&mesh);
    let mut s = Sampler::new(11, 0, 0);
    let (mut hits, mut spawned_hits, mut cases) = (0, 0, 0);
    LANE_HITS.with(|c| c.set((0, 0)));
    for (n, chunk) in all.chunks(4).enumerate().take(800) {
        let prims = &chunk[..1 + n % chunk.len()];
        for _ in 0..8 {
            let k = (s.next_f32() * prims.len() as f32) as usize % prims.len();
            let Shape::Triangle(t) = prims[k].shape else {
                unreachable!()
            };
            let (b1, b2) = (s.next_f32(), s.next_f32());
            let (b1, b2) = if b1 + b2 > 1.0 {
                (1.0 - b1, 1.0 - b2)
            } else {
                (b1, b2)
            };
            let targets = [
                t.v[0] + b1 * (t.v[1] - t.v[0]) + b2 * (t.v[2] - t.v[0]),
                t.v[(n / 4) % 3],
                0.5 * (t.v[n % 3] + t.v[(n + 1) % 3]),
            ];
            for target in targets {
                let dist = 10f32.powf(s.next_f32() * 4.0 - 3.0);
                let o = target + dist * uniform_sphere(s.next_f32(), s.next_f32());
                let ray = Ray::new(o, (target - o).normalize());
                cases += 1;
                if agree(prims, &ray) {
                    hits += 1;
                    // A ray leaving the hit point, in any direction.
                    let r = ray.for_bvh(ray.t_max).sheared();
                    let (i, t) = scalar(prims, &r).unwrap();
                    let surf = prims[i as usize].shape.surface(&r, t);
                    let hit = Hit {
                        t,
                        p: surf.p,
                        n: surf.n,
                        err: surf.err,
                        err_along: surf.err_along,
                        prim: i,
                    };
                    let w = uniform_sphere(s.next_f32(), s.next_f32());
                    spawned_hits += agree(prims, &Ray::spawn(&hit, w, f32::INFINITY)) as usize;
                }
            }
        }
    }
    // Rays at interior points hit; those at vertices and edges on the block's border may pass
    // it by the top-left rule (measured: 12,158 of 19,200 hit). Spawned rays hit a neighbour
    // now and then.
    assert!(hits * 2 > cases, "{hits} of {cases}");
    assert!(spawned_hits > 0, "no spawned ray met a neighbour");
    // The lane test decides most hits and hands over their normal (measured: 34,317 of
    // 37,014; the others are rays aimed at vertices and edges, left to the scalar test).
    let (lane_hits, normals) = LANE_HITS.with(|c| c.get());
    assert!(
        lane_hits > 30_000 && normals * 10 > lane_hits * 8,
        "{normals} normals for {lane_hits} lane hits"
    );
}

/// A ray through a vertex or edge shared by two triangles of a block hits exactly one of them
/// (the lanes' edge functions are exactly zero there, so the scalar top-left rule decides):
/// axis-aligned rays through every vertex, edge midpoint and quarter point of a 1 x 1 grid of
/// two triangles, from both sides, and diagonal ones.
#[test]
fn shared_edges_and_vertices_go_to_exactly_one_lane() {
    let (a, b, c, d) = (Vec3A::ZERO, Vec3A::X, Vec3A::new(1., 1., 0.), Vec3A::Y);
    let quad = [tri(a, b, c), tri(a, c, d)];
    for x in 0..=4 {
        for y in 0..=4 {
            let p = Vec3A::new(x as f32 / 4.0, y as f32 / 4.0, 0.0);
            for dir in [Vec3A::Z, -Vec3A::Z, Vec3A::new(0.3, 0.4, -1.0).normalize()] {
                let ray = Ray::new(p - 2.0 * dir, dir);
                let inside = (1..4).contains(&x) && (1..4).contains(&y);
                let hit = agree(&quad, &ray);
                // Each triangle in a block of its own: inside the square, exactly one owns
                // the point, whether on the shared diagonal or not.
                let owners = quad
                    .iter()
                    .filter(|t| agree(std::slice::from_ref(t), &ray))
                    .count();
                if inside {
                    assert!(hit && owners == 1, "{owners} owners of {p} along {dir}");
                }
            }
        }
    }
}

/// Lanes that hold spheres go to the scalar test; the nearest of triangles and spheres wins
/// whichever lane it is in, and padding lanes never hit.
#[test]
fn blocks_mixing_spheres_and_triangles() {
    let sphere = |z: f32| {
        Prim::flat(Shape::Sphere(Sphere {
            c: Vec3A::new(0.0, 0.0, z),
            r: 0.5,
        }))
    };
    let square = |z: f32| {
        tri(
            Vec3A::new(-1., -1., z),
            Vec3A::new(1., -1., z),
            Vec3A::new(0., 1., z),
        )
    };
    let orders = [
        vec![sphere(3.0), square(1.0), sphere(-3.0), square(-1.0)],
        vec![square(1.0), sphere(0.0)],
        vec![sphere(0.0)],
        vec![square(2.0), square(2.0), square(-2.0)],
    ];
    for prims in &orders {
        for (o, d) in [(5.0, -1.0), (-5.0, 1.0), (0.2, 1.0), (0.2, -1.0)] {
            let ray = Ray::new(Vec3A::new(0.05, 0.1, o), Vec3A::new(0.0, 0.0, d));
            agree(prims, &ray);
            agree(prims, &Ray::segment(ray.o, ray.d, 3.5));
        }
    }
    // Coincident triangles: the later lane wins the tie, as in the loop.
    let r = Ray::new(Vec3A::new(0.1, 0.0, 5.0), -Vec3A::Z)
        .for_bvh(f32::INFINITY)
        .sheared();
    let (block, others) = block_of(&orders[3]);
    assert_eq!(closest(&block, &others, &r, r.t_max), Some((1, 3.0)));
}

/// A ray that starts on a lane's triangle (within its self-intersection band) meets it first,
/// a hair away, and must go on to the next lane it meets: [`Block::closest`] picks the nearest
/// lane met before checking the band, and falls back to the others when that lane fails it.
/// Stacks of parallel triangles at z = 1000, 999 and 998, in several orders, seen from above
/// and from starts 1.2e-4 above each (rounded to the float grid there, 6.1e-5 apart): the band
/// there is about 6e-4 (it grows with the coordinates, `gamma(5)` times their sum), so each
/// start is on the triangle below it.
#[test]
fn a_ray_starting_on_the_nearest_lane_goes_on_to_the_next() {
    let at = |z: f32| {
        tri(
            Vec3A::new(-1., -1., z),
            Vec3A::new(1., -1., z),
            Vec3A::new(0., 1., z),
        )
    };
    let stacks: [&[f32]; 4] = [
        &[1000.0, 999.0],
        &[999.0, 1000.0],
        &[998.0, 1000.0, 999.0],
        &[1000.0],
    ];
    let (mut fell_back, mut none) = (0, 0);
    for zs in stacks {
        let prims: Vec<Prim> = zs.iter().map(|&z| at(z)).collect();
        let (block, others) = block_of(&prims);
        for start in [1000.5, 1000.0 + 1.2e-4, 999.0 + 1.2e-4, 998.0 + 1.2e-4] {
            let ray = Ray::new(Vec3A::new(0.05, 0.1, start), -Vec3A::Z);
            agree(&prims, &ray);
            // The lane by hand: the first triangle below the start by more than the band.
            let r = ray.for_bvh(ray.t_max).sheared();
            let below = zs
                .iter()
                .enumerate()
                .filter(|&(_, &z)| z < start - 1e-3)
                .max_by(|a, b| a.1.total_cmp(b.1))
                .map(|(lane, _)| lane as u32);
            let found = closest(&block, &others, &r, r.t_max);
            assert_eq!(found.map(|f| f.0), below, "stack {zs:?}, start {start}");
            let on = zs.iter().any(|&z| z < start && z > start - 1e-3);
            fell_back += (on && below.is_some()) as usize;
            none += (on && below.is_none()) as usize;
        }
    }
    // The rays cover both ways on: a start on a triangle with another below it, and on the
    // last one (4 and 4 of the 16).
    assert_eq!((fell_back, none), (4, 4));
}
