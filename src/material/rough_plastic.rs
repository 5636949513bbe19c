//! Rough plastics: a diffuse base under a rough dielectric coating (Mitsuba 3's
//! `roughplastic`), in the local shading frame (`z` the normal on the viewer's side).
//!
//! The coating reflects as a rough dielectric's reflection lobe, `R F D G / (4 cos(theta_o))`
//! (Walter et al. 2007, eq. 20). The base is the smooth [`Plastic`](super::plastic::Plastic)'s,
//! with the Fresnel transmittances `1 - F(cos)` replaced by the rough coating's `T(cos)`: the
//! share of light from the direction of cosine `cos` that refracts through a facet and is not
//! masked on its way in ([`coating_transmittance`], by quadrature over visible normals), and
//! the light trapped under the coating by the coating's single-scattering albedo `R_c` seen from
//! inside ([`coating_albedo`]), averaged over the hemisphere. This is Mitsuba 3's model (since
//! its `eval_transmittance`; `T` was `1 - R_c` before, which counts light masked after
//! refraction as crossing) and its approximations: the transmitted light is
//! assumed to reach the base diffusely and leave diffusely, whatever the microfacet it crossed;
//! the coating's own multiple scattering is lost, as in the rough conductor.
//!
//! `T` is tabulated at construction on 32 cosines spaced as squares (`mu = (j / 31)^2`, dense
//! near grazing, where `T` falls fastest) and interpolated linearly in `sqrt(mu)`; Mitsuba uses
//! 64 evenly spaced cosines. Sampling picks the coating with probability `(1 - T(cos(theta_o)))
//! s / ((1 - T) s + T (1 - s))` (`s` the specular share of the mean reflectances), a visible
//! normal and its mirror direction; the base otherwise, by a cosine-distributed direction.

use super::bsdf_sample::BsdfSample;
use super::coating::Coating;
use super::fresnel_dielectric;
use super::microfacet::{Microfacet, half_vector};
use glam::Vec3A;
use std::f32::consts::FRAC_1_PI;

/// Number of cosines in the transmittance table.
const TABLE: usize = 32;

/// A rough plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    /// The coating's distribution of microfacet normals (isotropic) and its sampling.
    pub microfacet: Microfacet,
    /// The coating over the diffuse base.
    pub coating: Coating,
    /// `T(mu)` at `mu = (j / 31)^2`.
    transmittance: [f32; TABLE],
}

impl RoughPlastic {
    /// A rough plastic whose coating has the distribution `microfacet` and relative index
    /// `eta = int_ior / ext_ior`, over a base of reflectance `diffuse_reflectance`.
    pub fn new(
        microfacet: Microfacet,
        eta: f32,
        diffuse_reflectance: Vec3A,
        specular_reflectance: Vec3A,
        nonlinear: bool,
    ) -> Self {
        // T(mu) for light from outside (eta_i / eta_t = 1 / eta).
        let transmittance = std::array::from_fn(|j| {
            let x = j as f32 / (TABLE - 1) as f32;
            coating_transmittance(&microfacet, (x * x).max(1e-6), 1.0 / eta)
        });
        // F_dr seen from inside: 2 int R_c(mu) mu dmu, by the midpoint rule on 16 cosines on
        // each side of the critical cosine of total internal reflection (where a smooth
        // coating's R_c jumps to 1: the rule stays second order on either side). Mitsuba 3
        // takes the mean of `2 R_c(mu) mu` over 64 evenly spaced cosines, ends included, which
        // is about 1.5% below the integral: its base is about 1.4% darker than this one (and
        // its white rough plastic keeps 97.5% of the light at alpha 0, where the smooth one
        // keeps all of it).
        let internal = 2.0
            * split_midpoint(critical_cosine(eta), |mu| {
                coating_albedo(&microfacet, mu, eta) * mu
            });
        RoughPlastic {
            microfacet,
            coating: Coating::new(
                eta,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
                internal,
            ),
            transmittance,
        }
    }

