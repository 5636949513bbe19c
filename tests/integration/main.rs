//! The integration tests, one module per file, mirroring `src/` (see README.md, "Tests"): one
//! test binary, so that `cargo test` links the library into one executable rather than one per
//! file.

mod common;

mod architecture;
mod area_lights;
mod batch;
mod block;
mod bounds;
mod bsdfs;
mod bvh;
mod cameras;
mod cli;
mod cli_interrupt;
mod converge;
mod cpu_dispatch;
mod effects;
mod environment;
mod estimate;
mod global_waves;
mod global_weights;
mod golden;
mod hard_cases;
mod import;
mod inspect;
mod lights;
mod material_textures;
mod materials;
mod meshes;
mod origins;
mod output;
mod passes;
mod physical;
mod progressive;
mod readme;
mod room;
mod sampling;
mod scene_errors;
mod scene_fuzz;
mod shapes;
mod stability;
mod tev;
mod textures;
mod transport;
mod warptest;
mod watch;
