//! The dielectric coating over a diffuse base that the plastics share: the base's reflectance
//! after the light trapped under the coating, the coating's Fresnel term, and the choice
//! between the coating's reflection and the base in sampling.

use super::fresnel_dielectric;
use glam::Vec3A;

/// A dielectric coating of relative index `eta` over a diffuse base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coating {
    /// `int_ior / ext_ior`, > 0 and not 1.
    pub eta: f32,
    /// `1 / eta^2`.
    pub inv_eta2: f32,
    /// The base's reflectance `rho`, as given.
    pub diffuse_reflectance: Vec3A,
    /// Whether the light trapped under the coating takes the base's colour.
    pub nonlinear: bool,
    /// The base's reflectance after the light the coating reflects back down: `rho / (1 -
    /// F_dr)`, or `rho / (1 - rho F_dr)` when nonlinear.
    pub diffuse: Vec3A,
    /// Tint of the coating's reflection, per channel.
    pub specular_reflectance: Vec3A,
    /// The specular share of the mean reflectances, `s = mean(specular) / (mean(diffuse) +
    /// mean(specular))`, which steers sampling.
    pub specular_weight: f32,
    /// The share `F_dr` of diffuse light from below that the coating reflects back down.
    pub internal: f32,
}

impl Coating {
    /// The coating of relative index `eta` over a base of reflectance `diffuse_reflectance`,
    /// `internal` being the share `F_dr` of diffuse light from below that the coating reflects
    /// back down.
    pub fn new(
        eta: f32,
        diffuse_reflectance: Vec3A,
        specular_reflectance: Vec3A,
        nonlinear: bool,
        internal: f32,
    ) -> Self {
        let trapped = if nonlinear {
            diffuse_reflectance * internal
        } else {
            Vec3A::splat(internal)
        };
        let (d, s) = (
            diffuse_reflectance.element_sum() / 3.0,
            specular_reflectance.element_sum() / 3.0,
        );
        Coating {
            eta,
            inv_eta2: 1.0 / (eta * eta),
            diffuse_reflectance,
            nonlinear,
            diffuse: diffuse_reflectance / (Vec3A::ONE - trapped),
            specular_reflectance,
            specular_weight: if d + s > 0.0 { s / (d + s) } else { 0.5 },
            internal,
        }
    }

    /// The same coating over a base of reflectance `diffuse_reflectance`, its own reflection
    /// tinted by `specular_reflectance` (textured reflectances, looked up at a hit): the
    /// light trapped under it, which depends on the coating alone, is kept.
    #[inline]
    pub fn retinted(&self, diffuse_reflectance: Vec3A, specular_reflectance: Vec3A) -> Self {
        Coating::new(
            self.eta,
            diffuse_reflectance,
            specular_reflectance,
            self.nonlinear,
            self.internal,
        )
    }

    /// A smooth coating: the light trapped under it is [`diffuse_fresnel_reflectance`] from
    /// inside.
    pub fn smooth(
        eta: f32,
        diffuse_reflectance: Vec3A,
        specular_reflectance: Vec3A,
        nonlinear: bool,
    ) -> Self {
        let internal = diffuse_fresnel_reflectance(eta);
        Coating::new(
            eta,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            internal,
        )
    }

    /// The smooth coating's Fresnel reflectance for light from outside at cosine `cos`.
    #[inline]
    pub fn fresnel(&self, cos: f32) -> f32 {
        fresnel_dielectric(cos, 1.0 / self.eta)
    }

    /// The chance of sampling the coating's reflection when it reflects a share `f` of the
    /// light: `f s / (f s + (1 - f) (1 - s))`.
    #[inline]
    pub fn specular_probability(&self, f: f32) -> f32 {
        let (ps, pd) = (
            f * self.specular_weight,
            (1.0 - f) * (1.0 - self.specular_weight),
        );
        if ps + pd > 0.0 { ps / (ps + pd) } else { 0.0 }
    }
}

/// `F_dr = 2 int_0^1 F(mu) mu dmu`: the share of diffuse (cosine-distributed) light that a
/// smooth interface reflects, for light incident from the side of index `n_i` with `eta =
/// n_i / n_t`; by the midpoint rule on 4096 points, exact to about 1e-4 (the step of `F` at
/// the critical angle of total internal reflection).
pub fn diffuse_fresnel_reflectance(eta: f32) -> f32 {
    const N: usize = 4096;
    let sum: f64 = (0..N)
        .map(|j| {
            let mu = (j as f32 + 0.5) / N as f32;
            (fresnel_dielectric(mu, eta) * mu) as f64
        })
        .sum();
    (2.0 * sum / N as f64) as f32
}
