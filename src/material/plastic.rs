//! Smooth plastics: a diffuse base under a smooth dielectric coating (Mitsuba 3's `plastic`),
//! in the local shading frame (`z` the normal on the viewer's side).
//!
//! Light either reflects off the coating, a perfect mirror weighted by the Fresnel term
//! `F(cos(theta_o))` and `specular_reflectance`, or enters it, reflects diffusely from the
//! base, and leaves. Inside, the coating reflects back a share `F_dr` of the diffuse light
//! (the hemispherical average of Fresnel seen from inside, computed here by quadrature), which
//! meets the base again: the base's `rho` becomes `rho / (1 - F_dr)`, or `rho / (1 - rho F_dr)`
//! with `nonlinear`, the exact sum of the bounces (Mitsuba's two options, after Weidlich and
//! Wilkie 2007). The diffuse part is
//!
//! `f cos(theta_i) = rho' / pi (1 - F(cos(theta_o))) (1 - F(cos(theta_i))) / eta^2 cos(theta_i)`,
//!
//! the `1 / eta^2` spreading the radiance that leaves the denser coating over the wider solid
//! angle outside. Sampling picks the mirror with probability `F s / (F s + (1 - F) (1 - s))`,
//! `s` the specular share of the mean reflectances, as Mitsuba does.

use super::bsdf_sample::BsdfSample;
use super::coating::Coating;
use glam::Vec3A;
use std::f32::consts::FRAC_1_PI;

/// A smooth plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// The coating over the diffuse base.
    pub coating: Coating,
}

impl Plastic {
    /// `f(wo, wi) cos(theta_i)` of the diffuse part (the mirror is a delta, sampled only).
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Vec3A {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3A::ZERO;
        }
        let c = &self.coating;
        let t = (1.0 - c.fresnel(wo.z)) * (1.0 - c.fresnel(wi.z));
        c.diffuse * (FRAC_1_PI * c.inv_eta2 * t * wi.z)
    }

    /// The density per solid angle of the diffuse part's directions.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let f = self.coating.fresnel(wo.z);
        (1.0 - self.coating.specular_probability(f)) * wi.z * FRAC_1_PI
    }

    /// The mirror direction with probability `P(specular)`, else a cosine-distributed one.
    #[inline]
    pub fn sample(&self, wo: Vec3A, uc: f32, u1: f32, u2: f32) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let c = &self.coating;
        let f = c.fresnel(wo.z);
        let ps = c.specular_probability(f);
        if uc < ps {
            let wi = Vec3A::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                wi,
                weight: c.specular_reflectance * (f / ps),
                pdf: ps,
                eta: 1.0,
                delta: true,
            });
        }
        let wi = crate::sampling::hemisphere::cosine(u1, u2);
        BsdfSample::glossy(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }
}
