//! Ray queries over the prepared geometry: packets of four planes and (in small scenes) four
//! spheres tested with SSE, and a BVH over the remaining finite primitives.

pub mod block;
mod bvh;
pub mod lanes;
pub mod wide;

pub use bvh::{Bvh, Node};
pub use wide::{WideBvh, WideNode};

use crate::geometry::{Hit, Ray};
use crate::shape::{Shape, ShapeKind, Triangle};
use block::{Block, BlockRay};
use lanes::{Lanes, PlaneLanes, RayLanes, SphereLanes};

/// A shape with the index of its material.
#[derive(Clone, Copy, Debug)]
pub struct Prim {
    /// Geometry.
    pub shape: Shape,
    /// Index into the prepared material array.
    pub material: u32,
    /// Index into [`Geometry::normals`] of a smooth triangle's vertex normals, or [`FLAT`].
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

/// Scenes with at most this many spheres test them in packets instead of a BVH.
pub const PACKED_SPHERES: usize = 16;

/// Append packed primitives to `all`; returns each shape with its index there.
fn append<T>(all: &mut Vec<Prim>, packed: Vec<(Prim, T)>) -> Vec<(u32, T)> {
    packed
        .into_iter()
        .map(|(p, shape)| {
            all.push(p);
            ((all.len() - 1) as u32, shape)
        })
        .collect()
}

/// All of a scene's primitives, ready for ray queries.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// Every primitive; hits refer to indices here. The first `in_bvh` are the BVH's, in leaf
    /// order; the packed spheres and the planes follow.
    pub prims: Vec<Prim>,
    /// How many of `prims` the BVH holds.
    pub in_bvh: usize,
    /// Four-wide BVH over `prims[..in_bvh]`; a leaf's payload indexes `blocks`.
    pub bvh: WideBvh,
    /// The BVH's leaves, each with its triangles in lanes.
    pub blocks: Vec<Block>,
    /// Spheres in packets of four (small scenes).
    pub spheres: Lanes<SphereLanes>,
    /// Infinite planes in packets of four.
    pub planes: Lanes<PlaneLanes>,
    /// Vertex normals of smooth triangles.
    pub normals: Vec<[glam::Vec3A; 3]>,
    /// True if the BVH holds triangles: its rays then need the watertight test's shear
    /// constants.
    pub has_triangles: bool,
}

impl Geometry {
    /// Sort the primitives into packets and a BVH; `normals` holds the vertex normals that
    /// smooth primitives refer to.
    pub fn build(prims: Vec<Prim>, normals: Vec<[glam::Vec3A; 3]>) -> Self {
        let n_spheres = prims
            .iter()
            .filter(|p| p.shape.kind() == ShapeKind::Sphere)
            .count();
        let pack_spheres = n_spheres <= PACKED_SPHERES;
        // One pass: planes to their packets, spheres to theirs in small scenes, the rest to
        // the BVH. The packets keep each shape with its primitive, so no kind is lost.
        let (mut planes, mut spheres) = (Vec::new(), Vec::new());
        let for_bvh: Vec<Prim> = prims
            .into_iter()
            .filter(|p| match p.shape {
                Shape::Plane(pl) => {
                    planes.push((*p, pl));
                    false
                }
                Shape::Sphere(s) if pack_spheres => {
                    spheres.push((*p, s));
                    false
                }
                _ => true,
            })
            .collect();
        let has_triangles = for_bvh
            .iter()
            .any(|p| p.shape.kind() == ShapeKind::Triangle);
        let (binary, mut all) = Bvh::build(for_bvh);
        let mut blocks = Vec::new();
        let bvh = WideBvh::collapse(&binary.nodes, |first, count| {
            blocks.push(Block::new(&all, first, count));
            (blocks.len() - 1) as u32
        });
        let in_bvh = all.len();
        let sphere_items = append(&mut all, spheres);
        let plane_items = append(&mut all, planes);
        Geometry {
            prims: all,
            in_bvh,
            bvh,
            blocks,
            spheres: lanes::pack(&sphere_items, SphereLanes::pack),
            planes: lanes::pack(&plane_items, PlaneLanes::pack),
            normals,
            has_triangles,
        }
    }

    /// The shading normal at point `p` of primitive `prim` whose geometric normal is `n`:
    /// the vertex normals interpolated with `p`'s barycentric coordinates for smooth
    /// triangles, `n` otherwise.
    #[inline]
    pub fn shading_normal(&self, prim: &Prim, p: glam::Vec3A, n: glam::Vec3A) -> glam::Vec3A {
        match (prim.smooth, prim.shape) {
            (FLAT, _) => n,
            (i, Shape::Triangle(t)) => {
                let [n0, n1, n2] = self.normals[i as usize];
                let (e1, e2, ep) = (t.v[1] - t.v[0], t.v[2] - t.v[0], p - t.v[0]);
                let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
                let (d20, d21) = (ep.dot(e1), ep.dot(e2));
                let det = d00 * d11 - d01 * d01;
                let b1 = (d11 * d20 - d01 * d21) / det;
                let b2 = (d00 * d21 - d01 * d20) / det;
                let ns = ((1.0 - b1 - b2) * n0 + b1 * n1 + b2 * n2).normalize_or_zero();
                if ns == glam::Vec3A::ZERO { n } else { ns }
            }
            _ => n,
        }
    }

    /// The primitive a hit refers to.
    #[inline]
    pub fn prim(&self, index: u32) -> &Prim {
        &self.prims[index as usize]
    }

    /// True if the scene has no primitive at all.
    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// Number of primitives of each kind.
    pub fn count(&self, kind: ShapeKind) -> usize {
        self.prims.iter().filter(|p| p.shape.kind() == kind).count()
    }

    /// The nearest hit along `ray` within `(0, ray.t_max]`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut t_max = ray.t_max;
        let mut best: Option<u32> = None;
        let lanes = RayLanes::new(ray);
        self.spheres
            .closest(&lanes, &mut t_max, &mut best, SphereLanes::hit);
        if !self.bvh.nodes.is_empty() {
            let r = ray.for_bvh(t_max, self.has_triangles);
            let br = BlockRay::new(&r);
            let leaf = |b: u32, r: &Ray| self.blocks[b as usize].closest(&self.prims, &br, r);
            if let Some((i, t)) = self.bvh.closest(&r, leaf) {
                t_max = t;
                best = Some(i);
            }
        }
        self.planes
            .closest(&lanes, &mut t_max, &mut best, PlaneLanes::hit);
        let prim = best?;
        let s = self.prim(prim).shape.surface(ray, t_max);
        Some(Hit {
            t: t_max,
            p: s.p,
            n: s.n,
            err: s.err,
            err_along: s.err_along,
            prim,
        })
    }

    /// True if anything blocks `ray` within `(0, ray.t_max]` (any-hit query for shadow rays).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let lanes = RayLanes::new(ray);
        self.spheres.any(&lanes, ray.t_max, SphereLanes::hit)
            || self.planes.any(&lanes, ray.t_max, PlaneLanes::hit)
            || (!self.bvh.nodes.is_empty() && {
                let r = ray.for_bvh(ray.t_max, self.has_triangles);
                let br = BlockRay::new(&r);
                self.bvh
                    .any(&r, |b, r| self.blocks[b as usize].any(&self.prims, &br, r))
            })
    }
}
