//! Smooth conductors: a metal's mirror reflection, weighted by the Fresnel reflectance of its
//! complex index of refraction `eta + i k` per channel (Mitsuba 3's `conductor`), and the table
//! of named metals.

use super::phong::reflect;
use glam::Vec3A;

/// A smooth conductor: reflects `wo` about the normal, weighted by
/// `F(cos, eta + i k) * specular_reflectance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the index of refraction, per channel (relative to the outside).
    pub eta: Vec3A,
    /// Imaginary part (absorption), per channel.
    pub k: Vec3A,
    /// A tint on the reflection, per channel, in [0, 1] for a physically plausible metal.
    pub specular_reflectance: Vec3A,
}

impl Conductor {
    /// The Fresnel reflectance of the metal at incident cosine `cos_i`, per channel, times
    /// `specular_reflectance`.
    #[inline]
    pub fn reflectance(&self, cos_i: f32) -> Vec3A {
        let f = |c: usize| fresnel_conductor(cos_i, self.eta[c], self.k[c]);
        Vec3A::new(f(0), f(1), f(2)) * self.specular_reflectance
    }

    /// The one reflected direction of `wo` about the unit normal `n` and its weight.
    #[inline]
    pub fn reflect(&self, wo: Vec3A, n: Vec3A) -> (Vec3A, Vec3A) {
        (reflect(wo, n), self.reflectance(wo.dot(n).abs()))
    }
}

/// The unpolarised Fresnel reflectance of a conductor of complex relative index `eta + i k`,
/// at incident cosine `cos_i` in [0, 1] (the exact form for absorbing media: Born and Wolf,
/// "Principles of Optics", section 14.2; written as in Moeller, "Optics", 1988, and pbrt-v3's
/// `FrConductor`). `eta = 0, k = 1` reflects everything at every angle: Mitsuba's
/// `material: "none"`.
#[inline]
pub fn fresnel_conductor(cos_i: f32, eta: f32, k: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let (c2, s2) = (cos_i * cos_i, 1.0 - cos_i * cos_i);
    // |n^2 - sin^2|, with n^2 = eta^2 - k^2 + 2 i eta k: a^2 + b^2, and a, the real part of the
    // square root of n^2 - sin^2.
    let t = eta * eta - k * k - s2;
    let a2b2 = (t * t + 4.0 * eta * eta * k * k).max(0.0).sqrt();
    let a = (0.5 * (a2b2 + t)).max(0.0).sqrt();
    let (t1, t2) = (a2b2 + c2, 2.0 * cos_i * a);
    let rs = (t1 - t2) / (t1 + t2);
    let (t3, t4) = (a2b2 * c2 + s2 * s2, t2 * s2);
    let rp = rs * (t3 - t4) / (t3 + t4);
    let f = 0.5 * (rs + rp);
    if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// The metals Mitsuba 3 names in its `material` parameter, with the RGB `eta` and `k` that its
/// RGB variants derive from its measured spectra (read from Mitsuba 3.7's `scalar_rgb`
/// plugins).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Metal {
    /// Gold.
    Au,
    /// Silver.
    Ag,
    /// Aluminium.
    Al,
    /// Copper.
    Cu,
    /// Chromium.
    Cr,
    /// No metal: `eta = 0, k = 1`, which reflects everything (a perfect mirror).
    None,
}

impl Metal {
    /// Every metal, in the order the messages list them.
    pub const ALL: [Metal; 6] = [
        Metal::Au,
        Metal::Ag,
        Metal::Al,
        Metal::Cu,
        Metal::Cr,
        Metal::None,
    ];

    /// Its name in a scene file (Mitsuba's).
    pub fn name(self) -> &'static str {
        match self {
            Metal::Au => "Au",
            Metal::Ag => "Ag",
            Metal::Al => "Al",
            Metal::Cu => "Cu",
            Metal::Cr => "Cr",
            Metal::None => "none",
        }
    }

    /// The metal of a name, if it is one of [`Metal::ALL`]'s.
    pub fn from_name(name: &str) -> Option<Metal> {
        Metal::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Its complex index of refraction `(eta, k)` per channel.
    pub fn eta_k(self) -> (Vec3A, Vec3A) {
        let v = Vec3A::new;
        match self {
            Metal::Au => (v(0.143036, 0.375307, 1.44205), v(3.983, 2.38556, 1.60336)),
            Metal::Ag => (v(0.155276, 0.116728, 0.138388), v(4.82835, 3.12222, 2.1469)),
            Metal::Al => (v(1.6575, 0.880405, 0.521244), v(9.22381, 6.2695, 4.837)),
            Metal::Cu => (v(0.201005, 0.92375, 1.10222), v(3.91326, 2.45305, 2.14209)),
            Metal::Cr => (v(4.36967, 2.91651, 1.6549), v(5.20655, 4.23131, 3.7547)),
            Metal::None => (Vec3A::ZERO, Vec3A::ONE),
        }
    }
}
