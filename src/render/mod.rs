//! Rendering: the render scene and its effects, tiles of pixels traced in parallel with rayon,
//! each pixel with its own random stream, so the image is bit-identical for any thread count and
//! tile order; then the image and its output files.

pub mod effects;
pub mod estimate;
pub mod exact;
pub mod film;
pub mod inspect;
pub mod output;
pub mod pass;
pub mod progressive;
mod scene;
pub mod tev;
pub mod waves;

pub use scene::{Film, MAX_PIXELS, MAX_SIDE, MAX_SPP, RenderScene};

use crate::accel::MAX_LANES;
use crate::geometry::Ray;
use crate::sampling::{Sampler, pixel_sample};
use crate::shader::{self, Record, Shader, Technique};
use crate::stats::{RayKind, RayStats};
use exact::RgbSum;
use film::Image;
use glam::Vec3A;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
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
    /// Tiles rendered; the rest are black when the render was stopped.
    pub tiles_done: u64,
    /// Tiles in the image.
    pub tiles: u64,
}

impl Rendered {
    /// Millions of rays per second.
    pub fn mrays_per_second(&self) -> f64 {
        self.stats.total() as f64 / self.seconds.max(1e-9) / 1e6
    }

    /// Whether every tile was rendered.
    pub fn is_complete(&self) -> bool {
        self.tiles_done == self.tiles
    }
}

/// The colour of pixel `(col, row)`: the mean radiance of its `spp` camera samples, summed
/// exactly ([`exact`]), so that the order of the samples never changes a bit.
///
/// The last line of defence against numerical failure: a sample with a contribution that is
/// NaN, infinite or negative, or whose contributions sum beyond the largest `f32`, is dropped
/// (it adds zero) and counted in `stats.dropped`, so one bad sample can never poison a pixel,
/// and the count says that it happened.
#[inline]
pub fn render_pixel(scene: &RenderScene, col: u32, row: u32, stats: &mut RayStats) -> Vec3A {
    pixel_sum(scene, col, row, 0..scene.film.spp, stats).mean(scene.film.spp as u64)
}

/// The exact sum of the samples `samples` of pixel `(col, row)`.
#[inline]
pub fn pixel_sum(
    scene: &RenderScene,
    col: u32,
    row: u32,
    samples: std::ops::Range<u32>,
    stats: &mut RayStats,
) -> RgbSum {
    if let Shader::Path(p) = &scene.shader
        && waves::applies(scene)
    {
        return waves::pixel_sum(scene, col, row, samples, p, stats);
    }
    let mut sum = RgbSum::default();
    if let Shader::Path(p) = &scene.shader
        && scene.geometry.groups_pay()
    {
        // The camera rays of a pixel run close together: those of up to `MAX_LANES` samples
        // are traced as a group (in packets through the BVH, in lanes through packed
        // primitives: the one-ray hits to the bit), and each path goes on alone from its hit.
        let mut hits = Vec::with_capacity(MAX_LANES);
        let mut first = samples.start;
        while first < samples.end {
            let n = (samples.end - first).min(MAX_LANES as u32) as usize;
            let mut rays = [Ray::new(Vec3A::ZERO, Vec3A::Z); MAX_LANES];
            let mut samplers: [Option<Sampler>; MAX_LANES] = Default::default();
            for (i, (ray, sampler)) in rays.iter_mut().zip(&mut samplers).enumerate().take(n) {
                let (r, s) = camera_ray(scene, col, row, first + i as u32);
                (*ray, *sampler) = (r, Some(s));
            }
            scene.geometry.intersect_group(&rays[..n], &mut hits);
            for ((ray, &hit), sampler) in rays.iter().zip(&hits).zip(samplers) {
                let Some(sampler) = sampler else { break };
                let mut sample = SampleSum::default();
                let mut tracer = scene.tracer(sampler, stats);
                tracer.count(ray, RayKind::Camera);
                shader::path::radiance_from(&mut tracer, ray, hit, p, &mut sample);
                sample.keep_into(&mut sum, stats);
            }
            first += n as u32;
        }
        return sum;
    }
    for s in samples {
        let mut sample = SampleSum::default();
        trace_sample(scene, col, row, s, stats, &mut sample);
        sample.keep_into(&mut sum, stats);
    }
    sum
}

