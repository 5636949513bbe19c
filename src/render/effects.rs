//! Which effects a render simulates, decided once from the parts of the render scene before it
//! is assembled.

use crate::accel::Geometry;
use crate::effects::{Effects, Switches};
use crate::light::{Emitters, Light};
use crate::material::Material;
use crate::shader::Shader;
use crate::shape::ShapeKind;
use glam::Vec3A;

/// The outcome of [`derive()`].
#[derive(Clone, Debug, PartialEq)]
pub struct Derived {
    /// The effects to simulate.
    pub effects: Effects,
    /// The effects the scene could produce but switched off on purpose.
    pub switched_off: Effects,
    /// Switches that asked for an effect the scene cannot produce.
    pub warnings: Vec<String>,
}

/// The effects a scene's parts can produce under its shader, with the scene's switches
/// applied, and warnings for switches that ask for what the scene cannot produce.
pub fn derive(
    shader: &Shader,
    geometry: &Geometry,
    materials: &[Material],
    lights: &[Light],
    emitters: &Emitters,
    background: Vec3A,
    wanted: &Switches,
) -> Derived {
    let has = |k| geometry.count(k) > 0;
    let any_mat = |f: fn(&Material) -> bool| materials.iter().any(f);
    let shading = matches!(
        shader,
        Shader::Direct { .. } | Shader::Global(_) | Shader::Path(_)
    );
    let has_glass = any_mat(|m| matches!(m, Material::Transmissive(_)));
    // Surfaces that reflect light from every direction: Phong, and the BSDFs (whose sampled
    // rays are indirect rays).
    let has_phong = any_mat(|m| matches!(m, Material::Phong(_) | Material::Bsdf(_)));
    let indirect = has_phong
        && match shader {
            Shader::Global(g) => g.max_depth >= 1,
            Shader::Path(_) => true,
            _ => false,
        };
    // Light from emitting shapes and from the sky (whose power is 0 in a scene of no size).
    let emission = shading
        && (emitters.lights.iter().any(|l| l.power() > 0.0)
            || emitters
                .environment
                .as_ref()
                .is_some_and(|e| e.integral().max_element() > 0.0));
    let ambient = has_phong
        && matches!(shader, Shader::Global(g) if g.ambient != Vec3A::ZERO)
        && any_mat(|m| matches!(m, Material::Phong(p) if p.kd != Vec3A::ZERO));
    let possible = Effects {
        shadows: shading && (!lights.is_empty() || emission) && !geometry.is_empty() && has_phong,
        reflection: shading
            && (any_mat(|m| matches!(m, Material::Mirror(_) | Material::Conductor(_)))
                || has_glass),
        refraction: shading && has_glass,
        indirect,
        ambient,
        background: background != Vec3A::ZERO,
        emission,
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
    let effects = Effects {
        shadows: pick("shadows", possible.shadows, wanted.shadows),
        reflection: pick("reflection", possible.reflection, wanted.reflection),
        refraction: pick("refraction", possible.refraction, wanted.refraction),
        indirect: pick("indirect", possible.indirect, wanted.indirect),
        ambient: pick("ambient", possible.ambient, wanted.ambient),
        background: pick("background", possible.background, wanted.background),
        emission: pick("emission", possible.emission, wanted.emission),
        ..possible
    };
    Derived {
        effects,
        switched_off: possible.without(effects),
        warnings,
    }
}
