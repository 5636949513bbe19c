//! Environment lights: radiance arriving from infinitely far away in every direction, a
//! constant sky or a latitude-longitude map ([`SkyMap`]), as Mitsuba 3's `constant` and
//! `envmap` and pbrt-v4's `UniformInfiniteLight` and `ImageInfiniteLight`.
//!
//! It is a light like the area lights: chosen by power among them ([`super::Emitters`]),
//! sampled towards a direction with a density per solid angle, and seen by every ray that
//! leaves the scene, through mirrors and glass. Its power is what crosses a disk of the
//! scene's bounding radius `r` from every direction, `pi r^2 int L dw` (pbrt-v4,
//! `ImageInfiniteLight::Phi`).

use super::{LightSample, SkyMap};
use crate::sampling::warp::uniform_sphere;
use glam::{DMat3, DVec3, Mat3A, Vec3A};
use std::f32::consts::{PI, TAU};
use std::path::PathBuf;
use std::sync::Arc;

/// What the sky looks like.
#[derive(Clone, Debug, PartialEq)]
pub enum Sky {
    /// The same radiance from every direction, W/(m^2 sr) per channel.
    Uniform(Vec3A),
    /// A latitude-longitude image of radiance (shared by every render of the scene).
    Map {
        /// The image and its sampling distribution.
        map: Arc<SkyMap>,
        /// The file it was read from (for messages and `rtis check`), or a label for a map
        /// made in code.
        source: PathBuf,
    },
}

/// The environment light as the world holds it.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldEnvironment {
    /// Its radiance before `scale`.
    pub sky: Sky,
    /// A factor on the radiance, `>= 0`.
    pub scale: f32,
    /// Rotation of the map's frame in degrees about x, then y, then z (as a shape's
    /// `Transform`): the map's `+y` is the zenith and its centre column looks along `+z`.
    pub rotate: DVec3,
}

impl WorldEnvironment {
    /// The light in a scene whose finite parts fit in a ball of radius `scene_radius` (its
    /// power).
    pub fn extract(&self, scene_radius: f32) -> EnvironmentLight {
        let r = self.rotate * (std::f64::consts::PI / 180.0);
        let rot =
            DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x);
        EnvironmentLight {
            sky: self.sky.clone(),
            scale: self.scale,
            to_world: Mat3A::from(rot.as_mat3()),
            to_local: Mat3A::from(rot.transpose().as_mat3()),
            scene_radius,
        }
    }
}

/// A prepared environment light. Directions are the same in render and world coordinates
/// (extraction only shifts the origin).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLight {
    sky: Sky,
    scale: f32,
    to_world: Mat3A,
    to_local: Mat3A,
    /// Radius of a ball bounding the scene's finite parts.
    pub scene_radius: f32,
}

/// The map coordinates `(u, v)` of a unit direction `d` in the map's frame, and
/// `sin(theta) = sqrt(x^2 + z^2)`: `u = atan2(x, -z) / (2 pi)` in [0, 1), `v = acos(y) / pi`
/// (Mitsuba 3's `envmap`).
#[inline]
fn uv_of(d: Vec3A) -> (f32, f32, f32) {
    let u = (d.x.atan2(-d.z) / TAU).rem_euclid(1.0);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    // rem_euclid can round a tiny negative up to exactly 1.
    (
        if u >= 1.0 { 0.0 } else { u },
        v,
        (d.x * d.x + d.z * d.z).sqrt(),
    )
}

impl EnvironmentLight {
    /// Radiance arriving along a ray of unit direction `d` that leaves the scene (from the sky
    /// in direction `d`).
    #[inline]
    pub fn radiance(&self, d: Vec3A) -> Vec3A {
        match &self.sky {
            Sky::Uniform(l) => *l * self.scale,
            Sky::Map { map: m, .. } => {
                let (u, v, _) = uv_of(self.to_local * d);
                m.eval(u, v) * self.scale
            }
        }
    }

