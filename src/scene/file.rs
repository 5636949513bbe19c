//! The scene file format: serde structs read from RON. Every struct rejects unknown fields;
//! every optional field documents its default. `docs/scene-format.md` is the user's guide.
//!
//! The format knows no runtime types: it names only leaf enums (the model, the sampling
//! strategy, the microfacet distribution and its sampling, the PNG transfer) and converts each description into the world's own component
//! type (`to_world`), which `super::load` puts into the world.

use super::values::{
    Aperture, Count, Direction, Fov, Ior, IorPart, MetalName, NonNegative, Point, Positive,
    Reflectance, Rgb, Roughness, Scale, SpotAngle, UpTo,
};
use crate::camera::{Handedness, Projection, WorldCamera, WorldLens};
use crate::effects::Switches;
use crate::geometry::Transform;
use crate::light::{Emitter, RadianceTexture, Sky, WorldEnvironment, WorldLight};
use crate::material::conductor::{Conductor, Metal};
use crate::material::microfacet::Microfacet;
use crate::material::plastic::Plastic;
use crate::material::rough_conductor::RoughConductor;
use crate::material::rough_dielectric::RoughDielectric;
use crate::material::rough_plastic::RoughPlastic;
use crate::material::{Bsdf, Coating, Material, Mirror, Phong, Transmissive};
use crate::mesh::MeshData;
use crate::raster::Raster;
use crate::render::{Film, MAX_SIDE, MAX_SPP};
use crate::shader::{Global, Path, Shader};
use crate::shape::WorldShape;
use crate::texture::{
    Checkerboard, ImageTexture, MaterialTextures, TexelFilter, Texture, TextureKind, UvTransform,
    Wrap, mip_levels,
};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

pub use crate::material::Model;
pub use crate::material::microfacet::{Distribution, NormalSampling};
pub use crate::render::output::Transfer;
pub use crate::sampling::{LightSampling, LightsPerVertex, PixelFilter, SamplerKind, Sampling};

/// Largest hemisphere sample count of the Global shader.
pub const MAX_GLOBAL_SAMPLES: u32 = 1 << 16;
/// Largest area-light sample count per shading point.
pub const MAX_LIGHT_SAMPLES: u32 = 1 << 16;
/// Largest `max_depth` of the Global shader: its rays grow as `n * 2^(D-1)` per pixel.
pub const MAX_GLOBAL_DEPTH: u32 = crate::shader::global::MAX_DEPTH;
/// Largest `max_depth` and `rr_depth` of the Path shader.
pub const MAX_PATH_DEPTH: u32 = crate::shader::path::MAX_DEPTH;
/// Largest `max_specular` of the Direct and Global shaders.
pub const MAX_SPECULAR: u32 = crate::shader::MAX_SPECULAR;

/// One scene file as written. Every field is optional: a file that `extends` a base scene
/// overrides the base's film, camera, shader, background, seed and model, adds or replaces
/// materials by name, replaces the base's entities that have the same `name`, and appends the
/// others.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(rename = "Scene", deny_unknown_fields)]
pub struct SceneFile {
    /// A base scene to start from, relative to this file's folder.
    #[serde(default)]
    pub extends: Option<String>,
    /// Image size and sampling. Default: `Film(width: 720, height: 576, spp: 1, transfer: Srgb)`.
    #[serde(default)]
    pub film: Option<FilmDesc>,
    /// The camera. Default: perspective at the origin looking down +z, fov 60.
    #[serde(default)]
    pub camera: Option<CameraDesc>,
    /// How rays become colours. Default: `Direct()`.
    #[serde(default)]
    pub shader: Option<ShaderDesc>,
    /// Radiance of rays that leave the scene, linear RGB. Default: black.
    #[serde(default)]
    pub background: Option<Rgb>,
    /// Seed of every random number of the render. Default: 0.
    #[serde(default, deserialize_with = "super::values::seed")]
    pub seed: Option<u64>,
    /// Light-transport model for the shaders that have one. Default: `Course`.
    #[serde(default)]
    pub model: Option<Model>,
    /// Effects switched off (or asked for) on purpose. Default: all decided from the scene.
    #[serde(default)]
    pub effects: Option<EffectsDesc>,
    /// Named materials that entities refer to with `Named("...")`; a table entry
    /// cannot itself be `Named`.
    #[serde(default)]
    pub materials: Option<BTreeMap<String, TableMaterial>>,
    /// The scene's entities.
    #[serde(default)]
    pub entities: Option<Vec<EntityDesc>>,
}

/// Image size and sampling, as written and checked (see [`Film::checked`]).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "FilmFields", into = "FilmFields")]
pub struct FilmDesc(pub Film);

/// The film as written; checked into [`FilmDesc`].
#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(rename = "Film", deny_unknown_fields)]
pub struct FilmFields {
    #[serde(default = "default_width")]
    width: Count<MAX_SIDE>,
    #[serde(default = "default_height")]
    height: Count<MAX_SIDE>,
    #[serde(default = "one")]
    spp: Count<MAX_SPP>,
    #[serde(default)]
    transfer: Transfer,
    #[serde(default)]
    filter: FilterDesc,
    #[serde(default)]
    sampler: SamplerDesc,
}

/// A sampler as written: where each sample's random numbers come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum SamplerDesc {
    /// Independent uniform numbers (the default), as Mitsuba 3's `independent`.
    #[default]
    Independent,
    /// Padded, Owen-scrambled Sobol' points, as pbrt-v4's `PaddedSobolSampler`: every draw
    /// stratified over a pixel's samples (best with a power-of-two `spp`).
    Sobol,
}

/// A pixel filter as written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum FilterDesc {
    /// Each sample inside its pixel (the default).
    #[default]
    Box,
    /// A Gaussian truncated at 4 standard deviations, as Mitsuba 3's `gaussian`.
    Gaussian {
        /// Standard deviation in pixels, in (0, 8] (default 0.5, as Mitsuba's).
        #[serde(default = "half_pixel")]
        stddev: Positive,
    },
}

fn half_pixel() -> Positive {
    Positive(0.5)
}

fn default_width() -> Count<MAX_SIDE> {
    Count(720)
}
fn default_height() -> Count<MAX_SIDE> {
    Count(576)
}
fn one<const M: u32>() -> Count<M> {
    Count(1)
}

impl TryFrom<FilmFields> for FilmDesc {
    type Error = String;
    fn try_from(f: FilmFields) -> Result<Self, String> {
        Film {
            width: f.width.0,
            height: f.height.0,
            spp: f.spp.0,
            transfer: f.transfer,
            sampler: match f.sampler {
                SamplerDesc::Independent => SamplerKind::Independent,
                SamplerDesc::Sobol => SamplerKind::Sobol,
            },
            filter: match f.filter {
                FilterDesc::Box => PixelFilter::Box,
                FilterDesc::Gaussian { stddev } if stddev.0 <= 8.0 => PixelFilter::Gaussian {
                    stddev: stddev.0 as f32,
                },
                FilterDesc::Gaussian { stddev } => {
                    return Err(format!(
                        "a Gaussian filter's stddev is at most 8 pixels, got {}",
                        stddev.0
                    ));
                }
            },
        }
        .checked()
        .map(FilmDesc)
    }
}

impl From<FilmDesc> for FilmFields {
    fn from(FilmDesc(f): FilmDesc) -> Self {
        FilmFields {
            width: Count(f.width),
            height: Count(f.height),
            spp: Count(f.spp),
            transfer: f.transfer,
            sampler: match f.sampler {
                SamplerKind::Independent => SamplerDesc::Independent,
                SamplerKind::Sobol => SamplerDesc::Sobol,
            },
            filter: match f.filter {
                PixelFilter::Box => FilterDesc::Box,
                PixelFilter::Gaussian { stddev } => FilterDesc::Gaussian {
                    stddev: Positive(stddev as f64),
                },
            },
        }
    }
}

