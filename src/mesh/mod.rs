//! Triangle meshes: Wavefront OBJ and Stanford PLY loading, and a procedural generator for
//! tests and benchmarks.

mod generate;
mod obj;
mod ply;

pub use generate::{angle_weighted_normals, displaced_sphere, vertex_normals, write_obj};
pub use obj::load_obj;
pub use ply::load_ply;

/// Read the mesh at `path`: a PLY file (`.ply`), else a Wavefront OBJ file.
pub fn load(path: &std::path::Path) -> Result<MeshData, String> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("ply") => load_ply(path),
        _ => load_obj(path),
    }
}

use glam::DVec3;

/// An indexed triangle mesh in scene coordinates, in double precision like every other scene
/// coordinate (extraction makes it camera-relative before rounding to `f32`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Per-vertex unit normals (same indexing as `positions`), empty for flat shading.
    pub normals: Vec<DVec3>,
    /// Triangles as indices into `positions`.
    pub faces: Vec<[u32; 3]>,
    /// Per-vertex texture coordinates (same indexing as `positions`), empty when not given.
    /// From OBJ's `vt`, with `v` flipped (`1 - v`), as Mitsuba 3 reads OBJ files: an image's top
    /// row is at `v = 0`.
    pub uvs: Vec<glam::Vec2>,
}
