//! The closed set of shaders: what the colour of a camera ray means. Each variant lives in its
//! own file as one function over the [`RenderScene`]; [`radiance`] dispatches by `match`.
//!
//! Nothing here knows about RON or hecs.

mod depth;
mod direct;
pub mod global;
mod intersection;
mod normal;
pub mod path;
pub mod surface;

pub use global::Global;
pub use path::{Path, Sampling};

use crate::geometry::{Hit, Ray};
use crate::prepare::RenderScene;
use crate::render::stats::{RayKind, RayStats};
use crate::sampling::Sampler;
use crate::scene::ShaderDesc;
use glam::Vec3A;

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
        /// Longest chain of consecutive specular bounces.
        max_specular: u32,
    },
    /// The assignment's global shader (Eq. 1-4).
    Global(Global),
    /// The reference path tracer.
    Path(Path),
}

impl Shader {
    /// Convert the scene file's description.
    pub fn from_desc(d: &ShaderDesc) -> Shader {
        match *d {
            ShaderDesc::Intersection { color } => Shader::Intersection {
                color: color.0.as_vec3a(),
            },
            ShaderDesc::Depth {
                max_distance,
                color,
            } => Shader::Depth {
                max_distance: max_distance.0 as f32,
                color: color.0.as_vec3a(),
            },
            ShaderDesc::Normal => Shader::Normal,
            ShaderDesc::Direct { max_specular } => Shader::Direct { max_specular },
            ShaderDesc::Global {
                samples,
                max_depth,
                ambient,
                max_specular,
            } => Shader::Global(Global {
                samples: samples.0,
                max_depth: max_depth.0,
                ambient: ambient.0.as_vec3a(),
                max_specular,
            }),
            ShaderDesc::Path {
                max_depth,
                rr_depth,
                sampling,
            } => Shader::Path(Path {
                max_depth: max_depth.map(|d| d.0),
                rr_depth,
                sampling,
            }),
        }
    }
}

/// What one camera sample needs while it is traced: the scene, its random numbers and counters.
pub struct Tracer<'a> {
    /// The prepared scene.
    pub scene: &'a RenderScene,
    /// Random numbers of this (pixel, sample).
    pub sampler: Sampler,
    /// Rays traced so far, by kind.
    pub stats: &'a mut RayStats,
}

impl Tracer<'_> {
    /// Nearest hit of a ray of the given kind (counted), in render kernel `K`.
    #[inline]
    pub fn trace<const K: u32>(&mut self, ray: &Ray, kind: RayKind) -> Option<Hit> {
        self.stats.count(kind);
        self.scene.geometry.intersect_in::<K>(ray)
    }

    /// True if nothing blocks the shadow ray (counted), in render kernel `K`.
    #[inline]
    pub fn unoccluded<const K: u32>(&mut self, ray: &Ray) -> bool {
        self.stats.count(RayKind::Shadow);
        !self.scene.geometry.occluded_in::<K>(ray)
    }
}

/// Radiance arriving at the camera along the camera ray `ray`, in render kernel `K`
/// (see [`crate::effects`]).
#[inline]
pub fn radiance<const K: u32>(tr: &mut Tracer, ray: &Ray) -> Vec3A {
    match tr.scene.shader {
        Shader::Intersection { color } => intersection::radiance::<K>(tr, ray, color),
        Shader::Depth {
            max_distance,
            color,
        } => depth::radiance::<K>(tr, ray, max_distance, color),
        Shader::Normal => normal::radiance::<K>(tr, ray),
        Shader::Direct { max_specular } => direct::radiance::<K>(tr, ray, max_specular),
        Shader::Global(g) => global::radiance::<K>(tr, ray, &g),
        Shader::Path(p) => path::radiance::<K>(tr, ray, &p),
    }
}
