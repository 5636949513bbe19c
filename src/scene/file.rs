//! The scene file format: serde structs read from RON. Every struct rejects unknown fields;
//! every optional field documents its default. `docs/scene-format.md` is the user's guide.

use super::values::{Count, Direction, Fov, NonNegative, Point, Positive, Rgb, Scale, UpTo};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Largest image side in pixels.
pub const MAX_SIDE: u32 = 1 << 15;
/// Largest pixel count (8192 x 8192): the film holds 12 bytes per pixel.
pub const MAX_PIXELS: u64 = 1 << 26;
/// Largest samples per pixel.
pub const MAX_SPP: u32 = 1 << 20;
/// Largest hemisphere sample count of the Global shader.
pub const MAX_GLOBAL_SAMPLES: u32 = 1 << 16;
/// Largest `max_depth` of the Global shader: its rays grow as `n * 2^(D-1)` per pixel.
pub const MAX_GLOBAL_DEPTH: u32 = 16;
/// Largest `max_depth` of the Path shader.
pub const MAX_PATH_DEPTH: u32 = 1024;

/// One scene file as written. Every field is optional: a file that `extends` a base scene
/// overrides the base's film, camera, shader, background, seed and model, adds or replaces
/// materials by name, replaces the base's entities that have the same `name`, and appends the
/// others.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(rename = "Scene", deny_unknown_fields)]
pub struct SceneFile {
    /// A base scene to start from, relative to this file's folder.
    #[serde(default)]
    pub extends: Option<String>,
    /// Image size and sampling. Default: [`FilmDesc::default`].
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
    #[serde(default)]
    pub seed: Option<u64>,
    /// Light-transport model for the shaders that have one. Default: `Course`.
    #[serde(default)]
    pub model: Option<Model>,
    /// Effects switched off (or asked for) on purpose. Default: all decided from the scene.
    #[serde(default)]
    pub effects: Option<crate::effects::EffectsDesc>,
    /// Named materials that entities refer to with `Named("...")`; a table entry
    /// cannot itself be `Named`.
    #[serde(default)]
    pub materials: Option<BTreeMap<String, MaterialDesc>>,
    /// The scene's entities.
    #[serde(default)]
    pub entities: Option<Vec<EntityDesc>>,
}

/// Image size and sampling.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "FilmFields", into = "FilmFields")]
pub struct FilmDesc {
    /// Width in pixels (default 720, the course's).
    pub width: u32,
    /// Height in pixels (default 576).
    pub height: u32,
    /// Samples per pixel (default 1: one ray through each pixel centre).
    pub spp: u32,
    /// How linear radiance becomes 8-bit PNG values (default `Srgb`).
    pub transfer: Transfer,
}

impl Default for FilmDesc {
    fn default() -> Self {
        FilmDesc {
            width: 720,
            height: 576,
            spp: 1,
            transfer: Transfer::Srgb,
        }
    }
}

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
        FilmDesc {
            width: f.width.0,
            height: f.height.0,
            spp: f.spp.0,
            transfer: f.transfer,
        }
        .checked()
    }
}

impl FilmDesc {
    /// The film if its pixel count is within [`MAX_PIXELS`].
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

impl From<FilmDesc> for FilmFields {
    fn from(f: FilmDesc) -> Self {
        FilmFields {
            width: Count(f.width),
            height: Count(f.height),
            spp: Count(f.spp),
            transfer: f.transfer,
        }
    }
}

/// How 8-bit PNG values are made from linear radiance (EXR output is always linear float).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum Transfer {
    /// The sRGB curve after clamping to [0, 1]: what screens expect.
    #[default]
    Srgb,
    /// `min(v, 1) * 255`, no curve: the course's BMP output.
    Linear,
}

/// The light-transport model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum Model {
    /// The course's: reflectance `r = kd cos + ks cos^s` (no 1/pi) and the course's weights.
    #[default]
    Course,
    /// Physically based: normalised Phong BRDF, unbiased Monte Carlo weights, Fresnel glass.
    Physical,
}

/// A camera as written.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "CameraFields", into = "CameraFields")]
pub struct CameraDesc(pub CameraFields);

/// The camera variants as written; checked into [`CameraDesc`].
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum CameraFields {
    /// A pinhole camera.
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
    },
}

fn y_up() -> Direction {
    Direction(glam::DVec3::Y)
}
fn fov60() -> Fov {
    Fov(60.0)
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc(CameraFields::Perspective {
            position: Point(glam::DVec3::ZERO),
            look_at: Point(glam::DVec3::Z),
            up: y_up(),
            fov: fov60(),
        })
    }
}

