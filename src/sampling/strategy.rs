//! Direction-sampling strategies a shader can be asked to use.

use serde::{Deserialize, Serialize};

/// How the Path integrator picks the next direction at a Phong vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum Sampling {
    /// Uniform on the hemisphere (the course's sampler).
    Uniform,
    /// Proportional to `cos(theta)`.
    Cosine,
    /// A mixture of the cosine lobe and the Phong lobe, weighted by `kd` and `ks`.
    #[default]
    Brdf,
}

/// How the Path integrator gathers light from emitting shapes (area lights). Point lights are
/// always sampled: no direction can hit them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum LightSampling {
    /// Next-event estimation and BRDF sampling combined by multiple importance sampling with
    /// the power heuristic (Veach 1997).
    #[default]
    Mis,
    /// Next-event estimation only: emitters hit by BRDF-sampled rays add nothing (after a
    /// mirror or glass they still do, as no light sample can reach through them).
    Light,
    /// BRDF sampling only: emitters add light only when a sampled ray hits them.
    Brdf,
}

/// The power heuristic (exponent 2) weight of a sample drawn with density `pdf` from one
/// strategy when another would have drawn it with density `other`: `pdf^2 / (pdf^2 + other^2)`.
/// The weights of the two strategies for the same sample sum to 1.
#[inline]
pub fn power_heuristic(pdf: f32, other: f32) -> f32 {
    if pdf.is_infinite() {
        return 1.0;
    }
    // Scaled by the larger density, so that the squares neither overflow nor underflow.
    let m = pdf.max(other);
    if m <= 0.0 || m.is_infinite() {
        return 0.0;
    }
    let (a, b) = ((pdf / m) * (pdf / m), (other / m) * (other / m));
    a / (a + b)
}

/// How many lights the Path integrator samples at each vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum LightsPerVertex {
    /// Every point light (one shadow ray each, the course's Eq. 3) and one area-light sample.
    #[default]
    All,
    /// One light, point or area, chosen in proportion to its power (Mitsuba's default): one
    /// shadow ray per vertex whatever the number of lights, at some more noise.
    One,
    /// One light as `One` chooses it, except that the point lights' share goes to each in
    /// proportion to its unshadowed contribution `I cos(theta) / d^2` at the vertex (as pbrt-v4's
    /// light BVH weighs a point light): one shadow ray per vertex, and on diffuse surfaces
    /// under grey point lights only visibility is left to vary.
    Importance,
}