/// A camera as written.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "CameraFields", into = "CameraFields")]
pub struct CameraDesc(pub CameraFields);

/// The camera variants as written; checked into [`CameraDesc`].
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum CameraFields {
    /// A perspective camera: a pinhole, or a thin lens with `aperture_radius` above 0.
    Perspective {
        /// Centre of projection.
        position: Point,
        /// A point the camera looks at (not equal to `position`).
        look_at: Point,
        /// Up hint (default `(0, 1, 0)`), not parallel to the view direction.
        #[serde(default = "y_up")]
        up: Direction,
        /// Vertical field of view in degrees, in (0, 180) (default 60).
        #[serde(default = "fov60")]
        fov: Fov,
        /// Radius of the lens's aperture in scene units, from 0 (default: a pinhole, every
        /// depth sharp) to 1e9: a thin lens, as Mitsuba 3's `thinlens`.
        #[serde(default)]
        aperture_radius: Aperture,
        /// Distance from the lens to the plane in focus, along the viewing direction, in
        /// scene units (default: the distance to `look_at`). Used with `aperture_radius`.
        #[serde(default)]
        focus_distance: Option<Positive>,
        /// `Left` (default, the course's: the image's right is `up x forward`) or `Right`
        /// (Mitsuba 3's: `forward x up`, the mirror image).
        #[serde(default, skip_serializing_if = "is_left")]
        handedness: Handedness,
    },
    /// A parallel projection.
    Orthographic {
        /// Centre of the image rectangle.
        position: Point,
        /// A point the camera looks at (not equal to `position`).
        look_at: Point,
        /// Up hint (default `(0, 1, 0)`), not parallel to the view direction.
        #[serde(default = "y_up")]
        up: Direction,
        /// Vertical extent of the image rectangle in scene units, > 0.
        height: Positive,
        /// As a perspective camera's.
        #[serde(default, skip_serializing_if = "is_left")]
        handedness: Handedness,
    },
}

fn is_left(h: &Handedness) -> bool {
    *h == Handedness::Left
}

fn y_up() -> Direction {
    Direction(glam::DVec3::Y)
}
fn fov60() -> Fov {
    Fov(60.0)
}

impl CameraFields {
    /// Which way the image's right runs.
    pub fn handedness(&self) -> Handedness {
        match *self {
            CameraFields::Perspective { handedness, .. }
            | CameraFields::Orthographic { handedness, .. } => handedness,
        }
    }

    /// Position, look-at point and up hint.
    pub fn frame(&self) -> (glam::DVec3, glam::DVec3, glam::DVec3) {
        match *self {
            CameraFields::Perspective {
                position,
                look_at,
                up,
                ..
            }
            | CameraFields::Orthographic {
                position,
                look_at,
                up,
                ..
            } => (position.0, look_at.0, up.0),
        }
    }
}

impl TryFrom<CameraFields> for CameraDesc {
    type Error = String;
    fn try_from(c: CameraFields) -> Result<Self, String> {
        Ok(CameraDesc(c))
    }
}

impl CameraDesc {
    /// Why this camera has no view: the field to blame (`look_at` or `up`) and the message
    /// with a fix; `None` when it is sound. Checked after parsing, where the field's place in
    /// the file is known (`super::load`).
    pub fn degenerate(&self) -> Option<(&'static str, String)> {
        let (position, look_at, up) = self.0.frame();
        let forward = look_at - position;
        if forward.length_squared() == 0.0 {
            return Some((
                "look_at",
                "degenerate camera: look_at equals position, so there is no view direction: \
                 move look_at to the point the camera should face"
                    .into(),
            ));
        }
        let f = forward.normalize();
        if f.cross(up.normalize()).length() < 1e-6 {
            // Suggest the world axis least aligned with the view.
            let a = f.abs();
            let axis = if a.x <= a.y && a.x <= a.z {
                "(1, 0, 0)"
            } else if a.y <= a.z {
                "(0, 1, 0)"
            } else {
                "(0, 0, 1)"
            };
            return Some((
                "up",
                format!(
                    "degenerate camera: up is parallel to the view direction (look_at - \
                     position), so the image has no vertical: choose another, e.g. \
                     `up: {axis}`"
                ),
            ));
        }
        None
    }
}

impl CameraDesc {
    /// The world's camera.
    pub fn to_world(&self) -> WorldCamera {
        let (position, look_at, up) = self.0.frame();
        let projection = match self.0 {
            CameraFields::Perspective {
                fov,
                aperture_radius,
                focus_distance,
                ..
            } => Projection::Perspective {
                fov: fov.0,
                lens: (aperture_radius.0 > 0.0).then(|| WorldLens {
                    radius: aperture_radius.0,
                    focus_distance: focus_distance.map_or((look_at - position).length(), |f| f.0),
                }),
            },
            CameraFields::Orthographic { height, .. } => {
                Projection::Orthographic { height: height.0 }
            }
        };
        WorldCamera {
            projection,
            position,
            look_at,
            up,
            handedness: self.0.handedness(),
        }
    }
}

impl From<CameraDesc> for CameraFields {
    fn from(c: CameraDesc) -> Self {
        c.0
    }
}

/// A shader as written: what a camera ray's colour means.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum ShaderDesc {
    /// `color` where the ray hits anything, the background elsewhere.
    Intersection {
        /// Colour of hits (default white).
        #[serde(default = "white")]
        color: Rgb,
    },
    /// `color * (1 - t / max_distance)`, clamped at 0, with `t` the hit distance.
    Depth {
        /// Distance at which the colour has faded to black, > 0.
        max_distance: Positive,
        /// Colour at distance 0 (default white).
        #[serde(default = "white")]
        color: Rgb,
    },
    /// The unit normal facing the viewer, mapped to a colour as `(n + 1) / 2`.
    Normal,
    /// Direct light from point and area lights at Phong hits (Eq. 3); mirrors and glass are
    /// followed; emitters are seen.
    Direct {
        /// Longest chain of consecutive mirror/glass bounces, at most 1024 (default 32).
        #[serde(default = "max_specular")]
        max_specular: UpTo<MAX_SPECULAR>,
        /// Area-light samples per shading point, 1 to 65536 (default 1): more give smoother soft
        /// shadows. No effect without emitters.
        #[serde(default = "one")]
        light_samples: Count<MAX_LIGHT_SAMPLES>,
    },
    /// The assignment's global shader: Eq. 1 with the ambient (Eq. 2), hemisphere (Eq. 4) and
    /// normal-plus-reflection estimators of the indirect term.
    Global {
        /// Hemisphere samples `n` at the first Phong hit (default 64).
        #[serde(default = "global_samples")]
        samples: Count<MAX_GLOBAL_SAMPLES>,
        /// Phong hits before the ambient term takes over, `D` (default 3).
        #[serde(default = "global_depth")]
        max_depth: UpTo<MAX_GLOBAL_DEPTH>,
        /// Ambient radiance `a_t` (default `(0.3, 0.3, 0.3)`).
        #[serde(default = "ambient")]
        ambient: Rgb,
        /// Longest chain of consecutive mirror/glass bounces, at most 1024 (default 32).
        #[serde(default = "max_specular")]
        max_specular: UpTo<MAX_SPECULAR>,
        /// Area-light samples per shading point, 1 to 65536 (default 1). No effect without
        /// emitters.
        #[serde(default = "one")]
        light_samples: Count<MAX_LIGHT_SAMPLES>,
    },
    /// The reference path tracer under the scene's `model`.
    Path {
        /// Largest number of bounces of any kind (default: none, Russian roulette ends paths).
        #[serde(default)]
        max_depth: Option<UpTo<MAX_PATH_DEPTH>>,
        /// Bounces before Russian roulette starts, at most 1024 (default 5).
        #[serde(default = "rr_depth")]
        rr_depth: UpTo<MAX_PATH_DEPTH>,
        /// Direction sampling at Phong vertices: `Uniform`, `Cosine` or `Brdf` (default).
        #[serde(default)]
        sampling: Sampling,
        /// How area lights are gathered under the Physical model: `Mis` (default), `Light`
        /// (next-event estimation only) or `Brdf` (sampled rays only). The Course model always
        /// samples lights.
        #[serde(default)]
        lights: LightSampling,
        /// Lights sampled at each vertex under the Physical model: `All` (default: every point
        /// light, one shadow ray each, and one area-light sample), `One` (one light of all,
        /// chosen by power: one shadow ray) or `Importance` (one light, the point lights' share
        /// spent on each by its unshadowed contribution `I cos / d^2` at the vertex). The Course
        /// model sums its point lights.
        #[serde(default)]
        lights_per_vertex: LightsPerVertex,
    },
}

