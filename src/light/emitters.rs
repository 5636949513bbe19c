//! The scene's area lights and its environment light, chosen one per light sample in
//! proportion to their power.

use super::{AreaLight, EnvironmentLight};
use crate::geometry::Ray;
use crate::texture::Texture;
use glam::Vec3A;

/// [`crate::light`]'s index of a primitive that emits nothing.
pub const NO_LIGHT: u32 = u32::MAX;

/// The light one light sample picks, with the probability of picking it.
#[derive(Clone, Copy, Debug)]
pub enum Chosen<'a> {
    /// An area light.
    Area(&'a AreaLight, f32),
    /// The environment light.
    Environment(&'a EnvironmentLight, f32),
    /// Point light number `index` of the render (only when the point lights take part).
    Point(usize, f32),
}

/// Every area light of a render and its environment light, with the cumulative distribution of
/// their powers (area lights, then the environment); when one light is chosen per vertex
/// (`Path(lights_per_vertex: One)` or `Importance`), the point lights' powers take part too,
/// after them.
#[derive(Clone, Debug, Default)]
pub struct Emitters {
    /// The lights; a primitive refers to its light by index here.
    pub lights: Vec<AreaLight>,
    /// The environment light, if the scene has one (at most one).
    pub environment: Option<EnvironmentLight>,
    /// The textures of the lights with textured radiance ([`AreaLight::texture`]).
    pub textures: Vec<Texture>,
    /// `cdf[i]`: the power of lights `0..=i` over the total; the last is 1. Double precision,
    /// and sampled with 53-bit numbers, so that a light whose share is below f32's 2^-24 grid
    /// (one small triangle of a million) is still chosen as often as [`Emitters::pmf`] says.
    cdf: Vec<f64>,
    /// Each light's probability, `power / total` (area lights, the environment, then point
    /// lights).
    pmf: Vec<f32>,
}

impl Emitters {
    /// The set of `lights`, each chosen with probability proportional to its power (uniformly
    /// if none has any).
    pub fn new(lights: Vec<AreaLight>) -> Self {
        Self::with_points(lights, Vec::new(), None, &[])
    }

    /// The area `lights` (with the `textures` their [`AreaLight::texture`]s name), the
    /// `environment` light and point lights of powers `points`, each chosen in proportion to
    /// its power.
    pub fn with_points(
        lights: Vec<AreaLight>,
        textures: Vec<Texture>,
        environment: Option<EnvironmentLight>,
        points: &[f32],
    ) -> Self {
        let mut powers: Vec<f64> = lights
            .iter()
            .map(|l| l.power())
            .chain(environment.as_ref().map(EnvironmentLight::power))
            .chain(points.iter().copied())
            .map(f64::from)
            .collect();
        if powers.iter().sum::<f64>() <= 0.0 {
            powers.iter_mut().for_each(|w| *w = 1.0);
        }
        let total: f64 = powers.iter().sum();
        let pmf = powers.iter().map(|w| (w / total) as f32).collect();
        let mut acc = 0.0;
        let mut cdf: Vec<f64> = powers
            .iter()
            .map(|&w| {
                acc += w / total;
                acc
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Emitters {
            lights,
            environment,
            textures,
            cdf,
            pmf,
        }
    }

    /// `le`, the radiance `light` emits as its constant factor gives it, times its texture at
    /// `uv` for a footprint `width` wide in texture coordinates (0 for a light sample: the
    /// finest level); `le` itself for an untextured light.
    #[inline]
    pub fn textured(&self, light: &AreaLight, le: Vec3A, uv: glam::Vec2, width: f32) -> Vec3A {
        match light.texture {
            Some(t) if le != Vec3A::ZERO => le * self.textures[t.index as usize].eval(uv, width),
            _ => le,
        }
    }

    /// True when the scene has no area light and no environment light.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty() && self.environment.is_none()
    }

    /// The number of area lights and environment lights, which come before the point lights in
    /// the choice.
    #[inline]
    fn sampled(&self) -> usize {
        self.lights.len() + usize::from(self.environment.is_some())
    }

    /// True when point lights take part in the choice.
    #[inline]
    pub fn with_point_lights(&self) -> bool {
        self.pmf.len() > self.sampled()
    }

    /// The same area and environment lights, chosen with the point lights of powers `points`
    /// (none: among themselves).
    pub fn rechosen(&self, points: &[f32]) -> Self {
        Self::with_points(
            self.lights.clone(),
            self.textures.clone(),
            self.environment.clone(),
            points,
        )
    }

    /// Probability that the environment light is chosen (0 without one).
    #[inline]
    pub fn pmf_environment(&self) -> f32 {
        match self.environment {
            Some(_) => self.pmf[self.lights.len()],
            None => 0.0,
        }
    }

    /// The point lights' part of the choice: `(start, share)`, where `u` in [0, 1) picks a
    /// point light exactly when `u >= start`, and `share` is their probability all together
    /// (`(1, 0)` when they take no part).
    pub fn point_share(&self) -> (f64, f64) {
        if !self.with_point_lights() {
            return (1.0, 0.0);
        }
        let start = match self.sampled() {
            0 => 0.0,
            n => self.cdf[n - 1],
        };
        (start, 1.0 - start)
    }

    /// Probability that [`Emitters::choose`] picks light `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// The area light that `u`, uniform in [0, 1), picks, with its probability: the first
    /// whose cumulative share exceeds `u` (a light of zero power is never picked); `None` if
    /// `u` picks a point light or the environment, or there is no light.
    #[inline]
    pub fn choose(&self, u: f64) -> Option<(&AreaLight, f32)> {
        match self.choose_any(u)? {
            Chosen::Area(l, pmf) => Some((l, pmf)),
            Chosen::Environment(..) | Chosen::Point(..) => None,
        }
    }

    /// The light, area, environment or point, that `u` picks, with its probability.
    #[inline]
    pub fn choose_any(&self, u: f64) -> Option<Chosen<'_>> {
        if self.cdf.is_empty() {
            return None;
        }
        Some(self.chosen(self.cdf.partition_point(|&c| c <= u)))
    }

    /// The cumulative shares of the choice ([`Emitters::choose_any`] picks the light at the
    /// count of those at or below `u`, or the last); empty without lights.
    #[inline]
    pub fn cdf(&self) -> &[f64] {
        &self.cdf
    }

    /// The light at place `i` of the choice (the last if `i` is past it), with its probability.
    ///
    /// # Panics
    /// If there is no light ([`Emitters::cdf`] empty): [`Emitters::choose_any`] answers `None`
    /// there.
    #[inline]
    pub fn chosen(&self, i: usize) -> Chosen<'_> {
        let i = i.min(self.cdf.len() - 1);
        let pmf = self.pmf[i];
        let n = self.lights.len();
        match (self.lights.get(i), &self.environment) {
            (Some(l), _) => Chosen::Area(l, pmf),
            (None, Some(env)) if i == n => Chosen::Environment(env, pmf),
            (None, _) => Chosen::Point(i - self.sampled(), pmf),
        }
    }

    /// Density per unit solid angle with which one light sample from `p` (choose a light, then
    /// sample it) picks direction `w`: the sum over the lights the ray from `p` meets of the
    /// chance of choosing each times its density, and the environment's (which every ray
    /// meets, ignoring occlusion). For tests and `rtis warptest`; shaders ask the one light a
    /// ray hit.
    pub fn pdf_direction(&self, p: Vec3A, w: Vec3A) -> f32 {
        let ray = Ray::new(p, w);
        let mut pdf = match &self.environment {
            Some(env) => self.pmf_environment() * env.pdf(w),
            None => 0.0,
        };
        for (i, light) in self.lights.iter().enumerate() {
            let shape = light.shape.shape();
            if let Some(t) = shape.intersect(&ray) {
                let q = shape.surface(&ray, t);
                pdf += self.pmf(i) * light.pdf(p, q.p, q.n);
            }
        }
        pdf
    }
}
