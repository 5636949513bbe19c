//! Area lights: shapes that emit a constant radiance from their surface (diffuse emitters).
//!
//! Each emitting primitive (a sphere, or one triangle of a rectangle or mesh) is one
//! [`AreaLight`]. Spheres are sampled by the cone of directions they subtend (uniformly in solid
//! angle, pbrt-v4's method) from outside, and uniformly by area from inside and from points
//! near their surface; triangles uniformly by area. Every pdf here is per unit solid angle at
//! the shaded point.

use crate::sampling::warp::{cone_one_minus_cos, uniform_sphere, uniform_triangle};
use crate::shape::{Shape, Sphere, Triangle};
use crate::texture::Texture;
use glam::{Vec2, Vec3A};
use std::f32::consts::{PI, TAU};

/// The emitter component of an entity: its shape emits `radiance` on the side its normal points
/// to (outward for spheres, `(b - a) x (c - a)` for triangles, `u x v` for rectangles), or on
/// both sides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emitter {
    /// Emitted radiance, W/(m^2 sr) per channel, >= 0.
    pub radiance: Vec3A,
    /// Emit from both sides of the surface.
    pub two_sided: bool,
}

/// The world component of an emitter whose radiance varies over its surface: the texture,
/// looked up at each point's texture coordinates, times the [`Emitter`]'s radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct RadianceTexture(pub Texture);

/// An area light's textured radiance in the render data: the texture's index in
/// [`crate::light::Emitters::textures`], its corners' texture coordinates (a triangle's), and
/// the texture's mean (which weighs the light's power).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionTexture {
    /// Index of the texture.
    pub index: u32,
    /// A triangle's corners' `(u, v)` (unused for a sphere).
    pub uvs: [Vec2; 3],
    /// The texture's mean over its image.
    pub mean: Vec3A,
}

/// The shape of an area light, in render coordinates.
#[derive(Clone, Copy, Debug)]
pub enum Emitting {
    /// A sphere.
    Sphere(Sphere),
    /// A triangle (of a triangle, rectangle or mesh).
    Triangle(Triangle),
}

impl Emitting {
    /// The shape as rays meet it.
    pub fn shape(&self) -> Shape {
        match *self {
            Emitting::Sphere(s) => Shape::Sphere(s),
            Emitting::Triangle(t) => Shape::Triangle(t),
        }
    }
}

/// Points within this factor of a sphere's squared radius from its centre sample it by area,
/// not by cone: on the surface (where a shading point on the sphere itself lies, within
/// rounding) the cone opens to a hemisphere whose samples all collapse onto the point. Area
/// sampling is unbiased from anywhere (samples on the far side are occluded or face away), so
/// the band costs only a little variance within 0.5% of the radius.
const CONE_FROM: f32 = 1.01;

/// True if a sphere of radius `r` is sampled by its cone from squared distance `d2` to its
/// centre.
#[inline]
fn by_cone(d2: f32, r: f32) -> bool {
    d2 > CONE_FROM * r * r
}

/// One emitting primitive.
#[derive(Clone, Copy, Debug)]
pub struct AreaLight {
    /// Its shape.
    pub shape: Emitting,
    /// Its emission.
    pub emitter: Emitter,
    /// Its surface area, computed once: every light sample and every MIS weight reads it.
    area: f32,
    /// Its textured radiance, if any (then `emitter.radiance` is the texture's factor).
    pub texture: Option<EmissionTexture>,
}

/// A point sampled on an area light, seen from the shaded point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shaded point towards the sampled point.
    pub wi: Vec3A,
    /// Distance to the sampled point.
    pub dist: f32,
    /// Radiance the light emits towards the shaded point (zero from a one-sided light's back).
    pub le: Vec3A,
    /// Density of `wi` per unit solid angle.
    pub pdf: f32,
    /// The sampled point's texture coordinates when the light is textured (else zero); `le`
    /// is then still the constant factor, which [`crate::light::Emitters::textured`] scales.
    pub uv: Vec2,
}

impl AreaLight {
    /// The light of `shape` emitting as `emitter`.
    pub fn new(shape: Emitting, emitter: Emitter) -> Self {
        let area = match shape {
            Emitting::Sphere(s) => 4.0 * PI * s.r * s.r,
            Emitting::Triangle(t) => 0.5 * (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).length(),
        };
        AreaLight {
            shape,
            emitter,
            area,
            texture: None,
        }
    }

    /// The light of `shape` emitting as `emitter` times `texture`.
    pub fn textured(shape: Emitting, emitter: Emitter, texture: EmissionTexture) -> Self {
        AreaLight {
            texture: Some(texture),
            ..AreaLight::new(shape, emitter)
        }
    }

    /// Surface area.
    #[inline]
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Emitted power of a Lambertian emitter, `pi A L` per side, averaged over the channels:
    /// the weight of this light when one is chosen per shading point.
    pub fn power(&self) -> f32 {
        let sides = if self.emitter.two_sided { 2.0 } else { 1.0 };
        let mean = self.texture.map_or(Vec3A::ONE, |t| t.mean);
        PI * self.area() * sides * (self.emitter.radiance * mean).element_sum() / 3.0
    }