fn rr_depth() -> UpTo<MAX_PATH_DEPTH> {
    UpTo(5)
}

fn white() -> Rgb {
    Rgb::grey(1.0)
}
fn max_specular() -> UpTo<MAX_SPECULAR> {
    UpTo(32)
}
fn global_samples() -> Count<MAX_GLOBAL_SAMPLES> {
    Count(64)
}
fn global_depth() -> UpTo<MAX_GLOBAL_DEPTH> {
    UpTo(3)
}
fn ambient() -> Rgb {
    Rgb::grey(0.3)
}

impl ShaderDesc {
    /// The shader with its parameters.
    pub fn to_world(&self) -> Shader {
        let rgb = |c: Rgb| c.0.as_vec3a();
        match *self {
            ShaderDesc::Intersection { color } => Shader::Intersection { color: rgb(color) },
            ShaderDesc::Depth {
                max_distance,
                color,
            } => Shader::Depth {
                max_distance: max_distance.0 as f32,
                color: rgb(color),
            },
            ShaderDesc::Normal => Shader::Normal,
            ShaderDesc::Direct {
                max_specular,
                light_samples,
            } => Shader::Direct {
                max_specular: max_specular.0,
                light_samples: light_samples.0,
            },
            ShaderDesc::Global {
                samples,
                max_depth,
                ambient,
                max_specular,
                light_samples,
            } => Shader::Global(Global {
                samples: samples.0,
                max_depth: max_depth.0,
                ambient: rgb(ambient),
                max_specular: max_specular.0,
                light_samples: light_samples.0,
            }),
            ShaderDesc::Path {
                max_depth,
                rr_depth,
                sampling,
                lights,
                lights_per_vertex,
            } => Shader::Path(Path {
                max_depth: max_depth.map(|d| d.0),
                rr_depth: rr_depth.0,
                sampling,
                lights,
                lights_per_vertex,
            }),
        }
    }
}

/// A material as written: inline, or a name from the scene's `materials` table.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum MaterialDesc {
    /// A material of the scene's `materials` table (only in an entity's `material` slot).
    Named(String),
    /// Diffuse plus glossy: `r(wi, wo) = kd (wi.n) + ks (wo.wr)^shininess`.
    Phong {
        /// Diffuse coefficient, a reflectance in [0, 1] per channel, or a texture.
        kd: Paint,
        /// Specular coefficient, a reflectance in [0, 1] per channel, or a texture (default
        /// black).
        #[serde(default = "black_paint")]
        ks: Paint,
        /// Phong exponent, from 0 to 1e6 (default 1).
        #[serde(default = "shininess")]
        shininess: NonNegative,
    },
    /// A perfect mirror tinted by `color`.
    Mirror {
        /// Tint, a reflectance in [0, 1] per channel, or a texture (default white).
        #[serde(default = "white_paint")]
        color: Paint,
    },
    /// A smooth metal (Mitsuba 3's `conductor`): the mirror reflection weighted by the Fresnel
    /// term of the complex index `eta + i k` per channel, times `specular_reflectance`. The
    /// index comes from a named metal (`material`: "Au", "Ag", "Al", "Cu", "Cr", or "none", a
    /// perfect mirror, the default) or from `eta` and `k` given together.
    Conductor {
        /// A metal of Mitsuba's table, instead of `eta` and `k`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        material: Option<MetalName>,
        /// Real part of the index per channel, with `k`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        eta: Option<IorPart>,
        /// Imaginary part (absorption) per channel, with `eta`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        k: Option<IorPart>,
        /// Tint, a reflectance in [0, 1] per channel (default white).
        #[serde(default = "white_paint")]
        specular_reflectance: Paint,
    },
    /// A rough metal (Mitsuba 3's `roughconductor`): microfacets, each a [`Conductor`](
    /// MaterialDesc::Conductor)'s mirror, distributed by `distribution` with roughness `alpha`,
    /// or `alpha_u` along the surface's tangent and `alpha_v` across it.
    RoughConductor {
        /// `Ggx` (default) or `Beckmann`.
        #[serde(default)]
        distribution: Distribution,
        /// Isotropic roughness, from 1e-4 to 1 (default 0.1 unless `alpha_u` and `alpha_v`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha: Option<Paint<Roughness>>,
        /// Roughness along the tangent, with `alpha_v`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_u: Option<Paint<Roughness>>,
        /// Roughness across the tangent, with `alpha_u`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_v: Option<Paint<Roughness>>,
        /// A metal of Mitsuba's table, instead of `eta` and `k` (default "none": Fresnel 1).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        material: Option<MetalName>,
        /// Real part of the index per channel, with `k`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        eta: Option<IorPart>,
        /// Imaginary part (absorption) per channel, with `eta`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        k: Option<IorPart>,
        /// Tint, a reflectance in [0, 1] per channel (default white).
        #[serde(default = "white_paint")]
        specular_reflectance: Paint,
        /// Which normals are sampled: `Visible` (default) or `Full`.
        #[serde(default)]
        sampling: NormalSampling,
    },
    /// A rough interface between two dielectrics (Mitsuba 3's `roughdielectric`): frosted
    /// glass. The inside (index `int_ior`) is where the shape's normal points away from.
    RoughDielectric {
        /// `Ggx` (default) or `Beckmann`.
        #[serde(default)]
        distribution: Distribution,
        /// Isotropic roughness, from 1e-4 to 1 (default 0.1 unless `alpha_u` and `alpha_v`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha: Option<Paint<Roughness>>,
        /// Roughness along the tangent, with `alpha_v`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_u: Option<Paint<Roughness>>,
        /// Roughness across the tangent, with `alpha_u`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_v: Option<Paint<Roughness>>,
        /// Index of refraction inside, from 0.01 to 100 (default 1.5046, BK7 glass).
        #[serde(default = "bk7")]
        int_ior: Ior,
        /// Index of refraction outside (default 1.000277, air); must differ from `int_ior`.
        #[serde(default = "air")]
        ext_ior: Ior,
        /// Tint of the reflection, a reflectance per channel (default white).
        #[serde(default = "white_paint")]
        specular_reflectance: Paint,
        /// Tint of the transmission, a reflectance per channel (default white).
        #[serde(default = "white_paint")]
        specular_transmittance: Paint,
        /// Which normals are sampled: `Visible` (default) or `Full`.
        #[serde(default)]
        sampling: NormalSampling,
    },
    /// A diffuse base under a rough dielectric coating (Mitsuba 3's `roughplastic`; isotropic).
    RoughPlastic {
        /// `Ggx` (default) or `Beckmann`.
        #[serde(default)]
        distribution: Distribution,
        /// Roughness of the coating, from 1e-4 to 1 (default 0.1).
        #[serde(default = "alpha")]
        alpha: Roughness,
        /// Index of refraction of the coating (default 1.49, polypropylene).
        #[serde(default = "polypropylene")]
        int_ior: Ior,
        /// Index of refraction outside (default 1.000277, air); must differ from `int_ior`.
        #[serde(default = "air")]
        ext_ior: Ior,
        /// Reflectance of the base per channel (default 0.5).
        #[serde(default = "half_paint")]
        diffuse_reflectance: Paint,
        /// Tint of the coating's reflection per channel (default white).
        #[serde(default = "white_paint")]
        specular_reflectance: Paint,
        /// Account for the base's colour in the light trapped under the coating (default
        /// false, as Mitsuba).
        #[serde(default)]
        nonlinear: bool,
        /// Which normals are sampled: `Visible` (default) or `Full`.
        #[serde(default)]
        sampling: NormalSampling,
    },
    /// A diffuse base under a smooth dielectric coating (Mitsuba 3's `plastic`).
    Plastic {
        /// Index of refraction of the coating (default 1.49, polypropylene).
        #[serde(default = "polypropylene")]
        int_ior: Ior,
        /// Index of refraction outside (default 1.000277, air); must differ from `int_ior`.
        #[serde(default = "air")]
        ext_ior: Ior,
        /// Reflectance of the base per channel (default 0.5).
        #[serde(default = "half_paint")]
        diffuse_reflectance: Paint,
        /// Tint of the coating's reflection per channel (default white).
        #[serde(default = "white_paint")]
        specular_reflectance: Paint,
        /// Account for the base's colour in the light trapped under the coating (default
        /// false, as Mitsuba).
        #[serde(default)]
        nonlinear: bool,
    },
    /// A perfect refractor (inside index `ior`, outside air) tinted by `color`.
    Transmissive {
        /// Index of refraction, from 0.01 to 100.
        ior: Ior,
        /// Tint, a reflectance in [0, 1] per channel, or a texture (default white).
        #[serde(default = "white_paint")]
        color: Paint,
    },
    /// Mitsuba 3's `normalmap`: `material` shaded with the normal a tangent-space normal map
    /// gives (each texel `c` the normal `2 c - 1` in the frame of the surface's `dp/du`,
    /// the normal's cross product with it, and the normal). The map is read as stored, never
    /// decoded from sRGB.
    NormalMap {
        /// The map, an `Image(...)` (or any texture).
        normal_map: TextureDesc,
        /// The material it bends, written inline (not `Named`, not another `NormalMap`).
        material: Box<MaterialDesc>,
    },
}

