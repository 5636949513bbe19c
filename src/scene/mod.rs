//! Scene files: the RON format, its validation, and loading into the ECS world.
//!
//! Data flows one way: RON text -> [`file::SceneFile`] (serde, validated while parsed, located
//! errors) -> resolved (`extends` merged, names checked, meshes loaded) -> [`Scene`]: a
//! `hecs::World` whose components are the world's own types (`crate::world`), with the settings
//! beside it. Nothing here knows about rays; `crate::extract` turns a [`Scene`] into render data.

mod error;
pub mod file;
mod load;
mod messages;
mod spans;
pub mod values;

pub use crate::world::{Scene, Settings};
pub use error::{EXCERPT_RADIUS, MAX_MESSAGE, SceneError, clip_message};
pub use file::{
    CameraDesc, FilmDesc, LightDesc, MaterialDesc, Model, ShaderDesc, ShapeDesc, TransformDesc,
};
pub use load::{DEFAULT_SCENE, MAX_EXTENDS, load_default, load_path, load_str};
pub use values::Rgb;