/// The exact sum of the contributions of camera sample `s` of pixel `(col, row)` (the path
/// tracer's are several, every other shader's one), from the sample's own random stream;
/// zero, and counted in `stats.dropped`, when one of them is NaN, infinite or negative or
/// their sum is beyond the largest `f32`.
#[inline]
pub fn render_sample(
    scene: &RenderScene,
    col: u32,
    row: u32,
    s: u32,
    stats: &mut RayStats,
) -> RgbSum {
    let mut sample = SampleSum::default();
    trace_sample(scene, col, row, s, stats, &mut sample);
    sample.kept(stats)
}

/// Trace camera sample `s` of pixel `(col, row)` from the sample's own random stream, telling
/// `rec` what it finds (its contributions, and the path's events if it keeps them).
#[inline]
pub fn trace_sample<R: Record>(
    scene: &RenderScene,
    col: u32,
    row: u32,
    s: u32,
    stats: &mut RayStats,
    rec: &mut R,
) {
    let ray = camera_ray(scene, col, row, s);
    let mut tracer = scene.tracer(ray.1, stats);
    shader::radiance(&scene.shader, &mut tracer, &ray.0, rec);
}

/// The camera ray of sample `s` of pixel `(col, row)`, and the sample's random stream after
/// it (which the shader goes on drawing from).
#[inline(always)]
pub fn camera_ray(scene: &RenderScene, col: u32, row: u32, s: u32) -> (Ray, Sampler) {
    let film = &scene.film;
    let pixel = row as u64 * film.width as u64 + col as u64;
    let mut sampler = Sampler::of(film.sampler, scene.seed, pixel, s as u64);
    let (dx, dy) = film
        .filter
        .place(pixel_sample(s, film.spp, scene.seed ^ pixel, &mut sampler));
    let u = (col as f32 + dx) / film.width as f32;
    let v = (row as f32 + dy) / film.height as f32;
    let ray = scene.camera.ray(u, v, || sampler.next_2d());
    (ray, sampler)
}

/// The exact sum of one sample's contributions, and whether one of them failed (NaN, infinite
/// or negative).
///
/// Most samples' contributions add exactly in `f64` (a sum of `f32` values within 29 binary
/// orders of magnitude of one another has no rounding in `f64`'s 53 bits), so each is added
/// there and checked by Knuth's TwoSum, whose error term is the exact rounding error of the
/// add (Knuth, TAOCP vol. 2, 4.2.2): a contribution whose add would round goes to the
/// fixed-point accumulator instead. The sum is then exact either way, at a few floating-point
/// operations per contribution instead of three fixed-point adds.
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleSum {
    /// The contributions whose adds were exact, summed in `f64`.
    fast: glam::DVec3,
    /// The others, summed in fixed point.
    rest: RgbSum,
    /// Whether `rest` holds any.
    rounded: bool,
    /// True if a contribution was NaN, infinite or negative: the sample is dropped.
    failed: bool,
}

impl SampleSum {
    /// The exact sum of the valid contributions.
    #[inline]
    pub fn sum(&self) -> RgbSum {
        let mut sum = RgbSum::default();
        self.add_to(&mut sum);
        sum
    }

    /// Add the exact sum of the valid contributions to `sum`.
    #[inline(always)]
    fn add_to(&self, sum: &mut RgbSum) {
        for (c, s) in sum.0.iter_mut().enumerate() {
            s.add_f64(self.fast[c]);
        }
        if self.rounded {
            *sum += self.rest;
        }
    }

