//! Random numbers and sample warps.

pub mod hemisphere;
mod pixel;
mod rng;

pub use pixel::pixel_sample;
pub use rng::Sampler;
