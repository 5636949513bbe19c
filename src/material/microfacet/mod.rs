//! Microfacet distributions of normals, GGX (Trowbridge-Reitz) and Beckmann, isotropic or
//! anisotropic, with Smith's masking and their samplers: the rough materials' common part.
//!
//! Everything is in the local shading frame: `z` is the macro-surface normal and `x` the
//! tangent along which `alpha_x` applies. For a microfacet normal `wm` and a direction `w`:
//!
//! - `D(wm)`: the density of microfacet normals, normalised so that `int D(wm) cos(theta_m)
//!   dwm = 1` over the hemisphere (Walter et al. 2007, "Microfacet models for refraction
//!   through rough surfaces", eq. 4).
//! - `Lambda(w)`: Smith's auxiliary function of the distribution; `G1(w, wm) = chi(w.wm / w.z)
//!   / (1 + Lambda(w))` is the fraction of the microsurface seen from `w` (Heitz 2014,
//!   "Understanding the masking-shadowing function in microfacet-based BRDFs", eq. 43).
//! - `G(wo, wi, wm) = G1(wo, wm) G1(wi, wm)`: the separable form, as Mitsuba 3 has it, so that a
//!   scene gives Mitsuba's image (pbrt-v4 uses the height-correlated `1 / (1 + Lambda(wo) +
//!   Lambda(wi))`, a few percent brighter at grazing angles).
//! - `D_w(wm) = G1(w, wm) max(0, w.wm) D(wm) / w.z`: the distribution of normals visible from
//!   `w` (Heitz 2014, eq. 38), a density on the sphere that integrates to 1 for every `w`.
//!
//! Normals are sampled from `D_w` ([`NormalSampling::Visible`]: GGX by Dupuy and Benyoub 2023,
//! "Sampling visible GGX normals with spherical caps"; Beckmann by Heitz and d'Eon 2014,
//! "Importance sampling microfacet-based BSDFs using the distribution of visible normals") or
//! from `D(wm) cos(theta_m)` ([`NormalSampling::Full`], the classic sampler, which wastes the
//! normals `w` cannot see).

mod beckmann;
mod ggx;

use glam::Vec3A;
use serde::{Deserialize, Serialize};

/// The smallest `alpha` a rough material accepts: the lobe is then some 1e-4 rad wide, near
/// what a unit vector in `f32` resolves (about 6e-8 rad per component step, and less as
/// directions are rounded through the half vector); the smooth materials are the limit.
pub const MIN_ALPHA: f32 = 1e-4;

/// The shape of the distribution of microfacet normals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum Distribution {
    /// GGX (Trowbridge-Reitz): long tails, the default of Mitsuba 3 and pbrt-v4.
    #[default]
    Ggx,
    /// Beckmann: Gaussian slopes.
    Beckmann,
}

/// Which normals a sampler draws.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum NormalSampling {
    /// The normals visible from `wo`, in proportion to their projected area (`D_wo`).
    #[default]
    Visible,
    /// Every normal, in proportion to `D(wm) cos(theta_m)`.
    Full,
}

/// A distribution of microfacet normals with its sampler.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// GGX or Beckmann.
    pub distribution: Distribution,
    /// Roughness along the tangent `x`, in `[MIN_ALPHA, 1]`.
    pub alpha_x: f32,
    /// Roughness along the bitangent `y`, in `[MIN_ALPHA, 1]`.
    pub alpha_y: f32,
    /// Visible or full sampling of normals.
    pub sampling: NormalSampling,
}

impl Microfacet {
    /// An isotropic distribution of roughness `alpha`, sampled by visible normals.
    pub fn isotropic(distribution: Distribution, alpha: f32) -> Self {
        Microfacet {
            distribution,
            alpha_x: alpha,
            alpha_y: alpha,
            sampling: NormalSampling::Visible,
        }
    }

