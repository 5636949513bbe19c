//! The ECS world a scene is loaded into: entities with components of the world's own types, and
//! the scene-wide settings beside them as resources.
//!
//! Components (each optional on an entity, in any combination the loader allows):
//! - [`Name`]: a label for messages and `rtis check`.
//! - [`WorldShape`] with a [`Material`]: geometry in scene units, double precision. Every shape
//!   has a material; a mesh always has its triangles.
//! - [`MaterialName`]: the `materials` table entry the material came from.
//! - [`Transform`]: placement of the entity's shape.
//! - [`WorldLight`]: a light source in scene units.
//! - [`WorldEnvironment`]: the sky, an environment light (at most one in a world).
//! - [`Emitter`]: makes the entity's shape an area light.
//!
//! Nothing here knows the file format or rays; the extraction step (`extract.rs`) turns a
//! [`Scene`] into render data.

pub use crate::camera::{Projection, WorldCamera};
pub use crate::effects::Switches;
pub use crate::geometry::Transform;
pub use crate::light::{Emitter, RadianceTexture, WorldEnvironment, WorldLight};
pub use crate::material::{Material, Model};
pub use crate::render::Film;
pub use crate::shader::Shader;
pub use crate::shape::WorldShape;
use glam::{DVec3, Vec3A};

/// The scene-wide resources that sit beside the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Image size and sampling.
    pub film: Film,
    /// The camera.
    pub camera: WorldCamera,
    /// The shader with its parameters.
    pub shader: Shader,
    /// Radiance of escaped rays, linear RGB.
    pub background: Vec3A,
    /// Seed of the render's random numbers.
    pub seed: u64,
    /// Light-transport model.
    pub model: Model,
    /// Effects switched off (or asked for) on purpose.
    pub effects: Switches,
}

impl Default for Settings {
    /// The defaults of a scene file that sets nothing: the course's film, a perspective camera
    /// at the origin looking down +z with a 60 degree field of view, the Direct shader (32
    /// specular bounces), a black background, seed 0, the Course model, effects decided from
    /// the scene.
    fn default() -> Self {
        Settings {
            film: Film::default(),
            camera: WorldCamera {
                projection: Projection::Perspective {
                    fov: 60.0,
                    lens: None,
                },
                position: DVec3::ZERO,
                look_at: DVec3::Z,
                up: DVec3::Y,
                handedness: crate::camera::Handedness::Left,
            },
            shader: Shader::Direct {
                max_specular: 32,
                light_samples: 1,
            },
            background: Vec3A::ZERO,
            seed: 0,
            model: Model::Course,
            effects: Switches::default(),
        }
    }
}

/// The `name` component of an entity.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Name(pub String);

/// The name under which an entity's material was declared in the `materials` table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MaterialName(pub String);

/// A loaded scene: an ECS world plus its resources.
pub struct Scene {
    /// Entities with the components listed in the module documentation.
    pub world: hecs::World,
    /// Film, camera, shader, background, seed, model, effect switches.
    pub settings: Settings,
    /// Where the scene came from (a path, or `<default cornell.ron>` for the embedded box).
    pub origin: String,
    /// Things worth telling the user that do not stop the render.
    pub warnings: Vec<String>,
    /// The files it was read from: the scene file, the bases it extends and the meshes it
    /// loads (what `rtis watch` follows). A scene given as text lists the bases and meshes
    /// it reads, not itself.
    pub files: Vec<std::path::PathBuf>,
}
