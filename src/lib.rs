//! rtis: a ray tracer for learning, teaching and testing light transport.
//!
//! Layers, imports pointing down only (`docs/architecture.md` has the diagram):
//! - [`scene`]: the RON format ([`scene::file`]) and the loader that fills the world;
//! - [`extract`](mod@extract): the one step that reads the world and builds the render data;
//! - [`world`]: the ECS world's component types and settings;
//! - [`render`](mod@render): the render scene, its effects, the tiled render loop, images and output;
//! - [`shader`]: one file per shader, given the parts of the scene it reads;
//! - [`accel`]: ray queries over the flat primitives (SIMD packets and a BVH);
//! - [`shape`], [`material`], [`light`], [`camera`], [`texture`]: the closed sets, one file per
//!   variant;
//! - [`geometry`], [`sampling`], [`mesh`], [`raster`], [`effects`], [`stats`]: leaf maths and
//!   data.
//!
//! [`converge`] (error against time) sits beside the command line on top.

#![warn(missing_docs)]

pub mod accel;
pub mod camera;
pub mod converge;
pub mod effects;
pub mod extract;
pub mod geometry;
pub mod import;
pub mod light;
pub mod material;
pub mod mesh;
pub mod raster;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod shader;
pub mod shape;
pub mod stats;
pub mod texture;
pub mod world;

pub use extract::extract;
pub use render::{RenderScene, Rendered, render};