    /// `D(wm)`, for a unit `wm` (zero below the surface).
    #[inline]
    pub fn d(&self, wm: Vec3A) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        // The squared slope of `wm`, each axis divided by its roughness: `tan^2(theta_m)
        // (cos^2(phi) / ax^2 + sin^2(phi) / ay^2)`.
        let z2 = wm.z * wm.z;
        let e = ((wm.x / self.alpha_x).powi(2) + (wm.y / self.alpha_y).powi(2)) / z2;
        let scale = std::f32::consts::PI * self.alpha_x * self.alpha_y * z2 * z2;
        let d = match self.distribution {
            Distribution::Ggx => ggx::d(e),
            Distribution::Beckmann => beckmann::d(e),
        } / scale;
        if d.is_finite() { d } else { 0.0 }
    }

    /// Smith's `Lambda(w)` for a unit `w` with `w.z != 0` (it depends on `|w.z|`).
    #[inline]
    pub fn lambda(&self, w: Vec3A) -> f32 {
        // `alpha(phi)^2 tan^2(theta)`: the squared slope of `w` seen by the stretched surface.
        let t2 = ((w.x * self.alpha_x).powi(2) + (w.y * self.alpha_y).powi(2)) / (w.z * w.z);
        match self.distribution {
            Distribution::Ggx => ggx::lambda(t2),
            Distribution::Beckmann => beckmann::lambda(t2),
        }
    }

    /// `G1(w, wm)`: the share of the microsurface of normal `wm` seen from `w`; zero where
    /// `wm` faces away from `w` or `w` lies on the other side of the macro-surface from `wm`'s
    /// side (the characteristic function `chi(w.wm / w.z)`).
    #[inline]
    pub fn g1(&self, w: Vec3A, wm: Vec3A) -> f32 {
        if w.dot(wm) * w.z <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(w))
    }

    /// `G(wo, wi, wm) = G1(wo, wm) G1(wi, wm)` (the separable form, as Mitsuba 3).
    #[inline]
    pub fn g(&self, wo: Vec3A, wi: Vec3A, wm: Vec3A) -> f32 {
        self.g1(wo, wm) * self.g1(wi, wm)
    }

    /// The density of visible normals `D_w(wm) = G1(w, wm) max(0, w.wm) D(wm) / w.z`, for `w`
    /// above the surface.
    #[inline]
    pub fn d_visible(&self, w: Vec3A, wm: Vec3A) -> f32 {
        if w.z <= 0.0 {
            return 0.0;
        }
        self.g1(w, wm) * w.dot(wm).max(0.0) * self.d(wm) / w.z
    }

    /// A microfacet normal for the viewer `wo` (above the surface) from the uniform numbers
    /// `(u1, u2)` in `[0, 1)`, by [`Microfacet::sampling`]; its density is
    /// [`Microfacet::pdf_normal`].
    #[inline]
    pub fn sample_normal(&self, wo: Vec3A, u1: f32, u2: f32) -> Vec3A {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        match (self.sampling, self.distribution) {
            (NormalSampling::Visible, Distribution::Ggx) => ggx::sample_visible(wo, ax, ay, u1, u2),
            (NormalSampling::Visible, Distribution::Beckmann) => {
                beckmann::sample_visible(wo, ax, ay, u1, u2)
            }
            (NormalSampling::Full, d) => {
                // Unit-roughness slopes of density `P22`, stretched by the roughness: a normal
                // of density `D(wm) cos(theta_m)` (slopes to normals: `dwm = cos^3 dslope`).
                let r2 = match d {
                    Distribution::Ggx => ggx::slope_radius2(u1),
                    Distribution::Beckmann => beckmann::slope_radius2(u1),
                };
                let (sin_p, cos_p) = crate::sampling::sin_cos_turns(u2);
                let r = r2.sqrt();
                from_slopes(ax * r * cos_p, ay * r * sin_p)
            }
        }
    }

    /// The density per solid angle with which [`Microfacet::sample_normal`] draws `wm` for the
    /// viewer `wo`.
    #[inline]
    pub fn pdf_normal(&self, wo: Vec3A, wm: Vec3A) -> f32 {
        match self.sampling {
            NormalSampling::Visible => self.d_visible(wo, wm),
            NormalSampling::Full => self.d(wm) * wm.z.max(0.0),
        }
    }

    /// A reflected direction for the viewer `wo`: the mirror of `wo` about a sampled normal,
    /// with its density per solid angle `pdf_normal / (4 wo.wm)` (the half-vector Jacobian,
    /// Walter et al. 2007, eq. 14); `None` when it points below the surface.
    #[inline]
    pub fn sample_reflection(&self, wo: Vec3A, u1: f32, u2: f32) -> Option<(Vec3A, f32)> {
        let wm = self.sample_normal(wo, u1, u2);
        let cos_om = wo.dot(wm);
        if cos_om <= 0.0 {
            return None;
        }
        let wi = 2.0 * cos_om * wm - wo;
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf_normal(wo, wm) / (4.0 * cos_om);
        (pdf > 0.0 && pdf.is_finite()).then_some((wi, pdf))
    }

    /// The density per solid angle of [`Microfacet::sample_reflection`] drawing `wi`.
    #[inline]
    pub fn pdf_reflection(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let Some(wm) = half_vector(wo, wi) else {
            return 0.0;
        };
        let cos_om = wo.dot(wm);
        if cos_om <= 0.0 {
            return 0.0;
        }
        self.pdf_normal(wo, wm) / (4.0 * cos_om)
    }
}

