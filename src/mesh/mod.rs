//! Triangle meshes: Wavefront OBJ loading and a procedural generator for tests and benchmarks.

mod generate;
mod obj;

pub use generate::{displaced_sphere, vertex_normals, write_obj};
pub use obj::load_obj;

use glam::Vec3;

/// An indexed triangle mesh in scene coordinates (double precision is not needed for vertex
/// data: meshes are small relative to f32 range, and prepare works camera-relative).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex unit normals (same indexing as `positions`), empty for flat shading.
    pub normals: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub faces: Vec<[u32; 3]>,
}