/// A material parameter as written: a constant (a reflectance `(r, g, b)` by default, or a
/// [`Roughness`]), or a texture looked up at each hit.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Paint<T = Reflectance> {
    /// The same everywhere: each channel in [0, 1], or a roughness.
    Constant(T),
    /// A texture (its values clamped to the constant's range where looked up).
    Texture(TextureDesc),
}

fn black_paint() -> Paint {
    Paint::Constant(black())
}
fn white_paint() -> Paint {
    Paint::Constant(unit())
}
fn half_paint() -> Paint {
    Paint::Constant(half())
}

impl Paint {
    /// The constant, or white in place of a texture (the material's other checks see a
    /// surface that reflects; the texture replaces it at every hit).
    fn constant(&self) -> glam::Vec3A {
        match self {
            Paint::Constant(r) => r.0.as_vec3a(),
            Paint::Texture(_) => glam::Vec3A::ONE,
        }
    }
}

impl Paint<Roughness> {
    /// The roughness, or Mitsuba's default 0.1 in place of a texture (which replaces it at
    /// every hit).
    fn roughness(&self) -> Roughness {
        match self {
            Paint::Constant(r) => *r,
            Paint::Texture(_) => Roughness(0.1),
        }
    }
}

impl<T> Paint<T> {
    /// The texture, read by `load` (a path as written and `raw`).
    fn texture(&self, load: &mut ImageLoader) -> Result<Option<Texture>, String> {
        match self {
            Paint::Constant(_) => Ok(None),
            Paint::Texture(t) => t.to_world(load).map(Some),
        }
    }
}

/// Reads an image a texture names: its path as written and `raw`, to its texels and the file
/// they came from.
pub type ImageLoader<'a> = dyn FnMut(&str, bool) -> Result<(Arc<Raster>, PathBuf), String> + 'a;

/// A texture as written.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum TextureDesc {
    /// Mitsuba 3's `checkerboard`: `color0` where the fractional parts of `u` and `v` are both
    /// below or both above 1/2, `color1` elsewhere.
    Checkerboard {
        /// Default 0.4, as Mitsuba's.
        #[serde(default = "checker0")]
        color0: Reflectance,
        /// Default 0.2, as Mitsuba's.
        #[serde(default = "checker1")]
        color1: Reflectance,
        /// Map of the coordinates (default none).
        #[serde(default)]
        uv_transform: UvTransformDesc,
    },
    /// Mitsuba 3's `bitmap`: an image (PNG decoded from sRGB unless `raw`, or OpenEXR),
    /// relative to this file's folder.
    Image {
        /// The image file.
        path: String,
        /// `Bilinear` (default), `Nearest` or `Trilinear` (MIP levels by the footprint).
        #[serde(default)]
        filter: TexelFilter,
        /// `Repeat` (default), `Clamp` or `Mirror`.
        #[serde(default)]
        wrap: Wrap,
        /// Take PNG values as stored, not decoded from sRGB (default false).
        #[serde(default)]
        raw: bool,
        /// Map of the coordinates (default none).
        #[serde(default)]
        uv_transform: UvTransformDesc,
    },
}

fn checker0() -> Reflectance {
    Reflectance(glam::DVec3::splat(0.4))
}
fn checker1() -> Reflectance {
    Reflectance(glam::DVec3::splat(0.2))
}

/// A map of texture coordinates as written: scale, then rotate (degrees), then offset.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(rename = "UvTransform", deny_unknown_fields)]
pub struct UvTransformDesc {
    /// Factors on `u` and `v` (default `(1, 1)`).
    #[serde(default = "unit_uv")]
    pub scale: (f64, f64),
    /// Rotation in degrees, counter-clockwise in `(u, v)` (default 0).
    #[serde(default)]
    pub rotate: f64,
    /// Added last (default `(0, 0)`).
    #[serde(default)]
    pub offset: (f64, f64),
}

impl Default for UvTransformDesc {
    fn default() -> Self {
        UvTransformDesc {
            scale: (1.0, 1.0),
            rotate: 0.0,
            offset: (0.0, 0.0),
        }
    }
}

fn unit_uv() -> (f64, f64) {
    (1.0, 1.0)
}

impl UvTransformDesc {
    /// The world's map, or why its numbers are not (each finite and within 1e9).
    fn to_world(self) -> Result<UvTransform, String> {
        let all = [
            self.scale.0,
            self.scale.1,
            self.rotate,
            self.offset.0,
            self.offset.1,
        ];
        if let Some(bad) = all.iter().find(|v| !v.is_finite() || v.abs() > 1e9) {
            return Err(format!(
                "uv_transform: {bad} is not a finite number within 1e9"
            ));
        }
        if self.scale.0.abs() < 1e-9 || self.scale.1.abs() < 1e-9 {
            return Err(format!(
                "uv_transform: a scale of ({}, {}) flattens the texture to a line; each factor \
                 must be at least 1e-9 in size",
                self.scale.0, self.scale.1
            ));
        }
        Ok(UvTransform {
            scale: glam::Vec2::new(self.scale.0 as f32, self.scale.1 as f32),
            rotate: self.rotate as f32,
            offset: glam::Vec2::new(self.offset.0 as f32, self.offset.1 as f32),
        })
    }
}

