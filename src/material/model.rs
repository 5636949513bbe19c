//! The light-transport model: which weights the shaders use.

use serde::{Deserialize, Serialize};

/// The light-transport model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum Model {
    /// The course's: reflectance `r = kd cos + ks cos^s` (no 1/pi) and the course's weights.
    #[default]
    Course,
    /// Physically based: normalised Phong BRDF, unbiased Monte Carlo weights, Fresnel glass.
    Physical,
}
