//! rtis's BVH against obvhs 0.4 (CWBVH, `fast_build` and `medium_build`) on the same displaced
//! spheres and the same incoherent rays. Prints one JSON line per BVH and size: build seconds,
//! bytes per triangle (rtis: wide nodes, leaf blocks with the vertices, lane attributes;
//! obvhs: its nodes and primitive indices, without its copy of the triangles), Mrays/s and hits.

use glam::{Vec3, Vec3A};
use obvhs::{BvhBuildParams, cwbvh::builder::build_cwbvh_from_tris, ray::RayHit};
use rayon::prelude::*;
use rtis::accel::block::Block;
use rtis::accel::{Attrs, Geometry, Prim};
use rtis::geometry::Ray;
use rtis::mesh::displaced_sphere;
use rtis::sampling::{Sampler, hemisphere};
use std::time::{Duration, Instant};

fn rays(n: usize) -> Vec<(Vec3A, Vec3A)> {
    let mut s = Sampler::new(1, 2, 3);
    (0..n)
        .map(|_| {
            let o = Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 4.0 - Vec3A::splat(2.0);
            let (u, v) = s.next_2d();
            let mut d = hemisphere::uniform(u, v);
            if s.next_f32() < 0.5 {
                d.z = -d.z;
            }
            (o, d)
        })
        .collect()
}

fn rate(rays: &[(Vec3A, Vec3A)], f: impl Fn(Vec3A, Vec3A) -> bool + Sync) -> (f64, usize) {
    let start = Instant::now();
    let hits: usize = rays
        .par_chunks(4096)
        .map(|c| c.iter().filter(|(o, d)| f(*o, *d)).count())
        .sum();
    (rays.len() as f64 / start.elapsed().as_secs_f64() / 1e6, hits)
}

fn main() {
    let rays = rays(1_000_000);
    for n in [10_000usize, 100_000, 1_000_000] {
        let mesh = displaced_sphere(n, Vec3::ZERO, 1.0, 0.05);
        let tris: Vec<[Vec3A; 3]> = mesh
            .faces
            .iter()
            .map(|f| f.map(|i| mesh.positions[i as usize].as_vec3a()))
            .collect();
        // rtis.
        let prims = Prim::flat_triangles(&mesh);
        let count = prims.len();
        let t = Instant::now();
        let g = Geometry::build(prims, Vec::new());
        let build = t.elapsed().as_secs_f64();
        let bytes = (g.bvh.node_bytes()
            + g.blocks.len() * std::mem::size_of::<Block>()
            + g.attrs.len() * std::mem::size_of::<Attrs>()) as f64
            / count as f64;
        let (r, hits) = rate(&rays, |o, d| g.intersect(&Ray::new(o, d)).is_some());
        line(count, "rtis BVH8, float top, quantised", build, bytes, r, hits);
        // obvhs.
        let otris: Vec<obvhs::triangle::Triangle> = tris
            .iter()
            .map(|v| obvhs::triangle::Triangle { v0: v[0], v1: v[1], v2: v[2] })
            .collect();
        for (name, params) in [
            ("obvhs CWBVH fast", BvhBuildParams::fast_build()),
            ("obvhs CWBVH medium", BvhBuildParams::medium_build()),
        ] {
            let t = Instant::now();
            let bvh = build_cwbvh_from_tris(&otris, params, &mut Duration::default());
            let build = t.elapsed().as_secs_f64();
            let bytes = (bvh.nodes.len() * 80 + bvh.primitive_indices.len() * 4) as f64 / count as f64;
            let (r, hits) = rate(&rays, |o, d| {
                let mut hit = RayHit::none();
                bvh.ray_traverse(obvhs::ray::Ray::new_inf(o, d), &mut hit, |ray, id| {
                    otris[bvh.primitive_indices[id] as usize].intersect(ray)
                })
            });
            line(count, name, build, bytes, r, hits);
        }
    }
}

/// One JSON line of results.
fn line(triangles: usize, bvh: &str, build_s: f64, bytes: f64, mrays: f64, hits: usize) {
    println!(
        "{{\"triangles\": {triangles}, \"bvh\": \"{bvh}\", \"build_s\": {build_s:.4}, \
         \"bytes_per_triangle\": {bytes:.1}, \"incoherent_mrays\": {mrays:.2}, \"hits\": {hits}}}"
    );
}