impl TextureDesc {
    /// The world's texture, its image read by `load`.
    pub fn to_world(&self, load: &mut ImageLoader) -> Result<Texture, String> {
        Ok(match self {
            TextureDesc::Checkerboard {
                color0,
                color1,
                uv_transform,
            } => Texture {
                kind: TextureKind::Checkerboard(Checkerboard {
                    color0: color0.0.as_vec3a(),
                    color1: color1.0.as_vec3a(),
                }),
                transform: uv_transform.to_world()?,
            },
            TextureDesc::Image {
                path,
                filter,
                wrap,
                raw,
                uv_transform,
            } => Texture {
                kind: TextureKind::Image({
                    let (raster, source) = load(path, *raw)?;
                    // The MIP pyramid, for trilinear lookups only.
                    let mips = match filter {
                        TexelFilter::Trilinear => mip_levels(&raster),
                        _ => Vec::new(),
                    };
                    ImageTexture {
                        raster,
                        mips: Arc::new(mips),
                        source,
                        raw: *raw,
                        filter: *filter,
                        wrap: *wrap,
                    }
                }),
                transform: uv_transform.to_world()?,
            },
        })
    }
}

impl MaterialDesc {
    /// The textures of its parameters (none for a `Named` reference), their images read by
    /// `load`.
    pub fn textures(&self, load: &mut ImageLoader) -> Result<MaterialTextures, String> {
        Ok(match self {
            MaterialDesc::Phong { kd, ks, .. } => MaterialTextures {
                reflectance: kd.texture(load)?,
                specular: ks.texture(load)?,
                ..Default::default()
            },
            MaterialDesc::Mirror { color } | MaterialDesc::Transmissive { color, .. } => {
                MaterialTextures {
                    reflectance: color.texture(load)?,
                    ..Default::default()
                }
            }
            MaterialDesc::Conductor {
                specular_reflectance,
                ..
            } => MaterialTextures {
                specular: specular_reflectance.texture(load)?,
                ..Default::default()
            },
            MaterialDesc::RoughConductor {
                alpha,
                alpha_u,
                alpha_v,
                specular_reflectance,
                ..
            } => {
                let (alpha_u, alpha_v) = alpha_textures(alpha, alpha_u, alpha_v, load)?;
                MaterialTextures {
                    specular: specular_reflectance.texture(load)?,
                    alpha_u,
                    alpha_v,
                    ..Default::default()
                }
            }
            MaterialDesc::RoughDielectric {
                alpha,
                alpha_u,
                alpha_v,
                specular_reflectance,
                specular_transmittance,
                ..
            } => {
                let (alpha_u, alpha_v) = alpha_textures(alpha, alpha_u, alpha_v, load)?;
                MaterialTextures {
                    specular: specular_reflectance.texture(load)?,
                    transmittance: specular_transmittance.texture(load)?,
                    alpha_u,
                    alpha_v,
                    ..Default::default()
                }
            }
            MaterialDesc::RoughPlastic {
                diffuse_reflectance,
                specular_reflectance,
                ..
            }
            | MaterialDesc::Plastic {
                diffuse_reflectance,
                specular_reflectance,
                ..
            } => MaterialTextures {
                reflectance: diffuse_reflectance.texture(load)?,
                specular: specular_reflectance.texture(load)?,
                ..Default::default()
            },
            MaterialDesc::Named(_) => MaterialTextures::default(),
            MaterialDesc::NormalMap {
                normal_map,
                material,
            } => {
                // The map's values are data: read raw.
                let mut map = normal_map.clone();
                if let TextureDesc::Image { raw, .. } = &mut map {
                    *raw = true;
                }
                let map = map.to_world(load)?;
                MaterialTextures {
                    normal_map: Some(map),
                    ..material.textures(load)?
                }
            }
        })
    }

    /// The material, `Ok(None)` for a `Named` reference (resolved by the loader), or why the
    /// fields do not make one (a conductor given both a named metal and `eta` or `k`, or only
    /// one of `eta` and `k`). A textured parameter is white here ([`MaterialDesc::textures`]
    /// replaces it at each hit).
    pub fn to_world(&self) -> Result<Option<Material>, String> {
        Ok(Some(match self {
            MaterialDesc::Named(_) => return Ok(None),
            MaterialDesc::NormalMap { material, .. } => match material.as_ref() {
                MaterialDesc::Named(_) | MaterialDesc::NormalMap { .. } => {
                    return Err(
                        "a NormalMap's `material` is written inline, not `Named` nor \
                                another `NormalMap`: write the material itself, as \
                                `material: Phong(kd: (0.8, 0.8, 0.8))`"
                            .into(),
                    );
                }
                inner => return inner.to_world(),
            },
            MaterialDesc::Conductor {
                material,
                eta,
                k,
                specular_reflectance,
            } => Material::Conductor(conductor(material, eta, k, specular_reflectance)?),
            MaterialDesc::RoughConductor {
                distribution,
                alpha,
                alpha_u,
                alpha_v,
                material,
                eta,
                k,
                specular_reflectance,
                sampling,
            } => {
                let microfacet = roughness(*distribution, alpha, alpha_u, alpha_v, *sampling)?;
                let metal = conductor(material, eta, k, specular_reflectance)?;
                Material::Bsdf(Bsdf::RoughConductor(RoughConductor { microfacet, metal }))
            }
            MaterialDesc::RoughDielectric {
                distribution,
                alpha,
                alpha_u,
                alpha_v,
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
                sampling,
            } => Material::Bsdf(Bsdf::RoughDielectric(RoughDielectric {
                microfacet: roughness(*distribution, alpha, alpha_u, alpha_v, *sampling)?,
                eta: relative_ior(*int_ior, *ext_ior)?,
                specular_reflectance: specular_reflectance.constant(),
                specular_transmittance: specular_transmittance.constant(),
            })),
            MaterialDesc::RoughPlastic {
                distribution,
                alpha,
                int_ior,
                ext_ior,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
                sampling,
            } => Material::Bsdf(Bsdf::RoughPlastic(RoughPlastic::new(
                roughness(
                    *distribution,
                    &Some(Paint::Constant(*alpha)),
                    &None,
                    &None,
                    *sampling,
                )?,
                relative_ior(*int_ior, *ext_ior)?,
                diffuse_reflectance.constant(),
                specular_reflectance.constant(),
                *nonlinear,
            ))),
            MaterialDesc::Plastic {
                int_ior,
                ext_ior,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
            } => Material::Bsdf(Bsdf::Plastic(Plastic {
                coating: Coating::smooth(
                    relative_ior(*int_ior, *ext_ior)?,
                    diffuse_reflectance.constant(),
                    specular_reflectance.constant(),
                    *nonlinear,
                ),
            })),
            MaterialDesc::Phong { kd, ks, shininess } => Material::Phong(Phong {
                kd: kd.constant(),
                ks: ks.constant(),
                shininess: shininess.0 as f32,
            }),
            MaterialDesc::Mirror { color } => Material::Mirror(Mirror {
                color: color.constant(),
            }),
            MaterialDesc::Transmissive { ior, color } => Material::Transmissive(Transmissive {
                ior: ior.0 as f32,
                color: color.constant(),
            }),
        }))
    }
}

/// The metal of a conductor's fields: a named metal, or `eta` and `k`, or none (Fresnel 1).
fn conductor(
    material: &Option<MetalName>,
    eta: &Option<IorPart>,
    k: &Option<IorPart>,
    specular_reflectance: &Paint,
) -> Result<Conductor, String> {
    let (eta, k) = match (material, eta, k) {
        (Some(m), None, None) => m.0.eta_k(),
        (None, Some(eta), Some(k)) => (eta.0.as_vec3a(), k.0.as_vec3a()),
        (None, None, None) => Metal::None.eta_k(),
        (Some(_), ..) => {
            return Err("a conductor takes a named `material` or `eta` and `k`, not both".into());
        }
        _ => return Err("a conductor's `eta` and `k` go together: give both".into()),
    };
    Ok(Conductor {
        eta,
        k,
        specular_reflectance: specular_reflectance.constant(),
    })
}