impl Microfacet {
    /// `int f(wm) dwm` over the hemisphere of normals, by the midpoint rule in slope space
    /// stretched by the roughness: slopes `(ax r cos(phi), ay r sin(phi))` with `r = tan(pi t /
    /// 2)` for `t` in [0, 1), on `nt x np` points, a normal's solid angle being `cos^3(theta_m)`
    /// times its slopes' area. Every roughness then spreads over the same grid, so a lobe of
    /// alpha 1e-3 is resolved as well as one of alpha 1: for tests and tables (the albedo a
    /// rough surface keeps), not for rendering.
    pub fn integrate_over_normals(&self, nt: usize, np: usize, f: impl Fn(Vec3A) -> f64) -> f64 {
        use std::f64::consts::PI;
        let (ax, ay) = (self.alpha_x as f64, self.alpha_y as f64);
        let mut acc = 0.0;
        for i in 0..nt {
            let t = (i as f64 + 0.5) / nt as f64;
            let r = (PI * t / 2.0).tan();
            let dr = PI / 2.0 / (PI * t / 2.0).cos().powi(2) / nt as f64;
            for j in 0..np {
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                let (sx, sy) = (ax * r * phi.cos(), ay * r * phi.sin());
                let wm = from_slopes(sx as f32, sy as f32);
                acc += f(wm) * (wm.z as f64).powi(3) * ax * ay * r * dr * (2.0 * PI / np as f64);
            }
        }
        acc
    }
}

/// The unit half vector of two unit directions, `None` when they are opposite.
#[inline]
pub fn half_vector(wo: Vec3A, wi: Vec3A) -> Option<Vec3A> {
    let h = wo + wi;
    let len2 = h.length_squared();
    (len2 > 0.0).then(|| h / len2.sqrt())
}

/// The unit normal of the microfacet with slopes `(sx, sy)`: `(-sx, -sy, 1)` normalised.
#[inline]
fn from_slopes(sx: f32, sy: f32) -> Vec3A {
    Vec3A::new(-sx, -sy, 1.0).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quadrature of the tests (2000 x 256 points).
    fn over_normals(m: &Microfacet, f: impl Fn(Vec3A) -> f64) -> f64 {
        m.integrate_over_normals(2000, 256, f)
    }

    fn distributions() -> Vec<Microfacet> {
        let mut v = Vec::new();
        for d in [Distribution::Ggx, Distribution::Beckmann] {
            for (ax, ay) in [(0.01, 0.01), (0.2, 0.2), (1.0, 1.0), (0.05, 0.6)] {
                v.push(Microfacet {
                    distribution: d,
                    alpha_x: ax,
                    alpha_y: ay,
                    sampling: NormalSampling::Visible,
                });
            }
        }
        v
    }

    /// `D` is normalised: `int D(wm) cos(theta_m) dwm = 1` (tolerance 1e-4: the quadrature).
    #[test]
    fn d_projects_to_unit_area() {
        for m in distributions() {
            let a = over_normals(&m, |wm| (m.d(wm) * wm.z) as f64);
            assert!((a - 1.0).abs() < 1e-4, "{m:?}: {a}");
        }
    }

    /// `Lambda` matches `D`: the visible normals' density integrates to 1 from every viewer,
    /// which holds only when `1 + Lambda(w)` is the microsurface's projected area towards `w`
    /// over `w.z` (Heitz 2014, eq. 20). Viewers from the normal to 89 degrees, off the axes.
    /// Tolerance 1e-3 (the quadrature, near grazing).
    #[test]
    fn visible_normals_integrate_to_one() {
        for m in distributions() {
            for theta in [0.0f32, 30.0, 60.0, 80.0, 89.0] {
                let (t, p) = (theta.to_radians(), 0.7f32);
                let w = Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
                let a = over_normals(&m, |wm| m.d_visible(w, wm) as f64);
                assert!((a - 1.0).abs() < 1e-3, "{m:?}, theta {theta}: {a}");
            }
        }
    }

    /// `G1` is 1 seen from the normal, falls towards grazing, and is 0 for a normal facing away.
    #[test]
    fn g1_limits() {
        for m in distributions() {
            assert_eq!(m.g1(Vec3A::Z, Vec3A::Z), 1.0, "{m:?}");
            let graze = Vec3A::new(1.0, 0.0, 1e-3).normalize();
            assert!(m.g1(graze, Vec3A::Z) < m.g1(Vec3A::new(1.0, 0.0, 1.0).normalize(), Vec3A::Z));
            assert_eq!(
                m.g1(
                    Vec3A::new(1.0, 0.0, 0.1).normalize(),
                    Vec3A::new(-1.0, 0.0, 0.1).normalize()
                ),
                0.0
            );
        }
    }
}
