//! The primitive: a render shape with its material, vertex normals and area light, the form
//! extraction hands to [`super::Geometry::build`].

use crate::shape::{Shape, Triangle};

/// A shape with the index of its material.
#[derive(Clone, Copy, Debug)]
pub struct Prim {
    /// Geometry.
    pub shape: Shape,
    /// Index into the prepared material array.
    pub material: u32,
    /// A triangle's corner attributes (vertex normals, texture coordinates), or [`FLAT`] for
    /// none: an index into the normals (and coordinates) passed to
    /// [`Geometry::build`](super::Geometry::build), and in the primitives [`Geometry::prim`](super::Geometry::prim) returns, into
    /// [`Geometry::normals`](super::Geometry::normals).
    pub smooth: u32,
    /// Index of the primitive's area light in the render's `Emitters`, or
    /// [`crate::light::NO_LIGHT`].
    pub light: u32,
}

impl Prim {
    /// A primitive of material 0, shaded with its geometric normal, emitting nothing: the form
    /// benchmarks and tests build geometry in.
    pub fn flat(shape: Shape) -> Self {
        Prim {
            shape,
            material: 0,
            smooth: FLAT,
            light: crate::light::NO_LIGHT,
        }
    }

    /// The non-degenerate triangles of `mesh` as [`Prim::flat`] primitives, in its own
    /// coordinates (for benchmarks and tests; scenes go through extraction).
    pub fn flat_triangles(mesh: &crate::mesh::MeshData) -> Vec<Prim> {
        mesh.faces
            .iter()
            .filter_map(|f| {
                let [a, b, c] = f.map(|i| mesh.positions[i as usize].as_vec3a());
                Triangle::new(a, b, c).map(|t| Prim::flat(Shape::Triangle(t)))
            })
            .collect()
    }
}

/// [`Prim::smooth`] of a primitive shaded with its geometric normal.
pub const FLAT: u32 = u32::MAX;