/// The microfacet distribution of a rough material's fields: `alpha`, or `alpha_u` and
/// `alpha_v` together, or neither (alpha 0.1, Mitsuba's default).
fn roughness(
    distribution: Distribution,
    alpha: &Option<Paint<Roughness>>,
    alpha_u: &Option<Paint<Roughness>>,
    alpha_v: &Option<Paint<Roughness>>,
    sampling: NormalSampling,
) -> Result<Microfacet, String> {
    let (ax, ay) = match (alpha, alpha_u, alpha_v) {
        (Some(a), None, None) => (a.roughness().0, a.roughness().0),
        (None, Some(u), Some(v)) => (u.roughness().0, v.roughness().0),
        (None, None, None) => (0.1, 0.1),
        (Some(_), ..) => {
            return Err(
                "a rough material takes `alpha` or `alpha_u` and `alpha_v`, not both".into(),
            );
        }
        _ => return Err("`alpha_u` and `alpha_v` go together: give both".into()),
    };
    Ok(Microfacet {
        distribution,
        alpha_x: ax as f32,
        alpha_y: ay as f32,
        sampling,
    })
}

/// The textures of a rough material's roughness: `alpha`'s along and across the tangent
/// alike, or `alpha_u`'s and `alpha_v`'s (the fields' combination is checked by
/// [`roughness`]).
fn alpha_textures(
    alpha: &Option<Paint<Roughness>>,
    alpha_u: &Option<Paint<Roughness>>,
    alpha_v: &Option<Paint<Roughness>>,
    load: &mut ImageLoader,
) -> Result<(Option<Texture>, Option<Texture>), String> {
    let read = |p: &Option<Paint<Roughness>>, load: &mut ImageLoader| match p {
        Some(p) => p.texture(load),
        None => Ok(None),
    };
    Ok(match alpha {
        Some(a) => {
            let t = read(&Some(a.clone()), load)?;
            (t.clone(), t)
        }
        None => (read(alpha_u, load)?, read(alpha_v, load)?),
    })
}

/// `int_ior / ext_ior`, or why the two indices make no interface.
fn relative_ior(int_ior: Ior, ext_ior: Ior) -> Result<f32, String> {
    let eta = (int_ior.0 / ext_ior.0) as f32;
    if (eta - 1.0).abs() < 1e-4 {
        return Err(format!(
            "`int_ior` ({}) and `ext_ior` ({}) must differ by 1e-4 relative or more: equal \
             indices make no interface",
            int_ior.0, ext_ior.0
        ));
    }
    Ok(eta)
}

/// An entry of the `materials` table: any material written inline, never `Named`; with what
/// was written, for its textures (read where the table's file is).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(try_from = "MaterialDesc")]
pub struct TableMaterial(pub Material, pub MaterialDesc);

impl TryFrom<MaterialDesc> for TableMaterial {
    type Error = String;
    fn try_from(m: MaterialDesc) -> Result<Self, String> {
        match m.to_world()? {
            Some(world) => Ok(TableMaterial(world, m)),
            None => Err(format!(
                "an entry of `materials` cannot be {m:?}: write the material itself, as \
                 `Phong(kd: (0.8, 0.8, 0.8))`"
            )),
        }
    }
}

fn black() -> Reflectance {
    Reflectance(glam::DVec3::ZERO)
}
fn unit() -> Reflectance {
    Reflectance(glam::DVec3::ONE)
}
fn shininess() -> NonNegative {
    NonNegative(1.0)
}
fn half() -> Reflectance {
    Reflectance(glam::DVec3::splat(0.5))
}
fn alpha() -> Roughness {
    Roughness(0.1)
}
fn bk7() -> Ior {
    Ior(1.5046)
}
fn air() -> Ior {
    Ior(1.000277)
}
fn polypropylene() -> Ior {
    Ior(1.49)
}

/// A shape as written, in scene units.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum ShapeDesc {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Point,
        /// Radius, > 0.
        radius: Positive,
    },
    /// An infinite plane, visible from both sides.
    InfinitePlane {
        /// Any point of the plane.
        point: Point,
        /// Normal (non-zero; normalised when used).
        normal: Direction,
    },
    /// A triangle, visible from both sides; its normal follows the winding `(b - a) x (c - a)`.
    /// A zero-area triangle is ignored with a warning.
    Triangle {
        /// First vertex.
        a: Point,
        /// Second vertex.
        b: Point,
        /// Third vertex.
        c: Point,
    },
    /// The parallelogram `corner + s u + t v` for `s, t` in [0, 1] (a rectangle when `u` and `v`
    /// are perpendicular), visible from both sides, with normal `u x v` (the side a one-sided
    /// emitter lights). `u` and `v` must not be parallel.
    Rectangle {
        /// One corner.
        corner: Point,
        /// First edge from the corner.
        u: Point,
        /// Second edge from the corner.
        v: Point,
    },
    /// Triangles sharing a vertex list: `faces` index `vertices` (counter-clockwise winding).
    TriangleMesh {
        /// Vertex positions.
        vertices: Vec<Point>,
        /// Triangles as triples of indices into `vertices`; at least one.
        #[serde(deserialize_with = "super::values::faces")]
        faces: Vec<(u32, u32, u32)>,
        /// Optional per-vertex normals for smooth shading (same count as `vertices`).
        #[serde(default)]
        normals: Vec<Direction>,
    },
    /// A Wavefront OBJ file, relative to the scene file's folder: positions, faces
    /// (triangulated), and vertex normals for smooth shading when the file has them.
    Mesh {
        /// Path of the mesh file: Wavefront OBJ, Stanford PLY (`.ply`) or Mitsuba serialized
        /// (`.serialized`).
        path: String,
        /// Which normals shade it: `File` (default: the file's vertex normals, each face's
        /// own without them), `Faces` (each face's own, always; Mitsuba 3's `face_normals`) or
        /// `Smooth` (the file's, else computed from the faces around each vertex weighted by
        /// their angles there, as Mitsuba 3 computes them by default).
        #[serde(default, skip_serializing_if = "MeshNormals::is_file")]
        normals: MeshNormals,
        /// Which mesh of a Mitsuba `.serialized` file (default 0, the first).
        #[serde(default, skip_serializing_if = "is_zero")]
        shape_index: u32,
        /// Turn every face and normal around (default false; Mitsuba 3's `flip_normals`): an
        /// emitting mesh then emits from its other side, and glass has its inside outside.
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        flip_normals: bool,
    },
}

fn is_zero(v: &u32) -> bool {
    *v == 0
}

/// Which normals shade a mesh read from a file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum MeshNormals {
    /// The file's vertex normals; flat faces without them.
    #[default]
    File,
    /// Flat faces, whatever the file holds.
    Faces,
    /// The file's vertex normals, else angle-weighted ones computed from the faces.
    Smooth,
}

impl MeshNormals {
    fn is_file(&self) -> bool {
        *self == MeshNormals::File
    }
}