    /// A direction towards the sky drawn from `(u1, u2)`, uniform in `[0, 1)^2`: uniform on the
    /// sphere for a constant sky, in proportion to the map's luminance otherwise. `None` when
    /// it has no density there (a black map, a pole).
    #[inline]
    pub fn sample(&self, u1: f64, u2: f64) -> Option<LightSample> {
        let (wi, le, pdf) = match &self.sky {
            Sky::Uniform(l) => (uniform_sphere(u1 as f32, u2 as f32), *l, 1.0 / (4.0 * PI)),
            Sky::Map { map: m, .. } => {
                let ((u, v), pdf_uv) = m.sample(u1, u2)?;
                let (sin_t, cos_t) = (v * PI).sin_cos();
                let (sin_p, cos_p) = crate::sampling::sin_cos_turns(u);
                if sin_t <= 0.0 {
                    return None;
                }
                let local = Vec3A::new(sin_p * sin_t, cos_t, -cos_p * sin_t);
                // p(w) = p(u, v) / (2 pi^2 sin(theta)): dw = sin(theta) dtheta dphi.
                let pdf = pdf_uv / (2.0 * PI * PI * sin_t);
                (self.to_world * local, m.eval(u, v), pdf)
            }
        };
        (pdf > 0.0 && pdf.is_finite()).then_some(LightSample {
            wi,
            dist: f32::INFINITY,
            le: le * self.scale,
            pdf,
            uv: glam::Vec2::ZERO,
        })
    }

    /// Density per solid angle with which [`EnvironmentLight::sample`] picks the unit
    /// direction `w`.
    #[inline]
    pub fn pdf(&self, w: Vec3A) -> f32 {
        match &self.sky {
            Sky::Uniform(_) => 1.0 / (4.0 * PI),
            Sky::Map { map: m, .. } => {
                let (u, v, sin_t) = uv_of(self.to_local * w);
                if sin_t <= 0.0 {
                    return 0.0;
                }
                m.pdf(u, v) / (2.0 * PI * PI * sin_t)
            }
        }
    }

    /// `int L dw` over the sphere, per channel.
    pub fn integral(&self) -> Vec3A {
        self.scale
            * match &self.sky {
                Sky::Uniform(l) => 4.0 * PI * *l,
                Sky::Map { map, .. } => map.integral(),
            }
    }

    /// Power averaged over the channels, `pi r^2 int L dw`, in double precision and at most
    /// `f32::MAX`.
    pub fn power(&self) -> f32 {
        let r = self.scene_radius as f64;
        let p = std::f64::consts::PI * r * r * self.integral().element_sum() as f64 / 3.0;
        p.min(f32::MAX as f64) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::Raster;

    /// Mitsuba's orientation: -z is the left edge (u = 0), +x a quarter across, +z the
    /// centre, and +y the top row.
    #[test]
    fn mitsuba_orientation() {
        let (u, ..) = uv_of(Vec3A::new(0.0, 0.0, -1.0));
        assert_eq!(u, 0.0);
        assert!((uv_of(Vec3A::X).0 - 0.25).abs() < 1e-6);
        assert!((uv_of(Vec3A::Z).0 - 0.5).abs() < 1e-6);
        assert!((uv_of(-Vec3A::X).0 - 0.75).abs() < 1e-6);
        assert_eq!(uv_of(Vec3A::Y).1, 0.0);
        assert!((uv_of(-Vec3A::Y).1 - 1.0).abs() < 1e-6);
    }

    /// A sampled direction's density is the one `pdf` gives it, and its radiance what
    /// `radiance` sees along it, for a rotated map.
    #[test]
    fn samples_agree_with_pdf_and_radiance() {
        let texels = (0..32).map(|i| [i as f32, 1.0, (i % 5) as f32]).collect();
        let map = SkyMap::new(Raster::new(8, 4, texels).unwrap());
        let light = WorldEnvironment {
            sky: Sky::Map {
                map: Arc::new(map),
                source: "test".into(),
            },
            scale: 2.0,
            rotate: DVec3::new(10.0, 70.0, -20.0),
        }
        .extract(1.0);
        for (u1, u2) in [(0.1, 0.3), (0.6, 0.55), (0.93, 0.8)] {
            let s = light.sample(u1, u2).unwrap();
            let pdf = light.pdf(s.wi);
            assert!((pdf / s.pdf - 1.0).abs() < 1e-3, "{pdf} {}", s.pdf);
            let l = light.radiance(s.wi);
            assert!((l - s.le).abs().max_element() < 1e-3 * s.le.max_element());
        }
    }
}