    /// Add the sum the pixel keeps to the pixel's `sum`: this one, or nothing (counted in
    /// `stats.dropped`) if it failed.
    #[inline(always)]
    pub fn keep_into(&self, sum: &mut RgbSum, stats: &mut RayStats) {
        if self.failed() {
            stats.dropped += 1;
        } else {
            self.add_to(sum);
        }
    }

    /// True if the sample failed: a contribution was NaN, infinite or negative, or their sum
    /// is beyond the largest `f32` (finite contributions can add up to infinity).
    #[inline(always)]
    pub fn failed(&self) -> bool {
        let beyond = |c: usize| {
            let rest = if self.rounded {
                self.rest.0[c].to_f64()
            } else {
                0.0
            };
            self.fast[c] + rest > f32::MAX as f64
        };
        self.failed || beyond(0) || beyond(1) || beyond(2)
    }

    /// The sum the pixel keeps: this one, or zero (counted in `stats.dropped`) if it failed.
    #[inline]
    pub fn kept(self, stats: &mut RayStats) -> RgbSum {
        if self.failed() {
            stats.dropped += 1;
            RgbSum::default()
        } else {
            self.sum()
        }
    }
}

/// True for a contribution a pixel can hold: finite and non-negative.
#[inline]
pub fn valid(l: Vec3A) -> bool {
    l.is_finite() && l.min_element() >= 0.0
}

impl Record for SampleSum {
    #[inline(always)]
    fn add(&mut self, l: Vec3A, _: Technique, _: u32) {
        if !valid(l) {
            self.failed = true;
            return;
        }
        // TwoSum: s = a + b and its rounding error, exactly.
        let (a, b) = (self.fast, l.as_dvec3());
        let s = a + b;
        let bb = s - a;
        let err = (a - (s - bb)) + (b - bb);
        if err == glam::DVec3::ZERO {
            self.fast = s;
        } else {
            self.rest.add(l);
            self.rounded = true;
        }
    }
}

/// Render the scene on the current rayon pool; `on_tile` is called after each tile (progress).
pub fn render(scene: &RenderScene, on_tile: &(dyn Fn() + Sync)) -> Rendered {
    render_until(scene, on_tile, &AtomicBool::new(false))
}

