//! A small scene's triangles tested in lanes (`src/accel/few.rs`): batches of rays give the
//! one-ray queries' answers to the bit, nearest hits and shadow rays, in every instruction set
//! the CPU runs, on random triangle soups up to the size limit at scales from 1e-3 to 1e5 (rays
//! from anywhere and rays leaving a hit, where the self-intersection bands decide), on rays
//! through shared edges and vertices (exact zeros of the edge functions), and where two
//! triangles are met at one distance (the one-ray query keeps the one it visits last); and
//! which scenes take the lanes.

use crate::batch::{bits, each_isa, grid, lattice_rays, point, rays, scale, unit};
use glam::Vec3A;
use proptest::prelude::*;
use rtis::accel::few::FEW;
use rtis::accel::{Geometry, Prim};
use rtis::geometry::Ray;
use rtis::shape::{Shape, Sphere, Triangle};

/// Up to [`FEW`] triangles at scale `s`, large and small.
fn soup(s: f32) -> impl Strategy<Value = Vec<Prim>> {
    let triangle = (point(s), point(s), point(0.2 * s), any::<bool>()).prop_filter_map(
        "zero area",
        |(a, b, c, small)| {
            let (b, c) = if small {
                (a + 0.1 * b, a + c)
            } else {
                (b, a + 4.0 * c)
            };
            Triangle::new(a, b, c).map(|t| Prim::flat(Shape::Triangle(t)))
        },
    );
    prop::collection::vec(triangle, 1..=FEW)
}

/// Every ray of `rays`, in batches, against the one-ray queries.
fn agrees(g: Geometry, rays: &[Ray]) -> Result<(), TestCaseError> {
    prop_assert!(g.few(), "a small scene of triangles takes the lanes");
    for (isa, g) in each_isa(g) {
        let mut hits = Vec::new();
        g.intersect_batch(rays, &mut hits);
        prop_assert_eq!(hits.len(), rays.len());
        let mut blocked = Vec::new();
        g.occluded_batch(rays, true, &mut blocked);
        for (k, (ray, hit)) in rays.iter().zip(&hits).enumerate() {
            prop_assert_eq!(bits(hit), bits(&g.intersect(ray)), "{:?}: ray {}", isa, k);
            prop_assert_eq!(blocked[k], g.occluded(ray), "{:?}: shadow ray {}", isa, k);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Nearest hits and shadow rays of random triangle soups.
    #[test]
    fn lanes_give_the_one_ray_answers(
        (s, prims, origins, dirs) in scale().prop_flat_map(|s| (
            Just(s),
            soup(s),
            prop::collection::vec(point(2.0 * s), 1..40),
            prop::collection::vec(unit(), 40),
        ))
    ) {
        let g = Geometry::build(prims, Vec::new());
        let mut rays = rays(&g, &origins, &dirs, s);
        // Rays from hit points themselves, not moved off their surface: the self-intersection
        // band keeps them from meeting it at their start.
        for (k, &o) in origins.iter().enumerate() {
            if let Some(hit) = g.intersect(&Ray::new(o, dirs[k])) {
                rays.push(Ray::new(hit.p, dirs[(k + 1) % dirs.len()]));
                rays.push(Ray::new(hit.p, -dirs[(k + 1) % dirs.len()]));
            }
        }
        agrees(g, &rays)?;
    }
}

/// Rays straight down through the vertices and edges of a tessellated square (edge functions
/// exactly zero: the scalar test's top-left rule decides), and through two such squares in
/// one plane, one shifted by a quarter (ties: two triangles met at one distance). Changing
/// either rule of `few.rs` (the lanes' answer where an edge function is zero, the tie sent
/// to the one-ray query) fails this.
#[test]
fn edges_and_ties_go_to_the_one_ray_query() {
    let rays = lattice_rays(4);
    agrees(Geometry::build(grid(4, Vec3A::ZERO), Vec::new()), &rays).unwrap();
    let mut prims = grid(4, Vec3A::ZERO);
    prims.extend(grid(3, Vec3A::new(0.25, 0.25, 0.0)));
    assert!(prims.len() <= FEW);
    let g = Geometry::build(prims, Vec::new());
    // Rays through the inside of the triangles of both squares too (not on an edge).
    let mut rays = rays;
    for k in 0..100 {
        let (x, y) = (0.3 + 0.031 * k as f32, 0.35 + 0.029 * (k * 7 % 100) as f32);
        rays.push(Ray::new(Vec3A::new(x, y, 3.0), -Vec3A::Z));
    }
    // The ties are there: some ray meets two triangles at one distance.
    let ties = rays
        .iter()
        .filter(|r| {
            let hits: Vec<f32> = g
                .indices()
                .filter_map(|i| match g.prim(i).shape {
                    Shape::Triangle(t) => t.intersect(&r.for_bvh(r.t_max).sheared()),
                    _ => None,
                })
                .collect();
            hits.iter()
                .any(|&t| hits.iter().filter(|&&u| u == t).count() > 1)
        })
        .count();
    assert!(ties > 10, "only {ties} ties");
    agrees(g, &rays).unwrap();
}

/// The lanes are for scenes of at most [`FEW`] primitives, all triangles: not one more, not
/// with a sphere.
#[test]
fn only_small_scenes_of_triangles_take_the_lanes() {
    let tri = |k: usize| {
        let a = Vec3A::new(k as f32, 0.0, 0.0);
        Prim::flat(Shape::Triangle(
            Triangle::new(a, a + Vec3A::X, a + Vec3A::Y).unwrap(),
        ))
    };
    let few: Vec<Prim> = (0..FEW).map(tri).collect();
    assert!(Geometry::build(few.clone(), Vec::new()).few());
    let more: Vec<Prim> = (0..=FEW).map(tri).collect();
    assert!(!Geometry::build(more, Vec::new()).few());
    let mut sphere = few;
    sphere.pop();
    sphere.push(Prim::flat(Shape::Sphere(Sphere {
        c: Vec3A::new(0.0, 0.0, -3.0),
        r: 1.0,
    })));
    assert!(!Geometry::build(sphere, Vec::new()).few());
}