impl CameraFields {
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
        let (position, look_at, up) = c.frame();
        let forward = look_at - position;
        if forward.length_squared() == 0.0 {
            return Err(
                "degenerate camera: look_at equals position, so there is no view \
                        direction"
                    .into(),
            );
        }
        if forward.normalize().cross(up.normalize()).length() < 1e-6 {
            return Err("degenerate camera: up is parallel to the view direction \
                        (look_at - position)"
                .into());
        }
        Ok(CameraDesc(c))
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
    /// Direct light from point lights at Phong hits (Eq. 3); mirrors and glass are followed.
    Direct {
        /// Longest chain of consecutive mirror/glass bounces (default 32).
        #[serde(default = "max_specular")]
        max_specular: u32,
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
        /// Longest chain of consecutive mirror/glass bounces (default 32).
        #[serde(default = "max_specular")]
        max_specular: u32,
    },
    /// The reference path tracer under the scene's `model`.
    Path {
        /// Largest number of bounces of any kind (default: none, Russian roulette ends paths).
        #[serde(default)]
        max_depth: Option<UpTo<MAX_PATH_DEPTH>>,
        /// Bounces before Russian roulette starts (default 5).
        #[serde(default = "rr_depth")]
        rr_depth: u32,
        /// Direction sampling at Phong vertices: `Uniform`, `Cosine` or `Brdf` (default).
        #[serde(default)]
        sampling: crate::shader::Sampling,
    },
}

fn rr_depth() -> u32 {
    5
}

fn white() -> Rgb {
    Rgb::grey(1.0)
}
fn max_specular() -> u32 {
    32
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

impl Default for ShaderDesc {
    fn default() -> Self {
        ShaderDesc::Direct {
            max_specular: max_specular(),
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
        /// Diffuse coefficient, unitless RGB.
        kd: Rgb,
        /// Specular coefficient, unitless RGB (default black).
        #[serde(default = "black")]
        ks: Rgb,
        /// Phong exponent, >= 0 (default 1).
        #[serde(default = "shininess")]
        shininess: NonNegative,
    },
    /// A perfect mirror tinted by `color`.
    Mirror {
        /// Tint, unitless RGB (default white).
        #[serde(default = "white")]
        color: Rgb,
    },
    /// A perfect refractor (inside index `ior`, outside air) tinted by `color`.
    Transmissive {
        /// Index of refraction, > 0.
        ior: Positive,
        /// Tint, unitless RGB (default white).
        #[serde(default = "white")]
        color: Rgb,
    },
}

fn black() -> Rgb {
    Rgb::BLACK
}
fn shininess() -> NonNegative {
    NonNegative(1.0)
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
    /// Triangles sharing a vertex list: `faces` index `vertices` (counter-clockwise winding).
    TriangleMesh {
        /// Vertex positions.
        vertices: Vec<Point>,
        /// Triangles as triples of indices into `vertices`.
        faces: Vec<(u32, u32, u32)>,
        /// Optional per-vertex normals for smooth shading (same count as `vertices`).
        #[serde(default)]
        normals: Vec<Direction>,
    },
    /// A Wavefront OBJ file, relative to the scene file's folder: positions, faces
    /// (triangulated), and vertex normals for smooth shading when the file has them.
    Mesh {
        /// Path of the .obj file.
        path: String,
    },
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
    /// The affine map `translate * Rz * Ry * Rx * scale`.
    pub fn affine(&self) -> glam::DAffine3 {
        use glam::DMat3;
        let r = self.rotate.0 * (std::f64::consts::PI / 180.0);
        let rot =
            DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x);
        glam::DAffine3 {
            matrix3: rot * DMat3::from_diagonal(self.scale.0),
            translation: self.translate.0,
        }
    }
}

/// A light as written.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// An isotropic point light: incident radiance `intensity / d^2`.
    Point {
        /// Position.
        position: Point,
        /// Radiant intensity, W/sr per channel, >= 0.
        intensity: Rgb,
    },
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
            .unwrap_or_else(|| "entity".into());
        match (&e.shape, &e.material, &e.light) {
            (Some(_), None, _) => Err(format!("{label} has a shape but no material")),
            (None, Some(_), _) => Err(format!("{label} has a material but no shape")),
            (None, None, None) => Err(format!("{label} has no shape and no light")),
            _ => {
                if let (Some(ShapeDesc::Sphere { .. }), Some(t)) = (&e.shape, &e.transform) {
                    let s = t.scale.0.abs();
                    if s.x != s.y || s.y != s.z {
                        return Err(format!(
                            "{label}: a sphere takes only a uniform scale, got {}",
                            t.scale.0
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
                        "{label}: {} normals for {} vertices: give one per vertex or none",
                        normals.len(),
                        vertices.len()
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
                        return Err(format!(
                            "{label}: face {i} {f:?} indexes past the {n} vertices"
                        ));
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