/// [`render`], stopping early once `stop` is set: tiles already started are finished, tiles
/// not yet started stay black, and [`Rendered::tiles_done`] says how many were rendered. Each
/// finished tile holds every sample, so a stopped render is exact where it is not black.
pub fn render_until(
    scene: &RenderScene,
    on_tile: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Rendered {
    let spp = scene.film.spp;
    let t = match in_waves(scene, 0..spp, on_tile, stop, |s| s.mean(spp as u64)) {
        Some(t) => t,
        None => by_tiles(scene, on_tile, stop, |col, row, stats| {
            render_pixel(scene, col, row, stats)
        }),
    };
    Rendered {
        image: Image {
            width: scene.film.width,
            height: scene.film.height,
            pixels: t.pixels,
        },
        stats: t.stats,
        seconds: t.seconds,
        tiles_done: t.tiles_done,
        tiles: t.tiles,
    }
}

/// Render the sample indices `samples` of every pixel, keeping exact sums: passes of one
/// scene, merged, give the same bits as one render ([`render`]) of all its samples.
///
/// # Panics
/// If `samples` reaches past the film's spp (a caller's range bug; `pass::pass_range` gives
/// ranges within it).
pub fn render_pass(
    scene: &RenderScene,
    samples: std::ops::Range<u32>,
    on_tile: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Tiled<RgbSum> {
    assert!(
        samples.end <= scene.film.spp,
        "samples {}..{} of a render of {} spp: a pass holds sample indices below the spp",
        samples.start,
        samples.end,
        scene.film.spp
    );
    if let Some(t) = in_waves(scene, samples.clone(), on_tile, stop, |s| s) {
        return t;
    }
    by_tiles(scene, on_tile, stop, |col, row, stats| {
        pixel_sum(scene, col, row, samples.clone(), stats)
    })
}

/// `each` of the exact sum of the samples `samples` of every pixel, each tile's paths traced
/// in waves ([`waves::sums`]); `None` where the waves do not apply.
fn in_waves<T: Clone + Default + Send + Sync>(
    scene: &RenderScene,
    samples: std::ops::Range<u32>,
    on_tile: &(dyn Fn() + Sync),
    stop: &AtomicBool,
    each: impl Fn(RgbSum) -> T + Sync,
) -> Option<Tiled<T>> {
    let Shader::Path(p) = &scene.shader else {
        return None;
    };
    if !waves::applies(scene) {
        return None;
    }
    let tile = |pixels: &[(u32, u32)], stats: &mut RayStats, _: &mut ()| {
        let sums = waves::sums(scene, pixels, samples.clone(), p, stats);
        sums.into_iter().map(&each).collect()
    };
    Some(by_tile_pixels(scene, on_tile, stop, tile, |()| {}))
}

/// Per-pixel values of a tiled render (a pass's exact sums, for [`render_pass`]).
#[derive(Clone, Debug)]
pub struct Tiled<T> {
    /// Per-pixel values, row-major.
    pub pixels: Vec<T>,
    /// Rays traced, by kind.
    pub stats: RayStats,
    /// Wall-clock seconds spent tracing.
    pub seconds: f64,
    /// Tiles rendered (all of them unless stopped).
    pub tiles_done: u64,
    /// Tiles in the image.
    pub tiles: u64,
}

/// Run `pixel` over every pixel in 16x16 tiles on the current rayon pool; tiles not started
/// when `stop` is set keep `T::default()`.
fn by_tiles<T: Clone + Default + Send + Sync>(
    scene: &RenderScene,
    on_tile: &(dyn Fn() + Sync),
    stop: &AtomicBool,
    pixel: impl Fn(u32, u32, &mut RayStats) -> T + Sync,
) -> Tiled<T> {
    by_tiles_with(
        scene,
        on_tile,
        stop,
        |col, row, stats, _: &mut ()| pixel(col, row, stats),
        |()| {},
    )
}

/// [`by_tiles`] with a state per tile that `pixel` updates (for what a tile keeps of its
/// pixels, as its largest samples), handed to `finished` as the tile finishes.
fn by_tiles_with<T: Clone + Default + Send + Sync, S: Default + Send>(
    scene: &RenderScene,
    on_tile: &(dyn Fn() + Sync),
    stop: &AtomicBool,
    pixel: impl Fn(u32, u32, &mut RayStats, &mut S) -> T + Sync,
    finished: impl Fn(S) + Sync,
) -> Tiled<T> {
    let tile = |pixels: &[(u32, u32)], stats: &mut RayStats, state: &mut S| {
        pixels
            .iter()
            .map(|&(col, row)| pixel(col, row, stats, state))
            .collect()
    };
    by_tile_pixels(scene, on_tile, stop, tile, finished)
}

/// [`by_tiles_with`] with a function of all of a tile's pixels (in rows, top to bottom) that
/// gives their values in that order.
fn by_tile_pixels<T: Clone + Default + Send + Sync, S: Default + Send>(
    scene: &RenderScene,
    on_tile: &(dyn Fn() + Sync),
    stop: &AtomicBool,
    tile: impl Fn(&[(u32, u32)], &mut RayStats, &mut S) -> Vec<T> + Sync,
    finished: impl Fn(S) + Sync,
) -> Tiled<T> {
    let start = Instant::now();
    let (w, h) = (scene.film.width, scene.film.height);
    let tiles_x = w.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..tiles_x).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let done: Vec<Option<(Vec<T>, RayStats)>> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            let mut stats = RayStats::default();
            let mut state = S::default();
            let mut pixels = Vec::with_capacity((TILE * TILE) as usize);
            for row in y0..(y0 + TILE).min(h) {
                for col in x0..(x0 + TILE).min(w) {
                    pixels.push((col, row));
                }
            }
            let px = tile(&pixels, &mut stats, &mut state);
            finished(state);
            on_tile();
            Some((px, stats))
        })
        .collect();
    let mut stats = RayStats::default();
    let mut tiles_done = 0;
    for (_, st) in done.iter().flatten() {
        stats += *st;
        tiles_done += 1;
    }
    // The image, row by row from the tiles, in parallel: each pixel written once where it
    // lies (no zeroed image first; a tile not rendered gives `T::default()`). Done on one
    // thread, this copy and the image's page faults held the other threads idle at the end of
    // every round.
    let mut pixels = Vec::new();
    (0..w as usize * h as usize)
        .into_par_iter()
        .map(|k| {
            let (col, row) = ((k % w as usize) as u32, (k / w as usize) as u32);
            let (tx, ty) = (col / TILE, row / TILE);
            let tw = (tx * TILE + TILE).min(w) - tx * TILE;
            let i = (row - ty * TILE) * tw + (col - tx * TILE);
            done[(ty * tiles_x + tx) as usize]
                .as_ref()
                .map_or_else(T::default, |(px, _)| px[i as usize].clone())
        })
        .collect_into_vec(&mut pixels);
    Tiled {
        pixels,
        stats,
        seconds: start.elapsed().as_secs_f64(),
        tiles_done,
        tiles: tiles.len() as u64,
    }
}