    /// Radiance leaving the surface of geometric normal `n` in direction `w` (unit, away from
    /// the surface).
    #[inline]
    pub fn emitted(&self, n: Vec3A, w: Vec3A) -> Vec3A {
        if self.emitter.two_sided || n.dot(w) > 0.0 {
            self.emitter.radiance
        } else {
            Vec3A::ZERO
        }
    }

    /// Sample a direction from `p` towards the light with `u1, u2` uniform in [0, 1); `None`
    /// when the sample has no density (`p` on the light, an edge-on triangle).
    #[inline]
    pub fn sample(&self, p: Vec3A, u1: f32, u2: f32) -> Option<LightSample> {
        let (q, nq, pdf, uv) = match self.shape {
            Emitting::Sphere(s) => {
                let f = s.c - p;
                let d2 = f.length_squared();
                let r2 = s.r * s.r;
                if !by_cone(d2, s.r) {
                    // Inside or on the surface: uniform by area, converted to solid angle below.
                    let n = uniform_sphere(u1, u2);
                    (s.c + s.r * n, n, None, self.sphere_uv(n))
                } else {
                    // Outside: uniform in the cone of directions the sphere subtends.
                    let sin2_max = r2 / d2;
                    let one_minus_cos_max = cone_one_minus_cos(sin2_max);
                    // theta: the angle of wi from the axis towards the centre.
                    let sin2 = u1 * (2.0 - one_minus_cos_max * u1) * one_minus_cos_max;
                    let cos_t = 1.0 - u1 * one_minus_cos_max;
                    // alpha: the angle at the centre between the axis back to p and the
                    // sampled point's normal (pbrt-v4, Sphere::Sample).
                    let sin_max = sin2_max.sqrt();
                    let cos_a = sin2 / sin_max + cos_t * (1.0 - sin2 / sin2_max).max(0.0).sqrt();
                    let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
                    let (sin_p, cos_p) = crate::sampling::sin_cos_turns(u2);
                    let frame = crate::geometry::Frame::from_normal(-f / d2.sqrt());
                    let n = frame
                        .to_world(Vec3A::new(sin_a * cos_p, sin_a * sin_p, cos_a))
                        .normalize();
                    let pdf = 1.0 / (TAU * one_minus_cos_max);
                    (s.c + s.r * n, n, Some(pdf), self.sphere_uv(n))
                }
            }
            Emitting::Triangle(t) => {
                let [b0, b1, b2] = uniform_triangle(u1, u2);
                let uv = self.texture.map_or(Vec2::ZERO, |t| {
                    b0 * t.uvs[0] + b1 * t.uvs[1] + b2 * t.uvs[2]
                });
                (b0 * t.v[0] + b1 * t.v[1] + b2 * t.v[2], t.n, None, uv)
            }
        };
        let to = q - p;
        let d2 = to.length_squared();
        if d2 == 0.0 || !d2.is_finite() {
            return None;
        }
        let dist = d2.sqrt();
        let wi = to / dist;
        let pdf = match pdf {
            Some(pdf) => pdf,
            None => area_to_solid_angle(self.area(), d2, nq.dot(wi).abs())?,
        };
        Some(LightSample {
            wi,
            dist,
            le: self.emitted(nq, -wi),
            pdf,
            uv,
        })
    }

    /// A textured sphere's coordinates at its unit direction `n` from the centre (else zero).
    #[inline]
    fn sphere_uv(&self, n: Vec3A) -> Vec2 {
        match self.texture {
            Some(_) => crate::shape::sphere_uv(n),
            None => Vec2::ZERO,
        }
    }

    /// Density per unit solid angle with which [`AreaLight::sample`] from `p` picks the
    /// direction towards `q`, a point of this light with geometric normal `nq` (the nearest hit
    /// of the ray from `p`); 0 when it cannot.
    #[inline]
    pub fn pdf(&self, p: Vec3A, q: Vec3A, nq: Vec3A) -> f32 {
        let to = q - p;
        let d2 = to.length_squared();
        if d2 == 0.0 || !d2.is_finite() {
            return 0.0;
        }
        if let Emitting::Sphere(s) = self.shape {
            let dc2 = (s.c - p).length_squared();
            if by_cone(dc2, s.r) {
                return 1.0 / (TAU * cone_one_minus_cos(s.r * s.r / dc2));
            }
        }
        let cos_q = nq.dot(to).abs() / d2.sqrt();
        area_to_solid_angle(self.area(), d2, cos_q).unwrap_or(0.0)
    }
}

/// The solid-angle density of a point uniform on area `a`, seen at squared distance `d2` at
/// cosine `cos_q` to its surface: `d^2 / (a cos)`; `None` edge-on.
#[inline]
fn area_to_solid_angle(a: f32, d2: f32, cos_q: f32) -> Option<f32> {
    let pdf = d2 / (a * cos_q);
    (cos_q > 0.0 && pdf.is_finite() && pdf > 0.0).then_some(pdf)
}
