//! Triangle meshes: Wavefront OBJ, Stanford PLY and Mitsuba serialized loading, and a procedural generator for
//! tests and benchmarks.

mod generate;
mod obj;
mod ply;
mod serialized;

pub use generate::{angle_weighted_normals, displaced_sphere, vertex_normals, write_obj};
pub use obj::load_obj;
pub use ply::load_ply;
pub use serialized::load_serialized;

/// Read the mesh at `path`: a PLY file (`.ply`), mesh `index` of a Mitsuba serialized file
/// (`.serialized`), else a Wavefront OBJ file. `index` is for serialized files only.
pub fn load(path: &std::path::Path, index: u32) -> Result<MeshData, String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext.eq_ignore_ascii_case("serialized") {
        return load_serialized(path, index);
    }
    if index != 0 {
        return Err(format!(
            "shape_index {index}: only a .serialized file holds several meshes"
        ));
    }
    if ext.eq_ignore_ascii_case("ply") {
        load_ply(path)
    } else {
        load_obj(path)
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