/// Number of tiles a render of this film has (for progress bars).
pub fn tile_count(scene: &RenderScene) -> u64 {
    (scene.film.width.div_ceil(TILE) * scene.film.height.div_ceil(TILE)) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample's sum is exact whatever its contributions: those whose f64 adds would round go
    /// to the fixed-point accumulator, the total is the exact one; a failed contribution
    /// drops the sample.
    #[test]
    fn sample_sums_are_exact_over_any_range() {
        let mut rng = Sampler::new(7, 0, 0);
        for _ in 0..2000 {
            let (mut sample, mut want) = (SampleSum::default(), RgbSum::default());
            let n = 1 + (rng.next_f32() * 12.0) as usize;
            for _ in 0..n {
                // Magnitudes from 2^-140 to 2^120.
                let v = |u: f32| (2.0f32).powf(u * 260.0 - 140.0);
                let l = Vec3A::new(v(rng.next_f32()), v(rng.next_f32()), v(rng.next_f32()));
                sample.add(l, Technique::Light, 1);
                want.add(l);
            }
            assert_eq!(sample.sum(), want);
            let mut stats = RayStats::default();
            let mut pixel = RgbSum::default();
            sample.keep_into(&mut pixel, &mut stats);
            assert_eq!(pixel, want);
        }
        // Finite contributions whose sum is beyond the largest f32 fail the sample too.
        let mut sample = SampleSum::default();
        sample.add(Vec3A::splat(f32::MAX), Technique::Light, 1);
        assert!(!sample.failed());
        sample.add(Vec3A::new(0.0, f32::MAX, 0.0), Technique::Bsdf, 2);
        assert!(sample.failed());
        // Also when the part summed in f64 and the part summed in fixed point are each below
        // it: 2^126 and 2^74 add exactly, 1.5 * 2^127 would round and goes to fixed point.
        let mut sample = SampleSum::default();
        for v in [2f32.powi(126), 2f32.powi(74), 1.5 * 2f32.powi(127)] {
            sample.add(Vec3A::splat(v), Technique::Light, 1);
        }
        assert!(sample.rounded && sample.failed());
        let mut sample = SampleSum::default();
        sample.add(Vec3A::ONE, Technique::Light, 1);
        sample.add(Vec3A::new(1.0, f32::NAN, 0.0), Technique::Bsdf, 2);
        let mut stats = RayStats::default();
        assert_eq!(sample.kept(&mut stats), RgbSum::default());
        assert_eq!(stats.dropped, 1);
    }
}
