//! A direction sampled from a BSDF.

use glam::Vec3A;

/// A direction sampled from a BSDF, in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction `wi`.
    pub wi: Vec3A,
    /// `f(wo, wi) |cos(theta_i)| / pdf`: what the sample multiplies the throughput by.
    pub weight: Vec3A,
    /// The density of `wi` per solid angle; for a delta lobe, the chance of choosing it.
    pub pdf: f32,
    /// `eta' = n_i / n_o`, the index on `wi`'s side over `wo`'s, for a direction through a
    /// dielectric (its weight then holds the radiance scaling `1 / eta'^2`); 1 otherwise.
    pub eta: f32,
    /// True when `wi` comes from a delta lobe (a smooth coating's mirror), which `eval` and
    /// `pdf` leave out: no light sample can find it.
    pub delta: bool,
}

impl BsdfSample {
    /// A sample of a non-delta lobe drawn with density `pdf` and carrying `f |cos| = f_cos`;
    /// `None` when it carries nothing or its weight is not finite.
    #[inline]
    pub fn glossy(wi: Vec3A, f_cos: Vec3A, pdf: f32) -> Option<Self> {
        if pdf.is_nan() || pdf <= 0.0 || f_cos == Vec3A::ZERO {
            return None;
        }
        let weight = f_cos / pdf;
        weight.is_finite().then_some(BsdfSample {
            wi,
            weight,
            pdf,
            eta: 1.0,
            delta: false,
        })
    }
}
