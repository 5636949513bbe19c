//! Wavefront OBJ through `tobj`.

use super::MeshData;
use glam::DVec3;
use std::path::Path;

/// Load every object of an OBJ file into one mesh: positions, normals when every vertex has one,
/// faces triangulated. Errors are one line, ready to be placed after the scene location.
pub fn load_obj(path: &Path) -> Result<MeshData, String> {
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Read the file here rather than in tobj, which drops the system's reason ("No such file
    // or directory", "Is a directory", "Permission denied").
    let bytes =
        std::fs::read(path).map_err(|e| format!("cannot read mesh {}: {e}", path.display()))?;
    // Materials (`mtllib`) are not used: the scene gives the material.
    let (models, _materials) = tobj::load_obj_buf(&mut bytes.as_slice(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| match e {
        tobj::LoadError::ReadError => format!(
            "cannot load mesh {}: it is not a text file (not UTF-8)",
            path.display()
        ),
        e => format!("cannot load mesh {}: {e}", path.display()),
    })?;
    let mut mesh = MeshData::default();
    let mut all_normals = true;
    let mut all_uvs = true;
    for m in &models {
        let base = mesh.positions.len() as u32;
        let p = &m.mesh.positions;
        if p.len() % 3 != 0 || m.mesh.indices.len() % 3 != 0 {
            return Err(format!(
                "mesh {}: malformed object `{}`",
                path.display(),
                m.name
            ));
        }
        mesh.positions.extend(
            p.chunks_exact(3)
                .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)),
        );
        let n = &m.mesh.normals;
        if n.len() == p.len() {
            mesh.normals
                .extend(n.chunks_exact(3).map(|c| {
                    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64).normalize_or_zero()
                }));
        } else {
            all_normals = false;
        }
        // Texture coordinates, `v` flipped as Mitsuba reads OBJ files.
        let t = &m.mesh.texcoords;
        if t.len() / 2 == p.len() / 3 && t.len() % 2 == 0 {
            mesh.uvs
                .extend(t.chunks_exact(2).map(|c| glam::Vec2::new(c[0], 1.0 - c[1])));
        } else {
            all_uvs = false;
        }
        mesh.faces.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|f| [base + f[0], base + f[1], base + f[2]]),
        );
    }
    if !all_normals || mesh.normals.contains(&DVec3::ZERO) {
        mesh.normals.clear();
    }
    if !all_uvs {
        mesh.uvs.clear();
    }
    if let Some(bad) = mesh
        .uvs
        .iter()
        .find(|t| !t.is_finite() || t.abs().max_element() > 1e9)
    {
        return Err(format!(
            "mesh {}: texture coordinate ({}, {}) (with v flipped) is not finite or beyond \
             +-1e9",
            path.display(),
            bad.x,
            bad.y
        ));
    }
    if let Some(bad) = mesh
        .positions
        .iter()
        .find(|p| !p.is_finite() || p.abs().max_element() > 1e9)
    {
        return Err(format!(
            "mesh {}: vertex {bad} is not finite or beyond +-1e9 scene units",
            path.display()
        ));
    }
    if mesh.faces.is_empty() {
        return Err(format!("mesh {}: no faces", path.display()));
    }
    let n = mesh.positions.len() as u32;
    if let Some(f) = mesh.faces.iter().find(|f| f.iter().any(|&i| i >= n)) {
        return Err(format!(
            "mesh {}: face {f:?} indexes past {n} vertices",
            path.display()
        ));
    }
    Ok(mesh)
}
