//! What the path tracer tells whoever renders it, besides the light it finds: each contribution
//! with the strategy that found it and the path's length, and each event of the path (a hit,
//! a scattered ray, an escape, Russian roulette) for replaying one sample.
//!
//! A render sums the contributions exactly (its exact sums), so an image split by
//! technique or by bounce sums to the render to the bit. The events cost nothing when the
//! recorder ignores them: [`Record::event`] takes a closure that builds the event, and the
//! recorders of a render never call it.

use crate::stats::RayKind;
use glam::Vec3A;
use serde::Serialize;

/// The strategy that found a contribution (the path tracer's estimators, each with its MIS
/// weight already applied).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Technique {
    /// Light met by the camera ray, or after a chain of mirrors and glass only, or the
    /// background: no other strategy could have found it (weight 1).
    Emitted,
    /// Next-event estimation: a light sample (or every point light) at a vertex.
    Light,
    /// An emitter, or the environment, met by a ray its vertex sampled from the BSDF or
    /// the Phong lobes.
    Bsdf,
    /// All the radiance of a shader other than Path, which does not split what it finds.
    Shader,
}

impl Technique {
    /// The path tracer's techniques, in the order images list them.
    pub const PATH: [Technique; 3] = [Technique::Emitted, Technique::Light, Technique::Bsdf];

    /// Every technique, in the order of their index ([`Technique::index`]).
    pub const ALL: [Technique; 4] = [
        Technique::Emitted,
        Technique::Light,
        Technique::Bsdf,
        Technique::Shader,
    ];

    /// The technique's index in arrays of parts.
    pub fn index(self) -> usize {
        match self {
            Technique::Emitted => 0,
            Technique::Light => 1,
            Technique::Bsdf => 2,
            Technique::Shader => 3,
        }
    }

    /// The name of the technique's image layer.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Emitted => "emitted",
            Technique::Light => "light",
            Technique::Bsdf => "bsdf",
            Technique::Shader => "shader",
        }
    }
}

/// Parts of the image by bounce: direct light (met by the camera ray, or after one scattering
/// vertex), then light that scattered 1, 2, and 3 or more times before that.
pub const BOUNCES: usize = 4;

/// Names of the bounce layers: `direct`, `1`, `2`, `3+`.
pub const BOUNCE_NAMES: [&str; BOUNCES] = ["direct", "1", "2", "3+"];

/// The bounce part of light that reached the camera through `vertices` scattering vertices
/// (mirrors and glass count, as in pbrt's depth): 0 and 1 are direct light, `k` vertices are
/// bounce `k - 1`, and four or more the last part.
#[inline]
pub fn bounce_of(vertices: u32) -> usize {
    (vertices.max(1) as usize - 1).min(BOUNCES - 1)
}

/// One event of a path, in the order the path tracer meets them.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "lowercase")]
pub enum Event {
    /// The path met a surface: its point and viewer-side shading normal, the material's index
    /// in the render's table and kind, and the throughput `beta` of the path up to it.
    Hit {
        /// The hit point.
        p: [f32; 3],
        /// The shading normal on the viewer's side.
        n: [f32; 3],
        /// The material's index in the render's table.
        material: u32,
        /// The material's kind (`Phong`, `Mirror`, `RoughConductor`, ...).
        kind: &'static str,
        /// Throughput of the path up to this vertex.
        beta: [f32; 3],
    },
    /// Light added: `l` (throughput, radiance and MIS weight applied) found by `technique`.
    Add {
        /// The strategy.
        technique: Technique,
        /// The contribution.
        l: [f32; 3],
    },
    /// The path continues in direction `wi`, sampled with density `pdf` (solid angle; `None`
    /// for a specular direction), its weight `f |cos| / pdf` multiplying the throughput.
    Scatter {
        /// Unit direction of the next ray.
        wi: [f32; 3],
        /// Its density, or `None` for a specular (delta) direction.
        pdf: Option<f32>,
        /// The weight the throughput is multiplied by.
        weight: [f32; 3],
        /// The next ray's kind.
        ray: RayKind,
    },
    /// Russian roulette: the path survived with probability `q` (its throughput divided by
    /// `q`), or ended.
    Roulette {
        /// The survival probability.
        q: f32,
        /// Whether the path survived.
        survived: bool,
    },
    /// The ray left the scene in direction `d`.
    Escape {
        /// Unit direction of the escaped ray.
        d: [f32; 3],
    },
}

/// The name of a ray kind in events.
pub fn ray_name(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Camera => "camera",
        RayKind::Shadow => "shadow",
        RayKind::Reflection => "reflection",
        RayKind::Refraction => "refraction",
        RayKind::Indirect => "indirect",
    }
}

/// Whoever renders the path tracer: told each contribution and, if it wants them, the events.
pub trait Record {
    /// Add light `l` (finite and non-negative unless the sample failed) found by `technique`
    /// along a path of `vertices` scattering vertices.
    fn add(&mut self, l: Vec3A, technique: Technique, vertices: u32);

    /// An event of the path, built only if the recorder keeps events (a render's recorders
    /// do not, and the closure is compiled away).
    #[inline]
    fn event(&mut self, _event: impl FnOnce() -> Event) {}
}

/// A vector as three numbers (for events).
#[inline]
pub fn arr(v: Vec3A) -> [f32; 3] {
    v.to_array()
}
