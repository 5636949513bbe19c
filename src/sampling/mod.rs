//! Random numbers, sample warps and sampling strategies.

pub mod distribution;
mod erf;
pub mod filter;
pub mod hemisphere;
mod pixel;
mod rng;
mod sampler;
mod sobol;
mod strategy;
pub mod trig;
pub mod warp;

pub use distribution::{Distribution1D, Distribution2D};
pub use erf::erf_inv;
pub use filter::PixelFilter;
pub use pixel::pixel_sample;
pub use rng::{Pcg32, PcgLanes, mix};
pub use sampler::{LANES, Sampler, SamplerKind, Streams, WithStreams};
pub use sobol::{Sobol, SobolLanes};
pub use strategy::{LightSampling, LightsPerVertex, Sampling, power_heuristic};
pub use trig::sin_cos_turns;