impl ShapeDesc {
    /// The world's shape; `load_mesh` reads the file of a `Mesh` (a path relative to the scene
    /// file) and says why it cannot.
    pub fn to_world(
        &self,
        load_mesh: impl FnOnce(&str, u32) -> Result<MeshData, String>,
    ) -> Result<WorldShape, String> {
        Ok(match self {
            ShapeDesc::Sphere { center, radius } => WorldShape::Sphere {
                center: center.0,
                radius: radius.0,
            },
            ShapeDesc::InfinitePlane { point, normal } => WorldShape::Plane {
                point: point.0,
                normal: normal.0,
            },
            ShapeDesc::Triangle { a, b, c } => WorldShape::Triangle { v: [a.0, b.0, c.0] },
            ShapeDesc::Rectangle { corner, u, v } => WorldShape::Rectangle {
                corner: corner.0,
                u: u.0,
                v: v.0,
            },
            ShapeDesc::TriangleMesh {
                vertices,
                faces,
                normals,
            } => WorldShape::Mesh(Arc::new(MeshData {
                positions: vertices.iter().map(|p| p.0).collect(),
                normals: normals.iter().map(|n| n.0).collect(),
                faces: faces.iter().map(|&(i, j, k)| [i, j, k]).collect(),
                uvs: Vec::new(),
            })),
            ShapeDesc::Mesh {
                path,
                normals,
                shape_index,
                flip_normals,
            } => {
                let mut mesh = load_mesh(path, *shape_index)?;
                if *flip_normals {
                    for f in &mut mesh.faces {
                        f.swap(1, 2);
                    }
                    for n in &mut mesh.normals {
                        *n = -*n;
                    }
                }
                match normals {
                    MeshNormals::File => {}
                    MeshNormals::Faces => mesh.normals.clear(),
                    MeshNormals::Smooth if mesh.normals.is_empty() => {
                        mesh.normals =
                            crate::mesh::angle_weighted_normals(&mesh.positions, &mesh.faces);
                    }
                    MeshNormals::Smooth => {}
                }
                WorldShape::Mesh(Arc::new(mesh))
            }
        })
    }
}

/// A transform applied to an entity's shape: scale, then rotate (degrees about x, then y, then
/// z), then translate. A sphere takes only a uniform scale.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(rename = "Transform", deny_unknown_fields)]
pub struct TransformDesc {
    /// Scale per axis (default `(1, 1, 1)`); no component zero.
    #[serde(default = "unit_scale")]
    pub scale: Scale,
    /// Rotation in degrees about x, then y, then z (default none).
    #[serde(default = "origin")]
    pub rotate: Point,
    /// Translation (default none).
    #[serde(default = "origin")]
    pub translate: Point,
}

fn unit_scale() -> Scale {
    Scale(glam::DVec3::ONE)
}
fn origin() -> Point {
    Point(glam::DVec3::ZERO)
}

impl TransformDesc {
    /// The world's transform.
    pub fn to_world(&self) -> Transform {
        Transform {
            scale: self.scale.0,
            rotate: self.rotate.0,
            translate: self.translate.0,
        }
    }
}

/// A light as written.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// An isotropic point light: incident radiance `intensity / d^2`.
    Point {
        /// Position.
        position: Point,
        /// Radiant intensity, W/sr per channel, >= 0.
        intensity: Rgb,
    },
    /// A spot light (Mitsuba 3's `spot`): `intensity` within `beam_width` of `direction`,
    /// falling linearly in the angle to zero at `cutoff_angle`.
    Spot {
        /// Position.
        position: Point,
        /// The direction it points along.
        direction: Direction,
        /// Radiant intensity on the axis, W/sr per channel, >= 0.
        intensity: Rgb,
        /// Half-angle in degrees beyond which it is black, in (0, 90] (default 20, as
        /// Mitsuba's).
        #[serde(default = "spot_cutoff")]
        cutoff_angle: SpotAngle,
        /// Half-angle in degrees of the full beam, in (0, cutoff_angle] (default three
        /// quarters of `cutoff_angle`, as Mitsuba's).
        #[serde(default)]
        beam_width: Option<SpotAngle>,
    },
    /// A directional light, a sun at infinity (Mitsuba 3's `directional`): light travelling
    /// along `direction` with `irradiance` on a surface facing it.
    Directional {
        /// The direction the light travels in (from the sun towards the scene).
        direction: Direction,
        /// Irradiance on a surface facing the light, W/m^2 per channel, >= 0.
        irradiance: Rgb,
    },
    /// An environment light (Mitsuba 3's `envmap` and `constant`): radiance arriving from
    /// infinitely far away in every direction, from a latitude-longitude `image` or a constant
    /// `radiance` (give one). Escaped rays see it; a scene has at most one, and no `background`
    /// beside it.
    Environment {
        /// A latitude-longitude image of the radiance (OpenEXR, linear; or PNG, decoded from
        /// sRGB), relative to this file's folder: its top row is the zenith (+y), its left
        /// edge looks along -z and its centre along +z, as Mitsuba's `envmap`.
        #[serde(default)]
        image: Option<String>,
        /// A constant sky's radiance, W/(m^2 sr) per channel, >= 0.
        #[serde(default)]
        radiance: Option<Rgb>,
        /// A factor on the radiance, >= 0 (default 1).
        #[serde(default = "unit_scale_factor")]
        scale: NonNegative,
        /// Rotation of the sky in degrees about x, then y, then z (default none), as a shape's
        /// `Transform(rotate: ...)`.
        #[serde(default = "origin")]
        rotate: Point,
    },
}

/// Why an environment without an image or a radiance cannot be.
const ENVIRONMENT_NEEDS: &str = "an Environment needs an `image: \"sky.exr\"` (a \
                                 latitude-longitude map) or a constant `radiance: (r, g, b)`";

fn unit_scale_factor() -> NonNegative {
    NonNegative(1.0)
}

/// A light as the world holds it: a light source placed in the world, or its sky.
#[derive(Clone, Debug, PartialEq)]
pub enum LightComponent {
    /// A point, spot or directional light.
    Light(WorldLight),
    /// The environment light.
    Environment(WorldEnvironment),
}

fn spot_cutoff() -> SpotAngle {
    SpotAngle(20.0)
}

impl LightDesc {
    /// Why this light cannot be: the field to blame and the message; `None` when it is sound.
    /// Checked after parsing, where the field's place in the file is known (`super::load`).
    pub fn invalid(&self) -> Option<(&'static str, String)> {
        match *self {
            LightDesc::Environment {
                image: Some(_),
                radiance: Some(_),
                ..
            } => Some((
                "radiance",
                "an Environment takes an `image` or a constant `radiance`, not both: remove one"
                    .into(),
            )),
            LightDesc::Environment {
                image: None,
                radiance: None,
                ..
            } => Some(("", ENVIRONMENT_NEEDS.into())),
            LightDesc::Spot {
                cutoff_angle,
                beam_width: Some(beam),
                ..
            } if beam.0 > cutoff_angle.0 => Some((
                "beam_width",
                format!(
                    "a spot's beam_width ({}) is wider than its cutoff_angle ({}): the beam is \
                     the part inside the cutoff; make beam_width at most cutoff_angle",
                    beam.0, cutoff_angle.0
                ),
            )),
            _ => None,
        }
    }

    /// The world's light; `load` reads an environment's image (its path as written) into its
    /// sky, and its message is the error's, as is an environment with neither an image nor a
    /// radiance ([`LightDesc::invalid`]).
    pub fn to_world(
        &self,
        load: impl FnOnce(&str) -> Result<Sky, String>,
    ) -> Result<LightComponent, String> {
        let light = |l| Ok(LightComponent::Light(l));
        match self {
            &LightDesc::Point {
                position,
                intensity,
            } => light(WorldLight::Point {
                position: position.0,
                intensity: intensity.0.as_vec3a(),
            }),
            &LightDesc::Spot {
                position,
                direction,
                intensity,
                cutoff_angle,
                beam_width,
            } => light(WorldLight::Spot {
                position: position.0,
                direction: direction.0,
                intensity: intensity.0.as_vec3a(),
                cutoff_angle: cutoff_angle.0,
                beam_width: beam_width.map_or(cutoff_angle.0 * 0.75, |b| b.0),
            }),
            &LightDesc::Directional {
                direction,
                irradiance,
            } => light(WorldLight::Directional {
                direction: direction.0,
                irradiance: irradiance.0.as_vec3a(),
            }),
            LightDesc::Environment {
                image,
                radiance,
                scale,
                rotate,
            } => {
                let sky = match (image, radiance) {
                    (Some(path), _) => load(path)?,
                    (None, Some(l)) => Sky::Uniform(l.0.as_vec3a()),
                    (None, None) => return Err(ENVIRONMENT_NEEDS.into()),
                };
                Ok(LightComponent::Environment(WorldEnvironment {
                    sky,
                    scale: scale.0 as f32,
                    rotate: rotate.0,
                }))
            }
        }
    }
}