    /// `T(cos)`: the share of light from the direction of cosine `cos` that crosses the coating.
    #[inline]
    pub fn transmittance(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0).sqrt() * (TABLE - 1) as f32;
        let j = (x as usize).min(TABLE - 2);
        let w = x - j as f32;
        (1.0 - w) * self.transmittance[j] + w * self.transmittance[j + 1]
    }

    /// `f(wo, wi) cos(theta_i)`: the coating's lobe plus the base's.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Vec3A {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o <= 0.0 || cos_i <= 0.0 {
            return Vec3A::ZERO;
        }
        let c = &self.coating;
        let Some(wm) = half_vector(wo, wi) else {
            return Vec3A::ZERO;
        };
        let m = &self.microfacet;
        let specular = c.fresnel(wo.dot(wm)) * m.d(wm) * m.g(wo, wi, wm) / (4.0 * cos_o);
        let base = FRAC_1_PI * c.inv_eta2 * self.transmittance(cos_o) * self.transmittance(cos_i);
        let f = c.specular_reflectance * specular + c.diffuse * (base * cos_i);
        if f.is_finite() { f } else { Vec3A::ZERO }
    }

    /// The density per solid angle with which [`RoughPlastic::sample`] draws `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability(wo.z);
        ps * self.microfacet.pdf_reflection(wo, wi) + (1.0 - ps) * wi.z * FRAC_1_PI
    }

    /// A direction from the coating's lobe if `uc < P(coating)`, else from the base.
    #[inline]
    pub fn sample(&self, wo: Vec3A, uc: f32, u1: f32, u2: f32) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if uc < self.specular_probability(wo.z) {
            self.microfacet.sample_reflection(wo, u1, u2)?.0
        } else {
            crate::sampling::hemisphere::cosine(u1, u2)
        };
        BsdfSample::glossy(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }

    /// The chance of sampling the coating for a viewer at cosine `cos_o`.
    #[inline]
    fn specular_probability(&self, cos_o: f32) -> f32 {
        self.coating
            .specular_probability(1.0 - self.transmittance(cos_o))
    }
}

/// The cosine below which light inside a coating of relative index `eta` is totally
/// reflected, `sqrt(1 - 1 / eta^2)`; 0 when there is none (`eta <= 1`).
fn critical_cosine(eta: f32) -> f32 {
    if eta > 1.0 {
        (1.0 - 1.0 / (eta * eta)).sqrt()
    } else {
        0.0
    }
}

/// `int_0^1 g(mu) dmu` by the midpoint rule on 16 points in `[0, c]` and 16 in `[c, 1]`.
fn split_midpoint(c: f32, g: impl Fn(f32) -> f32) -> f32 {
    const N: usize = 16;
    let mut sum = 0.0;
    for (a, b) in [(0.0, c), (c, 1.0)] {
        let h = (b - a) / N as f32;
        sum += (0..N).map(|j| g(a + (j as f32 + 0.5) * h)).sum::<f32>() * h;
    }
    sum
}

/// `T(mu)`: the share of light from a direction of cosine `mu` that crosses a rough dielectric
/// interface of relative index `eta = n_i / n_t` and leaves its microsurface, `int D_wo(wm) (1 -
/// F(wo.wm)) G1(wt, wm) dwm` over the normals visible from `wo` (`wt` the refraction of `wo`
/// through `wm`; Walter et al. 2007, with the separable masking), by the quadrature of
/// [`coating_albedo`]. Mitsuba 3's `eval_transmittance`: light that refracts into a facet
/// and is masked on its way out is lost, as the single-scattering model loses it on reflection.
pub fn coating_transmittance(m: &Microfacet, mu: f32, eta: f32) -> f32 {
    let wo = Vec3A::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let crossed = m.integrate_over_normals(64, 64, |wm| {
        let cos_om = wo.dot(wm);
        // Snell's law at the facet; none crosses under total internal reflection.
        let cos2_t = 1.0 - eta * eta * (1.0 - cos_om * cos_om);
        if cos_om <= 0.0 || cos2_t <= 0.0 {
            return 0.0;
        }
        let wt = -eta * wo + (eta * cos_om - cos2_t.sqrt()) * wm;
        if wt.z >= 0.0 {
            return 0.0;
        }
        let f = fresnel_dielectric(cos_om, eta);
        (m.d_visible(wo, wm) * (1.0 - f) * m.g1(wt, wm)) as f64
    });
    let visible = m.integrate_over_normals(64, 64, |wm| m.d_visible(wo, wm) as f64);
    if visible > 0.0 {
        (crossed / visible) as f32
    } else {
        0.0
    }
}

/// `R_c(mu)`: the share of light from a direction of cosine `mu` that a rough dielectric
/// interface of relative index `eta = n_i / n_t` reflects once, `int D_wo(wm) F(wo.wm) G1(wi,
/// wm) dwm` over the normals visible from `wo` (`wi` the mirror of `wo`; Heitz 2014, eq. 38,
/// with the separable masking), by quadrature over normals on 64 x 64 points (to about 1e-3).
pub fn coating_albedo(m: &Microfacet, mu: f32, eta: f32) -> f32 {
    let wo = Vec3A::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let reflected = m.integrate_over_normals(64, 64, |wm| {
        let cos_om = wo.dot(wm);
        let wi = 2.0 * cos_om * wm - wo;
        if cos_om <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        (m.d_visible(wo, wm) * fresnel_dielectric(cos_om, eta) * m.g1(wi, wm)) as f64
    });
    // Divided by the same quadrature of D_wo, which is 1: the ratio cancels most of the
    // quadrature's error near grazing.
    let visible = m.integrate_over_normals(64, 64, |wm| m.d_visible(wo, wm) as f64);
    if visible > 0.0 {
        (reflected / visible) as f32
    } else {
        0.0
    }
}
