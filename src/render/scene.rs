//! The render scene: everything a render reads, as flat arrays. Per-ray code reads only this.

use super::output::Transfer;
use crate::accel::Geometry;
use crate::camera::Camera;
use crate::effects::Effects;
use crate::light::{Emitters, Light};
use crate::material::{Material, Model};
use crate::sampling::{PixelFilter, Sampler, SamplerKind};
use crate::shader::{RayAudit, Shader, Tracer};
use crate::stats::RayStats;
use crate::texture::{Footprint, MaterialTextures};
use glam::{DVec3, Vec3A};

/// Largest image side in pixels.
pub const MAX_SIDE: u32 = 1 << 15;
/// Largest pixel count (8192 x 8192). A render in one go holds 16 bytes per pixel; a
/// progressive one, limited to [`super::progressive::MAX_PIXELS`], about 360 while a round ends.
pub const MAX_PIXELS: u64 = 1 << 26;
/// Largest samples per pixel.
pub const MAX_SPP: u32 = 1 << 20;

/// Image size, sampling and output transfer of a render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// PNG transfer curve.
    pub transfer: Transfer,
    /// Where in and around its pixel each sample goes ([`PixelFilter`]).
    pub filter: PixelFilter,
    /// Where each sample's random numbers come from.
    pub sampler: SamplerKind,
}

impl Default for Film {
    /// The course's 720 x 576, one sample per pixel, sRGB PNG, the box filter.
    fn default() -> Self {
        Film {
            width: 720,
            height: 576,
            spp: 1,
            transfer: Transfer::Srgb,
            filter: PixelFilter::Box,
            sampler: SamplerKind::Independent,
        }
    }
}

impl Film {
    /// The film if its sides, pixel count and samples are within [`MAX_SIDE`], [`MAX_PIXELS`]
    /// and [`MAX_SPP`], and none is zero.
    pub fn checked(self) -> Result<Self, String> {
        let pixels = self.width as u64 * self.height as u64;
        if pixels > MAX_PIXELS {
            return Err(format!(
                "film of {}x{} = {pixels} pixels is too large: at most {MAX_PIXELS} pixels \
                 (8192x8192) are allowed",
                self.width, self.height
            ));
        }
        if self.width == 0 || self.height == 0 || self.spp == 0 {
            return Err("film width, height and spp must be at least 1".into());
        }
        if self.width > MAX_SIDE || self.height > MAX_SIDE {
            return Err(format!(
                "film of {}x{}: each side must be at most {MAX_SIDE} pixels",
                self.width, self.height
            ));
        }
        if self.spp > MAX_SPP {
            return Err(format!("{} samples per pixel: at most {MAX_SPP}", self.spp));
        }
        Ok(self)
    }
}

/// Everything a render needs, as flat arrays. Per-ray code reads only this.
#[derive(Clone, Debug)]
pub struct RenderScene {
    /// The camera, at the origin of the render coordinates.
    pub camera: Camera,
    /// Primitives and their BVH.
    pub geometry: Geometry,
    /// Materials, indexed by `Prim::material`.
    pub materials: Vec<Material>,
    /// Their textures at the same indices, or empty when no material is textured.
    pub textures: Vec<MaterialTextures>,
    /// A pixel's footprint on surfaces, from the camera and the film ([`Footprint`]); each
    /// sample's is this over the square root of the film's spp.
    pub footprint: Footprint,
    /// Point lights.
    pub lights: Vec<Light>,
    /// Area lights (emitting primitives), chosen by power.
    pub emitters: Emitters,
    /// Radiance of escaped rays (zero when the background effect is off).
    pub background: Vec3A,
    /// The shader with its parameters (Global's ambient zero when the ambient effect is off).
    pub shader: Shader,
    /// Light-transport model.
    pub model: Model,
    /// Image settings.
    pub film: Film,
    /// Seed of the render's random numbers.
    pub seed: u64,
    /// World position of the render origin (the camera).
    pub origin: DVec3,
    /// The effects this render simulates.
    pub effects: Effects,
    /// The effects the scene switched off on purpose.
    pub switched_off: Effects,
    /// Notes from extraction and effect derivation (ignored degenerate triangles...).
    pub warnings: Vec<String>,
    /// The observer of every ray its shaders trace, for tests ([`RayAudit`]); `None` in renders.
    pub audit: Option<RayAudit>,
}

impl RenderScene {
    /// Simulate exactly `effects`: zero the ambient term and the background when they are off.
    pub fn set_effects(&mut self, effects: Effects) {
        if !effects.ambient
            && let Shader::Global(g) = &mut self.shader
        {
            g.ambient = Vec3A::ZERO;
        }
        if !effects.background {
            self.background = Vec3A::ZERO;
        }
        self.effects = effects;
    }

    /// Render with `shader`: the light choice follows it (point lights join the area lights'
    /// power distribution when the path tracer chooses one light per vertex).
    pub fn set_shader(&mut self, shader: Shader) {
        self.shader = shader;
        let one = matches!(shader, Shader::Path(p) if p.one_light_under(self.model));
        if one != self.emitters.with_point_lights() {
            let powers: Vec<f32> = if one {
                self.lights.iter().map(Light::power).collect()
            } else {
                Vec::new()
            };
            self.emitters = self.emitters.rechosen(&powers);
        }
    }

    /// The same render with every effect on except those the scene switched off on purpose:
    /// for checking that the derived effects change no pixel.
    pub fn with_every_effect(&self) -> RenderScene {
        RenderScene {
            effects: Effects::ALL.without(self.switched_off),
            ..self.clone()
        }
    }

    /// The parts a shader reads, with the random numbers of one sample and its counters.
    #[inline]
    pub fn tracer<'a>(&'a self, sampler: Sampler, stats: &'a mut RayStats) -> Tracer<'a> {
        Tracer {
            geometry: &self.geometry,
            materials: &self.materials,
            textures: &self.textures,
            footprint: self.footprint.per_sample(self.film.spp),
            lights: &self.lights,
            emitters: &self.emitters,
            background: self.background,
            model: self.model,
            effects: self.effects,
            sampler,
            stats,
            audit: self.audit,
            traversal: None,
        }
    }
}
