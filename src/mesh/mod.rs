//! Triangle meshes: Wavefront OBJ loading and a procedural generator for tests and benchmarks.

mod generate;
mod obj;

pub use generate::{displaced_sphere, vertex_normals, write_obj};
pub use obj::load_obj;

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
}
