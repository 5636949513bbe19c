//! Scenes: the RON format, its validation, and loading into an ECS world.
//!
//! Data flows one way: RON text -> [`file::SceneFile`] (serde, validated while parsed) ->
//! resolved (`extends` merged, names checked) -> [`Scene`]: a `hecs::World` of entities with
//! shape, material and light components, plus [`Settings`] as resources beside it. Nothing here
//! knows about rays; `crate::prepare` turns a [`Scene`] into flat render data.

mod error;
pub mod file;
mod load;
pub mod values;

pub use error::SceneError;
pub use file::{
    CameraDesc, FilmDesc, LightDesc, MaterialDesc, Model, ShaderDesc, ShapeDesc, TransformDesc,
};
pub use load::{DEFAULT_SCENE, load_default, load_path, load_str};
pub use values::Rgb;

/// The scene-wide resources that sit beside the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Image size and sampling.
    pub film: FilmDesc,
    /// The camera.
    pub camera: CameraDesc,
    /// The shader.
    pub shader: ShaderDesc,
    /// Radiance of escaped rays.
    pub background: Rgb,
    /// Seed of the render's random numbers.
    pub seed: u64,
    /// Light-transport model.
    pub model: Model,
    /// Effect switches.
    pub effects: crate::effects::EffectsDesc,
}

/// The `name` component of an entity.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Name(pub String);

/// The name under which an entity's material was declared in the `materials` table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MaterialName(pub String);

/// The triangles of a `Mesh` shape, loaded from its OBJ file when the scene was loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedMesh(pub std::sync::Arc<crate::mesh::MeshData>);

/// A loaded scene: an ECS world plus its resources.
pub struct Scene {
    /// Entities with [`ShapeDesc`], [`MaterialDesc`] (always inline, never `Named`),
    /// [`MaterialName`], [`LightDesc`], [`TransformDesc`], [`LoadedMesh`] and [`Name`]
    /// components.
    pub world: hecs::World,
    /// Film, camera, shader, background, seed, model.
    pub settings: Settings,
    /// Where the scene came from (a path, or `<default>` for the embedded Cornell box).
    pub origin: String,
    /// Things worth telling the user that do not stop the render.
    pub warnings: Vec<String>,
}
