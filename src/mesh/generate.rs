//! A procedural mesh: a displaced UV sphere of about N triangles, so tests and benchmarks need
//! no committed mesh files.

use super::MeshData;
use glam::{DVec3, Vec3};
use std::f32::consts::{PI, TAU};
use std::io::Write;
use std::path::Path;

/// A UV sphere of radius `radius` at `center` with about `triangles` triangles, its radius
/// displaced by a smooth deterministic bump pattern of relative amplitude `bump`, with
/// area-weighted vertex normals of the displaced surface.
pub fn displaced_sphere(triangles: usize, center: Vec3, radius: f32, bump: f32) -> MeshData {
    // A sphere of r rings and s = 2r segments has 2 s (r - 1) triangles.
    let rings = ((triangles as f64 / 4.0).sqrt().round() as usize).max(3);
    let segments = 2 * rings;
    let mut mesh = MeshData::default();
    let vertex = |theta: f32, phi: f32| {
        let dir = Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        );
        let h = 1.0
            + bump
                * ((7.0 * theta).sin() * (5.0 * phi).cos()
                    + 0.5 * (13.0 * phi + 3.0 * theta).sin());
        center + dir * radius * h
    };
    // Poles, then rings 1..rings-1 of `segments` vertices each.
    mesh.positions.push(vertex(0.0, 0.0).as_dvec3());
    mesh.positions.push(vertex(PI, 0.0).as_dvec3());
    for i in 1..rings {
        let theta = PI * i as f32 / rings as f32;
        for j in 0..segments {
            mesh.positions
                .push(vertex(theta, TAU * j as f32 / segments as f32).as_dvec3());
        }
    }
    let at = |i: usize, j: usize| (2 + (i - 1) * segments + j % segments) as u32;
    for j in 0..segments {
        mesh.faces.push([0, at(1, j + 1), at(1, j)]);
        mesh.faces.push([1, at(rings - 1, j), at(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
            mesh.faces.push([a, b, d]);
            mesh.faces.push([a, d, c]);
        }
    }
    mesh.normals = vertex_normals(&mesh.positions, &mesh.faces);
    mesh
}

/// Area-weighted vertex normals: the sum of the (unnormalised) normals of the faces around each
/// vertex, normalised.
pub fn vertex_normals(positions: &[DVec3], faces: &[[u32; 3]]) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; positions.len()];
    for f in faces {
        let [a, b, c] = f.map(|i| positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in f {
            n[i as usize] += face;
        }
    }
    n.into_iter().map(DVec3::normalize_or_zero).collect()
}

/// Angle-weighted vertex normals (Thurmer and Wuthrich, "Computing vertex normals from
/// polygonal facets", JGT 1998; Mitsuba 3's for meshes without normals): each face adds its unit
/// normal to each of its corners, weighted by its interior angle there, and the sums are
/// normalised; a vertex that no face of area uses gets `(1, 0, 0)`, as Mitsuba's (it shades
/// nothing, and a normal is a direction).
pub fn angle_weighted_normals(positions: &[DVec3], faces: &[[u32; 3]]) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; positions.len()];
    for f in faces {
        let p = f.map(|i| positions[i as usize]);
        let Some(face) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else {
            continue;
        };
        for k in 0..3 {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let angle = a.angle_between(b);
            if angle.is_finite() {
                n[f[k] as usize] += face * angle;
            }
        }
    }
    n.into_iter().map(|v| v.normalize_or(DVec3::X)).collect()
}

/// Write a mesh as Wavefront OBJ (positions, normals if any, 1-based faces).
pub fn write_obj(mesh: &MeshData, path: &Path) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for n in &mesh.normals {
        writeln!(w, "vn {} {} {}", n.x, n.y, n.z)?;
    }
    let smooth = !mesh.normals.is_empty();
    for f in &mesh.faces {
        let [a, b, c] = f.map(|i| i + 1);
        if smooth {
            writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
        } else {
            writeln!(w, "f {a} {b} {c}")?;
        }
    }
    w.flush()
}
