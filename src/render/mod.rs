//! Rendering: the render scene and its effects, tiles of pixels traced in parallel with rayon,
//! each pixel with its own random stream, so the image is bit-identical for any thread count and
//! tile order; then the image and its output files.

pub mod effects;
pub mod film;
pub mod output;
mod scene;

pub use scene::{Film, MAX_PIXELS, MAX_SIDE, MAX_SPP, RenderScene};

use crate::sampling::{Sampler, pixel_sample};
use crate::shader::radiance;
use crate::stats::RayStats;
use film::Image;
use glam::Vec3A;
use rayon::prelude::*;
use std::time::Instant;

/// Side of a square tile in pixels.
pub const TILE: u32 = 16;

/// A finished render.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The image (linear radiance).
    pub image: Image,
    /// Rays traced, by kind.
    pub stats: RayStats,
    /// Wall-clock seconds spent tracing.
    pub seconds: f64,
}

impl Rendered {
    /// Millions of rays per second.
    pub fn mrays_per_second(&self) -> f64 {
        self.stats.total() as f64 / self.seconds.max(1e-9) / 1e6
    }
}

/// The colour of pixel `(col, row)`: the mean radiance of its `spp` camera samples.
///
/// The last line of defence against numerical failure: a sample whose radiance is NaN,
/// infinite or negative is dropped (it adds zero) and counted in `stats.dropped`, so one bad
/// sample can never poison a pixel, and the count says that it happened.
#[inline]
pub fn render_pixel(scene: &RenderScene, col: u32, row: u32, stats: &mut RayStats) -> Vec3A {
    let film = &scene.film;
    let pixel = row as u64 * film.width as u64 + col as u64;
    let mut sum = Vec3A::ZERO;
    for s in 0..film.spp {
        let mut sampler = Sampler::new(scene.seed, pixel, s as u64);
        let (dx, dy) = pixel_sample(s, film.spp, scene.seed ^ pixel, &mut sampler);
        let u = (col as f32 + dx) / film.width as f32;
        let v = (row as f32 + dy) / film.height as f32;
        let ray = scene.camera.ray(u, v);
        let mut tracer = scene.tracer(sampler, stats);
        let l = radiance(&scene.shader, &mut tracer, &ray);
        if l.is_finite() && l.min_element() >= 0.0 {
            sum += l;
        } else {
            stats.dropped += 1;
        }
    }
    sum / film.spp as f32
}

/// Render the scene on the current rayon pool; `on_tile` is called after each tile (progress).
pub fn render(scene: &RenderScene, on_tile: &(dyn Fn() + Sync)) -> Rendered {
    let start = Instant::now();
    let (w, h) = (scene.film.width, scene.film.height);
    let tiles_x = w.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..tiles_x).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let done: Vec<(Vec<Vec3A>, RayStats)> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let mut stats = RayStats::default();
            let mut px = Vec::with_capacity((TILE * TILE) as usize);
            for row in y0..(y0 + TILE).min(h) {
                for col in x0..(x0 + TILE).min(w) {
                    px.push(render_pixel(scene, col, row, &mut stats));
                }
            }
            on_tile();
            (px, stats)
        })
        .collect();
    let mut image = Image::new(w, h);
    let mut stats = RayStats::default();
    for (&(x0, y0), (px, st)) in tiles.iter().zip(done) {
        stats += st;
        let tw = (x0 + TILE).min(w) - x0;
        for (i, p) in px.into_iter().enumerate() {
            let (col, row) = (x0 + i as u32 % tw, y0 + i as u32 / tw);
            image.pixels[(row * w + col) as usize] = p;
        }
    }
    Rendered {
        image,
        stats,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Number of tiles a render of this film has (for progress bars).
pub fn tile_count(scene: &RenderScene) -> u64 {
    (scene.film.width.div_ceil(TILE) * scene.film.height.div_ceil(TILE)) as u64
}
