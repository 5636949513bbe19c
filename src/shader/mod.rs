//! The closed set of shaders: what the colour of a camera ray means. Each variant lives in its
//! own file as one function over a [`Tracer`]; [`radiance`] dispatches by `match`.
//!
//! A shader is given only the parts it reads (geometry, materials, lights, background, model,
//! effects, its random numbers and counters), as pbrt's integrators are built from their parts
//! rather than from a scene object. Nothing here knows about RON or hecs.

mod depth;
mod direct;
pub mod global;
mod intersection;
mod normal;
pub mod path;
pub mod record;
pub mod surface;
pub mod warps;

pub use global::Global;
pub use path::Path;
pub use record::{Record, Technique};

use crate::accel::{Geometry, Traversal};
use crate::effects::Effects;
use crate::geometry::{Hit, Ray};
use crate::light::{Emitters, Light};
use crate::material::{Material, Model};
use crate::sampling::Sampler;
use crate::stats::{RayKind, RayStats};
use crate::texture::{Footprint, MaterialTextures};
use glam::Vec3A;

/// Longest chain of consecutive mirror/glass bounces any shader follows.
pub const MAX_SPECULAR: u32 = 1024;

/// A prepared shader with its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shader {
    /// `color` on hits, background on misses.
    Intersection {
        /// Colour of hits.
        color: Vec3A,
    },
    /// `color * max(0, 1 - t / max_distance)` on hits.
    Depth {
        /// Distance where the colour reaches black.
        max_distance: f32,
        /// Colour at distance 0.
        color: Vec3A,
    },
    /// `(n + 1) / 2` of the viewer-facing unit normal.
    Normal,
    /// Direct light (Eq. 3) at Phong hits; mirrors and glass followed.
    Direct {
        /// Longest chain of consecutive specular bounces, at most [`MAX_SPECULAR`].
        max_specular: u32,
        /// Area-light samples per shading point.
        light_samples: u32,
    },
    /// The assignment's global shader (Eq. 1-4).
    Global(Global),
    /// The reference path tracer.
    Path(Path),
}

/// An observer of every ray a shader traces, told each ray with its kind where the ray is
/// counted ([`RayStats`]), whichever code traces it: the one-ray queries, the waves' batches and
/// their rays in lanes. For tests (`tests/integration/origins.rs` checks that every spawned ray starts on
/// the side of the surface it leaves towards); renders leave it unset, at the cost of one
/// predictable branch per ray.
pub type RayAudit = fn(&Ray, RayKind);

/// What one camera sample needs while it is traced: the parts of the scene it reads, its
/// random numbers and its counters.
pub struct Tracer<'a> {
    /// Primitives and their acceleration structures.
    pub geometry: &'a Geometry,
    /// Materials, indexed by `Prim::material`.
    pub materials: &'a [Material],
    /// The textures of the materials at the same indices (empty when none is textured).
    pub textures: &'a [MaterialTextures],
    /// A sample's footprint on surfaces, for filtering textures.
    pub footprint: Footprint,
    /// Point lights.
    pub lights: &'a [Light],
    /// Area lights, indexed by `Prim::light`.
    pub emitters: &'a Emitters,
    /// Radiance of escaped rays.
    pub background: Vec3A,
    /// Light-transport model.
    pub model: Model,
    /// The effects this render simulates.
    pub effects: Effects,
    /// Random numbers of this (pixel, sample).
    pub sampler: Sampler,
    /// Rays traced so far, by kind.
    pub stats: &'a mut RayStats,
    /// The observer of every ray traced, if any ([`RayAudit`]).
    pub audit: Option<RayAudit>,
    /// The counters of nodes and primitives tested, when an inspected render measures them
    /// (a render leaves it unset: its queries are compiled without counters).
    pub traversal: Option<&'a Traversal>,
}

impl Tracer<'_> {
    /// Count a ray of `kind` that is about to be traced, and show it to the audit if there is
    /// one. Every ray traced one at a time passes here once; the waves' rays in lanes (the
    /// children of `waves/lanes.rs`, the shadow rays of the light pass) are counted and shown
    /// to the audit where they are made, in the same way.
    #[inline]
    pub fn count(&mut self, ray: &Ray, kind: RayKind) {
        self.stats.count(kind);
        if let Some(audit) = self.audit {
            audit(ray, kind);
        }
    }

    /// Count the shadow rays in the lanes of `mask` (origins `o`, directions `d`), made and
    /// tested in lanes, and show them to the audit if there is one, one by one.
    #[inline(always)]
    pub fn count_shadow_lanes<L: crate::accel::Floats>(
        &mut self,
        segments: crate::accel::Segments<L>,
        mask: u32,
    ) {
        self.stats.shadow += u64::from(mask.count_ones());
        let Some(audit) = self.audit else {
            return;
        };
        let rows = crate::accel::SegmentRows::new(segments);
        let mut bits = mask;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            audit(&rows.ray(i), RayKind::Shadow);
        }
    }

    /// Nearest hit of a ray of the given kind (counted).
    #[inline]
    pub fn trace(&mut self, ray: &Ray, kind: RayKind) -> Option<Hit> {
        self.count(ray, kind);
        match self.traversal {
            None => self.geometry.intersect(ray),
            Some(t) => self.geometry.intersect_tallied(ray, t),
        }
    }

    /// True if nothing blocks the shadow ray (counted).
    #[inline]
    pub fn unoccluded(&mut self, ray: &Ray) -> bool {
        self.count(ray, RayKind::Shadow);
        !match self.traversal {
            None => self.geometry.occluded(ray),
            Some(t) => self.geometry.occluded_tallied(ray, true, t),
        }
    }

    /// [`Tracer::unoccluded`] for a shadow ray towards a point light that no plane can hide
    /// ([`Light::in_room`]): the planes are not tested.
    #[inline]
    pub fn unoccluded_in_room(&mut self, ray: &Ray) -> bool {
        self.count(ray, RayKind::Shadow);
        !match self.traversal {
            None => self.geometry.occluded_in_room(ray),
            Some(t) => self.geometry.occluded_tallied(ray, false, t),
        }
    }
}

/// Radiance arriving at the camera along the camera ray `ray` under `shader`, told to `rec`:
/// the path tracer's contributions one by one, every other shader's radiance whole
/// ([`Technique::Shader`]).
#[inline]
pub fn radiance<R: Record>(shader: &Shader, tr: &mut Tracer, ray: &Ray, rec: &mut R) {
    let l = match *shader {
        Shader::Intersection { color } => intersection::radiance(tr, ray, color),
        Shader::Depth {
            max_distance,
            color,
        } => depth::radiance(tr, ray, max_distance, color),
        Shader::Normal => normal::radiance(tr, ray),
        Shader::Direct {
            max_specular,
            light_samples,
        } => direct::radiance(tr, ray, max_specular, light_samples),
        Shader::Global(g) => global::radiance(tr, ray, &g),
        Shader::Path(p) => return path::radiance(tr, ray, &p, rec),
    };
    rec.add(l, Technique::Shader, 0);
}