/// An emitter as written: the entity's shape emits `radiance` from its surface (a diffuse area
/// light).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(rename = "Emitter", deny_unknown_fields)]
pub struct EmitterDesc {
    /// Emitted radiance, W/(m^2 sr) per channel, >= 0; or a texture whose values are the
    /// radiance at each point (an OpenEXR image's as stored, a PNG's decoded from sRGB).
    pub radiance: Paint<Rgb>,
    /// Emit from both sides (default `false`: only on the side the shape's normal points to,
    /// outward for spheres, `(b - a) x (c - a)` for triangles, `u x v` for rectangles).
    #[serde(default)]
    pub two_sided: bool,
}

impl EmitterDesc {
    /// The world's emitter component (a textured radiance is white here: its texture,
    /// [`EmitterDesc::texture`], gives it at each point).
    pub fn to_world(&self) -> Emitter {
        Emitter {
            radiance: match &self.radiance {
                Paint::Constant(c) => c.0.as_vec3a(),
                Paint::Texture(_) => glam::Vec3A::ONE,
            },
            two_sided: self.two_sided,
        }
    }

    /// The texture of its radiance, if it has one, its image read by `load`.
    pub fn texture(&self, load: &mut ImageLoader) -> Result<Option<RadianceTexture>, String> {
        Ok(self.radiance.texture(load)?.map(RadianceTexture))
    }
}

/// Effect switches as written in a scene file: `None` (the default) lets rtis decide from the
/// scene, `false` switches an effect off to trade accuracy for time, `true` asks for it (a
/// warning when the scene cannot produce it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename = "Effects", deny_unknown_fields)]
pub struct EffectsDesc {
    /// Shadow rays towards point lights. Off: every light reaches every point facing it.
    #[serde(default)]
    pub shadows: Option<bool>,
    /// Mirror reflection (and glass's total internal and Fresnel reflection). Off: those
    /// directions return black.
    #[serde(default)]
    pub reflection: Option<bool>,
    /// Refraction through glass. Off: glass is opaque black (except its reflection).
    #[serde(default)]
    pub refraction: Option<bool>,
    /// Traced indirect light (Global's hemisphere and two-direction steps, Path's bounces off
    /// Phong surfaces). Off: Global uses the ambient term at every Phong hit (as with D = 0);
    /// Path stops after the first Phong vertex's direct light.
    #[serde(default)]
    pub indirect: Option<bool>,
    /// Global's ambient term (Eq. 2). Off: it is zero.
    #[serde(default)]
    pub ambient: Option<bool>,
    /// Background radiance. Off: escaped rays see black.
    #[serde(default)]
    pub background: Option<bool>,
    /// Light emitted by shapes (area lights). Off: emitters are dark.
    #[serde(default)]
    pub emission: Option<bool>,
}

impl EffectsDesc {
    /// The world's effect switches.
    pub fn to_world(&self) -> Switches {
        Switches {
            shadows: self.shadows,
            reflection: self.reflection,
            refraction: self.refraction,
            indirect: self.indirect,
            ambient: self.ambient,
            background: self.background,
            emission: self.emission,
        }
    }
}

/// An entity as written: a bag of optional components.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "EntityFields", into = "EntityFields")]
pub struct EntityDesc(pub EntityFields);

/// The components of an entity; checked into [`EntityDesc`].
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(rename = "Entity", deny_unknown_fields)]
pub struct EntityFields {
    /// A label shown by `rtis check` and in error messages.
    #[serde(default)]
    pub name: Option<String>,
    /// Geometry; needs a `material`.
    #[serde(default)]
    pub shape: Option<ShapeDesc>,
    /// Appearance of the `shape`.
    #[serde(default)]
    pub material: Option<MaterialDesc>,
    /// A light source.
    #[serde(default)]
    pub light: Option<LightDesc>,
    /// Makes the `shape` an area light (a sphere, triangle, rectangle or mesh; not an infinite
    /// plane). Without a `material` the shape reflects nothing (black Phong).
    #[serde(default)]
    pub emitter: Option<EmitterDesc>,
    /// Placement of the `shape` (default: as written).
    #[serde(default)]
    pub transform: Option<TransformDesc>,
}

impl TryFrom<EntityFields> for EntityDesc {
    type Error = String;
    fn try_from(e: EntityFields) -> Result<Self, String> {
        let label = e
            .name
            .as_deref()
            .map(|n| format!("entity \"{n}\""))
            .unwrap_or_else(|| "this entity".into());
        match (&e.shape, &e.material, &e.light, &e.emitter) {
            (Some(_), None, _, None) => Err(format!("{label} has a shape but no material")),
            (None, Some(_), _, _) => Err(format!("{label} has a material but no shape")),
            (None, _, _, Some(_)) => Err(format!(
                "{label} has an emitter but no shape: an emitter makes a shape glow"
            )),
            (None, None, None, None) => Err(format!("{label} has no shape and no light")),
            (Some(ShapeDesc::InfinitePlane { .. }), _, _, Some(_)) => Err(format!(
                "{label}: an infinite plane cannot be an emitter (it would emit infinite \
                 power); use a Rectangle"
            )),
            _ => {
                if let (Some(ShapeDesc::Sphere { .. }), Some(t)) = (&e.shape, &e.transform) {
                    let s = t.scale.0.abs();
                    if s.x != s.y || s.y != s.z {
                        let s = t.scale.0;
                        return Err(format!(
                            "{label}: a sphere takes only a uniform scale (the same factor on \
                             x, y and z), got ({}, {}, {})",
                            super::values::show(s.x),
                            super::values::show(s.y),
                            super::values::show(s.z)
                        ));
                    }
                }
                if let Some(ShapeDesc::TriangleMesh {
                    vertices, normals, ..
                }) = &e.shape
                    && !normals.is_empty()
                    && normals.len() != vertices.len()
                {
                    return Err(format!(
                        "{label}: {} normals for {} vertices: give one normal per vertex, or \
                         none",
                        normals.len(),
                        vertices.len()
                    ));
                }
                if let Some(ShapeDesc::Rectangle { u, v, .. }) = &e.shape
                    && u.0.cross(v.0).length_squared() == 0.0
                {
                    return Err(format!(
                        "{label}: a Rectangle needs two edges u and v that are not parallel \
                         (and not zero)"
                    ));
                }
                if let Some(ShapeDesc::TriangleMesh {
                    vertices, faces, ..
                }) = &e.shape
                {
                    let n = vertices.len() as u64;
                    if let Some((i, f)) = faces
                        .iter()
                        .enumerate()
                        .find(|(_, f)| f.0 as u64 >= n || f.1 as u64 >= n || f.2 as u64 >= n)
                    {
                        return Err(if n == 0 {
                            format!("{label}: face {i} is {f:?}, but there are no vertices")
                        } else {
                            format!(
                                "{label}: face {i} is {f:?}, but the {n} vertices are numbered \
                                 from 0 to {}",
                                n - 1
                            )
                        });
                    }
                }
                Ok(EntityDesc(e))
            }
        }
    }
}

impl From<EntityDesc> for EntityFields {
    fn from(e: EntityDesc) -> Self {
        e.0
    }
}
