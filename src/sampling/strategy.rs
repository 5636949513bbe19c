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
