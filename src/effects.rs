//! Simulate only the effects a scene calls for.
//!
//! [`Effects::derive`] looks at the prepared scene and its shader once per render and says which
//! effects can occur; the scene may switch effects off on purpose (`effects: (...)` in RON). The
//! result selects one of the monomorphised render kernels ([`Kernel`]): code for an effect the
//! scene lacks is not in the kernel that runs, rather than skipped by a branch per ray.

use crate::material::Material;
use crate::prepare::RenderScene;
use crate::shader::Shader;
use crate::shape::ShapeKind;
use serde::{Deserialize, Serialize};
use std::fmt;

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
}

/// The effects a render simulates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Effects {
    /// Shadow rays are traced.
    pub shadows: bool,
    /// Mirror rays (and glass reflection) are traced.
    pub reflection: bool,
    /// Refraction rays are traced.
    pub refraction: bool,
    /// Indirect rays are traced.
    pub indirect: bool,
    /// The ambient term is added.
    pub ambient: bool,
    /// Escaped rays see a non-black background.
    pub background: bool,
    /// The scene has spheres.
    pub spheres: bool,
    /// The scene has infinite planes.
    pub planes: bool,
    /// The scene has triangles.
    pub triangles: bool,
}

/// Bits of a render kernel: the effects whose code is compiled in or out.
pub mod kernel {
    /// Shadow rays.
    pub const SHADOWS: u32 = 1;
    /// Mirror and glass reflection.
    pub const REFLECTION: u32 = 2;
    /// Glass refraction.
    pub const REFRACTION: u32 = 4;
    /// Indirect rays at Phong surfaces.
    pub const INDIRECT: u32 = 8;
    /// Sphere intersection.
    pub const SPHERES: u32 = 16;
    /// Triangle intersection.
    pub const TRIANGLES: u32 = 32;
    /// Every effect: the unspecialised kernel.
    pub const ALL: u32 = 63;
    /// Number of kernels.
    pub const COUNT: u32 = 64;
}

/// A render kernel: a set of [`kernel`] bits.
pub type Kernel = u32;

impl Effects {
    /// The effects of `scene` under its shader, with the scene's switches applied, and warnings
    /// for switches that ask for what the scene cannot produce.
    pub fn derive(scene: &RenderScene, wanted: &EffectsDesc) -> (Effects, Vec<String>) {
        let has = |k| scene.geometry.count(k) > 0;
        let mats = &scene.materials;
        let any_mat = |f: fn(&Material) -> bool| mats.iter().any(f);
        let shading = matches!(
            scene.shader,
            Shader::Direct { .. } | Shader::Global(_) | Shader::Path(_)
        );
        let has_glass = any_mat(|m| matches!(m, Material::Transmissive(_)));
        let has_phong = any_mat(|m| matches!(m, Material::Phong(_)));
        let has_geometry = !scene.geometry.is_empty();
        let indirect = has_phong
            && match scene.shader {
                Shader::Global(g) => g.max_depth >= 1,
                Shader::Path(_) => true,
                _ => false,
            };
        let ambient = has_phong
            && matches!(scene.shader, Shader::Global(g) if g.ambient != glam::Vec3A::ZERO)
            && any_mat(|m| matches!(m, Material::Phong(p) if p.kd != glam::Vec3A::ZERO));
        let possible = Effects {
            shadows: shading && !scene.lights.is_empty() && has_geometry && has_phong,
            reflection: shading && (any_mat(|m| matches!(m, Material::Mirror(_))) || has_glass),
            refraction: shading && has_glass,
            indirect,
            ambient,
            background: scene.background != glam::Vec3A::ZERO,
            spheres: has(ShapeKind::Sphere),
            planes: has(ShapeKind::Plane),
            triangles: has(ShapeKind::Triangle),
        };
        let mut warnings = Vec::new();
        let mut pick = |name: &str, can: bool, want: Option<bool>| match want {
            Some(true) if !can => {
                warnings.push(format!(
                    "effects: {name} requested, but this scene and shader cannot produce it"
                ));
                false
            }
            Some(w) => w && can,
            None => can,
        };
        let e = Effects {
            shadows: pick("shadows", possible.shadows, wanted.shadows),
            reflection: pick("reflection", possible.reflection, wanted.reflection),
            refraction: pick("refraction", possible.refraction, wanted.refraction),
            indirect: pick("indirect", possible.indirect, wanted.indirect),
            ambient: pick("ambient", possible.ambient, wanted.ambient),
            background: pick("background", possible.background, wanted.background),
            ..possible
        };
        (e, warnings)
    }

    /// The kernel that simulates exactly these effects.
    pub fn kernel(&self) -> Kernel {
        use kernel::*;
        let bit = |on: bool, b: u32| if on { b } else { 0 };
        bit(self.shadows, SHADOWS)
            | bit(self.reflection, REFLECTION)
            | bit(self.refraction, REFRACTION)
            | bit(self.indirect, INDIRECT)
            | bit(self.spheres, SPHERES)
            | bit(self.triangles, TRIANGLES)
    }
}

impl fmt::Display for Effects {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let all = [
            ("shadows", self.shadows),
            ("reflection", self.reflection),
            ("refraction", self.refraction),
            ("indirect", self.indirect),
            ("ambient", self.ambient),
            ("background", self.background),
            ("spheres", self.spheres),
            ("planes", self.planes),
            ("triangles", self.triangles),
        ];
        let on: Vec<&str> = all.iter().filter(|(_, v)| *v).map(|(n, _)| *n).collect();
        let off: Vec<&str> = all.iter().filter(|(_, v)| !*v).map(|(n, _)| *n).collect();
        write!(f, "on: {}; off: {}", join(&on), join(&off))
    }
}

fn join(v: &[&str]) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}
