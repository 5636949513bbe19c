//! Ray queries over the prepared geometry: a BVH over the finite primitives and a flat list of
//! unbounded ones (infinite planes).

mod bvh;

pub use bvh::{Bvh, Node};

use crate::effects::kernel;
use crate::geometry::{Hit, Ray};
use crate::shape::{Shape, ShapeKind};

/// A shape with the index of its material.
#[derive(Clone, Copy, Debug)]
pub struct Prim {
    /// Geometry.
    pub shape: Shape,
    /// Index into the prepared material array.
    pub material: u32,
}

/// All of a scene's primitives, ready for ray queries.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// Finite primitives, in BVH leaf order.
    pub bounded: Vec<Prim>,
    /// BVH over `bounded`.
    pub bvh: Bvh,
    /// Primitives without bounds, tested one by one. Hit indices continue after `bounded`.
    pub unbounded: Vec<Prim>,
}

impl Geometry {
    /// Builds the BVH over the bounded primitives and sets the unbounded ones apart.
    pub fn build(prims: Vec<Prim>) -> Self {
        let (bounded, unbounded): (Vec<_>, Vec<_>) =
            prims.into_iter().partition(|p| p.shape.bounds().is_some());
        let (bvh, bounded) = Bvh::build(bounded);
        Geometry {
            bounded,
            bvh,
            unbounded,
        }
    }

    /// The primitive a hit refers to.
    #[inline]
    pub fn prim(&self, index: u32) -> &Prim {
        let i = index as usize;
        match self.bounded.get(i) {
            Some(p) => p,
            None => &self.unbounded[i - self.bounded.len()],
        }
    }

    /// Number of primitives of each kind.
    pub fn count(&self, kind: ShapeKind) -> usize {
        self.bounded
            .iter()
            .chain(&self.unbounded)
            .filter(|p| p.shape.kind() == kind)
            .count()
    }

    /// The nearest hit along `ray` within `(0, ray.t_max]`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_in::<{ kernel::ALL }>(ray)
    }

    /// [`Geometry::intersect`] in render kernel `K`.
    #[inline]
    pub fn intersect_in<const K: u32>(&self, ray: &Ray) -> Option<Hit> {
        let mut ray = *ray;
        let mut best: Option<u32> = None;
        if let Some((i, t)) = self.bvh.closest::<K>(&self.bounded, &ray) {
            ray.t_max = t;
            best = Some(i);
        }
        let base = self.bounded.len() as u32;
        for (j, p) in self.unbounded.iter().enumerate() {
            if let Some(t) = p.shape.intersect(&ray) {
                ray.t_max = t;
                best = Some(base + j as u32);
            }
        }
        let prim = best?;
        let s = self.prim(prim).shape.surface(&ray, ray.t_max);
        Some(Hit {
            t: ray.t_max,
            p: s.p,
            n: s.n,
            err: s.err,
            prim,
        })
    }

    /// True if anything blocks `ray` within `(0, ray.t_max]` (any-hit query for shadow rays).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_in::<{ kernel::ALL }>(ray)
    }

    /// [`Geometry::occluded`] in render kernel `K`.
    #[inline]
    pub fn occluded_in<const K: u32>(&self, ray: &Ray) -> bool {
        self.unbounded
            .iter()
            .any(|p| p.shape.intersect(ray).is_some())
            || self.bvh.any::<K>(&self.bounded, ray)
    }
}
