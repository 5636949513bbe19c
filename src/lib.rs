//! rtis: a ray tracer for learning, teaching and testing light transport.
//!
//! Scenes are authored in RON and loaded into an ECS world ([`scene`]); [`prepare`] turns the
//! world into flat render data once; [`render`] traces it in parallel with one of the closed set
//! of [`shader`]s. See `README.md` and `docs/`.

#![warn(missing_docs)]

pub mod accel;
pub mod camera;
pub mod converge;
pub mod effects;
pub mod geometry;
pub mod light;
pub mod material;
pub mod mesh;
pub mod prepare;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod shader;
pub mod shape;

pub use prepare::RenderScene;
pub use render::{Rendered, render};
