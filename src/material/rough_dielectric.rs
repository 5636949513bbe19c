//! Rough dielectrics: an interface between two indices of refraction whose surface is a
//! distribution of microscopic smooth facets, each reflecting or refracting (Mitsuba 3's
//! `roughdielectric`; Walter et al. 2007, "Microfacet models for refraction through rough
//! surfaces", eqs. 20 and 21), in the local shading frame.
//!
//! The frame's `z` is the surface's outward normal: `wo.z > 0` sees the outside (index
//! `ext_ior`), `wo.z < 0` the inside (`int_ior`). With `eta' = n_t / n_o`, the index of the
//! side `wi` is on over the side of `wo`, and `wm` the microfacet normal that takes `wo` to
//! `wi` (the half vector for reflection, the generalised half vector `wo + eta' wi` for
//! refraction, eq. 16), both facing `+z`:
//!
//! - reflection: `f cos(theta_i) = R F D G / (4 |cos(theta_o)|)`;
//! - refraction: `f |cos(theta_i)| = T (1 - F) D G |wi.wm wo.wm| / (|cos(theta_o)| (wi.wm +
//!   wo.wm / eta')^2) / eta'^2`,
//!
//! with `F` the dielectric Fresnel term at `wo.wm`, `R` and `T` the `specular_reflectance` and
//! `specular_transmittance` tints. The last `1 / eta'^2` scales radiance as it crosses into the
//! viewer's medium, as the smooth `Transmissive` does under the Physical model (pbrt-v4's
//! `TransportMode::Radiance`); it makes `f` reciprocal up to the indices: `f(wo, wi) / n_i^2 =
//! f(wi, wo) / n_o^2`. Sampling picks a visible normal, then reflection with probability `F`
//! and refraction otherwise.

use super::bsdf_sample::BsdfSample;
use super::fresnel_dielectric;
use super::microfacet::Microfacet;
use glam::Vec3A;

/// A rough dielectric interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// The distribution of microfacet normals and how it is sampled.
    pub microfacet: Microfacet,
    /// `int_ior / ext_ior`, > 0 and not 1.
    pub eta: f32,
    /// Tint of the reflection, per channel.
    pub specular_reflectance: Vec3A,
    /// Tint of the transmission, per channel.
    pub specular_transmittance: Vec3A,
}

/// The value and density of one way through the interface (reflected or refracted).
struct Way {
    /// `f |cos(theta_i)|`.
    f: Vec3A,
    /// The sampler's density per solid angle.
    pdf: f32,
}

impl RoughDielectric {
    /// `eta' = n_t / n_o` for a viewer on the side of `cos_o`'s sign.
    #[inline]
    fn etap(&self, cos_o: f32) -> f32 {
        if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        }
    }

    /// `f(wo, wi) |cos(theta_i)|`, reflected or refracted as `wi` lies on `wo`'s side or not.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Vec3A {
        self.through(wo, wi).map_or(Vec3A::ZERO, |l| l.f)
    }

    /// The density per solid angle with which [`RoughDielectric::sample`] draws `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        self.through(wo, wi).map_or(0.0, |l| l.pdf)
    }

    /// A direction `wi` for the viewer `wo`: a visible normal from `(u1, u2)`, then reflection
    /// if `uc < F`, refraction otherwise. `None` when the direction carries nothing.
    #[inline]
    pub fn sample(&self, wo: Vec3A, uc: f32, u1: f32, u2: f32) -> Option<BsdfSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 {
            return None;
        }
        // Sample a normal seen from wo's side, with the microfacets facing +z.
        let up = wo * cos_o.signum();
        let wm = self.microfacet.sample_normal(up, u1, u2);
        let cos_om = up.dot(wm);
        if cos_om <= 0.0 {
            return None;
        }
        let etap = self.etap(cos_o);
        let f = fresnel_dielectric(cos_om, 1.0 / etap);
        let reflected = uc < f;
        let wi = if reflected {
            // Reflection about wm.
            2.0 * wo.dot(wm) * wm - wo
        } else {
            // Refraction by Snell's law about wm turned towards wo (sin^2 < 1 since F < 1).
            let n = wm * cos_o.signum();
            let sin2_t = (1.0 - cos_om * cos_om).max(0.0) / (etap * etap);
            let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
            -wo / etap + (cos_om / etap - cos_t) * n
        };
        // Drawn by the way it was meant to be (a reflection that ends below the surface, or a
        // refraction above it, is not a sample), wi's value and density are those `eval` and
        // `pdf` find (from the half vector of wo and wi, not the sampled normal), so that MIS
        // weighs this sample and a light sample of the same direction with one density.
        if wi.z == 0.0 || (wi.z * cos_o > 0.0) != reflected {
            return None;
        }
        let way = self.through(wo, wi)?;
        let mut s = BsdfSample::glossy(wi, way.f, way.pdf)?;
        if wi.z * cos_o < 0.0 {
            s.eta = etap;
        }
        Some(s)
    }

    /// The lobe that takes `wo` to `wi`, with its microfacet normal found from the two.
    #[inline]
    fn through(&self, wo: Vec3A, wi: Vec3A) -> Option<Way> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return None;
        }
        // The generalised half vector (Walter et al. 2007, eq. 16), facing +z.
        let etap = if cos_o * cos_i > 0.0 {
            1.0
        } else {
            self.etap(cos_o)
        };
        let h = wo + wi * etap;
        let len2 = h.length_squared();
        if len2 == 0.0 || !len2.is_finite() {
            return None;
        }
        let wm = h / len2.sqrt();
        self.lobe(wo, wi, if wm.z < 0.0 { -wm } else { wm })
    }

    /// `f |cos(theta_i)|` and the density of the way from `wo` to `wi` through the facet of
    /// normal `wm` (facing +z); `None` where the facet faces away from either direction.
    #[inline]
    fn lobe(&self, wo: Vec3A, wi: Vec3A, wm: Vec3A) -> Option<Way> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        let (om, im) = (wo.dot(wm), wi.dot(wm));
        // Each direction must see the facet's side it lies on.
        if cos_o == 0.0 || cos_i == 0.0 || om * cos_o <= 0.0 || im * cos_i <= 0.0 {
            return None;
        }
        let m = &self.microfacet;
        let etap = self.etap(cos_o);
        let f = fresnel_dielectric(om.abs(), 1.0 / etap);
        let dg = m.d(wm) * m.g(wo, wi, wm);
        let pdf_m = m.pdf_normal(wo * cos_o.signum(), wm);
        let lobe = if cos_o * cos_i > 0.0 {
            // Reflection (eq. 20) and the half-vector Jacobian 1 / (4 |wo.wm|) (eq. 14).
            Way {
                f: self.specular_reflectance * (f * dg / (4.0 * cos_o.abs())),
                pdf: f * pdf_m / (4.0 * om.abs()),
            }
        } else {
            // Refraction (eq. 21) and its Jacobian |wi.wm| / (wi.wm + wo.wm / eta')^2 (eq. 17).
            let denom = im + om / etap;
            let denom2 = denom * denom;
            let ft = (1.0 - f) * dg * (im * om / (cos_o * denom2)).abs() / (etap * etap);
            Way {
                f: self.specular_transmittance * ft,
                pdf: (1.0 - f) * pdf_m * im.abs() / denom2,
            }
        };
        (lobe.pdf.is_finite() && lobe.f.is_finite()).then_some(lobe)
    }
}
