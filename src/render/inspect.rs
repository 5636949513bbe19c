//! Inspected renders: the image, to the bit as [`super::render`] makes it, with where its time
//! and its light went, pixel by pixel; and the replay of one sample.
//!
//! Each pixel keeps:
//! - the time its samples took to trace, measured around each sample;
//! - the rays it traced by kind, and the BVH nodes and primitives those rays tested (the
//!   queries compiled with counters, [`crate::accel::Traversal`]);
//! - its mean path length: the rays that are not shadow rays, per sample;
//! - the variance of its estimate, from the samples' spread;
//! - albedo, normal and depth at the camera ray's first hit (the mean over its samples);
//! - its light split by technique ([`Technique`]) and by bounce ([`crate::shader::record::BOUNCE_NAMES`]), each part
//!   the exact sum of the contributions it holds: the parts of a pixel sum exactly to its
//!   exact sum, so to the render's pixel.
//!
//! Every sample is traced alone, one ray at a time ([`crate::shader::radiance`]), not in
//! Path's waves ([`super::waves`]) or in groups of camera rays: those add the same bits, but
//! only a sample traced alone can be timed, counted and split on its own.
//!
//! The samples that stand out most above their pixel ("fireflies") are kept, then replayed
//! to give the path of each.
//! A replay ([`replay`]) traces one sample again from its own random stream, so that it finds
//! the same contributions to the bit.

use super::exact::RgbSum;
use super::film::Image;
use super::{RenderScene, SampleSum, Tiled, by_tiles_with, camera_ray, trace_sample, valid};
use crate::accel::Traversal;
use crate::shader::record::{BOUNCES, Event, bounce_of};
use crate::shader::surface::Interaction;
use crate::shader::{Record, Technique};
use crate::stats::RayStats;
use glam::{DVec3, Vec3A};
use serde::Serialize;
use std::collections::BinaryHeap;
use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// Parts of a pixel by technique, indexed by [`Technique::index`] (the path tracer's three,
/// then [`Technique::Shader`]).
pub const TECHNIQUES: usize = Technique::ALL.len();

/// What an inspected pixel measured (its exact sums, for tests and replays).
#[derive(Clone, Debug, Default)]
pub struct PixelSums {
    /// The exact sum of its samples: the render's.
    pub sum: RgbSum,
    /// The same contributions by technique.
    pub techniques: [RgbSum; TECHNIQUES],
    /// The same contributions by bounce.
    pub bounces: [RgbSum; BOUNCES],
}

/// One pixel of an inspected render.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelReport {
    /// The pixel's colour, as the render has it.
    pub color: Vec3A,
    /// Seconds spent tracing its samples.
    pub seconds: f64,
    /// Rays it traced, by kind (`dropped` counts its failed samples).
    pub rays: RayStats,
    /// BVH node tests of its rays.
    pub nodes: u64,
    /// Primitive tests of its rays.
    pub prims: u64,
    /// Rays per sample that are not shadow rays: camera, reflection, refraction and indirect
    /// (the path's length for Path; the tree's size for Global).
    pub path_length: f32,
    /// Variance of the pixel's estimate (the mean of its samples), per channel: the samples'
    /// variance over their count; zero with one sample per pixel.
    pub variance: Vec3A,
    /// Mean albedo at the first hit ([`crate::material::Material::albedo`]; 0 where the
    /// camera ray escapes).
    pub albedo: Vec3A,
    /// Mean shading normal at the first hit, on the camera's side (0 where it escapes).
    pub normal: Vec3A,
    /// Mean distance to the first hit (0 where it escapes).
    pub depth: f32,
    /// Its colour by technique (means of the exact parts).
    pub techniques: [Vec3A; TECHNIQUES],
    /// Its colour by bounce (means of the exact parts).
    pub bounces: [Vec3A; BOUNCES],
}

/// A sample kept for its size: which it is, and its radiance.
#[derive(Clone, Debug, Serialize)]
pub struct Firefly {
    /// The pixel's column and row.
    pub pixel: [u32; 2],
    /// The sample's index in the pixel.
    pub sample: u32,
    /// The sample's radiance: the exact sum of its contributions, rounded once.
    pub radiance: [f32; 3],
    /// Its luminance (Rec. 709 weights).
    pub luminance: f32,
    /// Its luminance less that of what it is ranked against ([`Inspect::against`]: a
    /// reference's pixel, or its own pixel's mean, or zero at 1 spp): how far the sample
    /// stands out. Fireflies are ranked by it.
    pub excess: f32,
    /// Its path, event by event (for the path tracer; other shaders record none).
    pub path: Vec<Event>,
}

/// Luminance of linear Rec. 709 RGB.
#[inline]
pub fn luminance(c: Vec3A) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// An inspected render.
#[derive(Clone, Debug)]
pub struct Inspected {
    /// The image, bit for bit the render's.
    pub image: Image,
    /// Each pixel's report, row-major.
    pub pixels: Vec<PixelReport>,
    /// Rays traced, by kind (the sum of the pixels').
    pub stats: RayStats,
    /// Wall-clock seconds of the whole render.
    pub seconds: f64,
    /// The samples that stand out most above their pixels, most first, with their paths.
    pub fireflies: Vec<Firefly>,
    /// Tiles rendered (all of them unless stopped).
    pub tiles_done: u64,
    /// Tiles in the image.
    pub tiles: u64,
}

/// The recorder of an inspected sample: its exact sum, and the same contributions by technique
/// and by bounce.
#[derive(Clone, Debug, Default)]
struct Parts {
    sample: SampleSum,
    techniques: [SampleSum; TECHNIQUES],
    bounces: [SampleSum; BOUNCES],
}

impl Record for Parts {
    #[inline]
    fn add(&mut self, l: Vec3A, technique: Technique, vertices: u32) {
        self.sample.add(l, technique, vertices);
        if valid(l) {
            self.techniques[technique.index()].add(l, technique, vertices);
            self.bounces[bounce_of(vertices)].add(l, technique, vertices);
        }
    }
}

/// A candidate firefly while the tiles render: excess, pixel index, sample, radiance.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    excess: f32,
    pixel: u64,
    sample: u32,
    radiance: Vec3A,
}

/// A candidate in the order of fireflies: larger excess first, then lower pixel index and
/// sample (a total order, so the same ones are kept whatever the tiles and threads); "greater"
/// is "ranked lower", so that a max-heap keeps the lowest ranked on top.
#[derive(Clone, Copy, Debug)]
struct Ranked(Candidate);

impl Ord for Ranked {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        let (a, b) = (&self.0, &o.0);
        b.excess
            .total_cmp(&a.excess)
            .then(a.pixel.cmp(&b.pixel))
            .then(a.sample.cmp(&b.sample))
    }
}

impl PartialOrd for Ranked {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

impl PartialEq for Ranked {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == std::cmp::Ordering::Equal
    }
}

impl Eq for Ranked {}

/// The `n` highest-ranked candidates so far (a heap with the lowest ranked on top).
#[derive(Clone, Debug, Default)]
struct Largest {
    n: usize,
    kept: BinaryHeap<Ranked>,
}

impl Largest {
    /// Keep `c` if it ranks among the `n` highest so far.
    fn offer(&mut self, c: Candidate) {
        if self.kept.len() < self.n {
            self.kept.push(Ranked(c));
        } else if self.kept.peek().is_some_and(|low| Ranked(c) < *low) {
            self.kept.pop();
            self.kept.push(Ranked(c));
        }
    }

    /// Keep the highest ranked of `self` and `other`.
    fn merge(&mut self, other: Largest) {
        for c in other.kept {
            self.offer(c.0);
        }
    }

    /// The candidates, highest ranked first.
    fn ranked(self) -> Vec<Candidate> {
        self.kept
            .into_sorted_vec()
            .into_iter()
            .map(|r| r.0)
            .collect()
    }
}

/// What an inspected render measures besides its image, and what its fireflies stand out from.
#[derive(Clone, Copy, Debug, Default)]
pub struct Inspect<'a> {
    /// Fireflies to keep (none if 0).
    pub fireflies: usize,
    /// Count BVH node and primitive tests (the time layer then includes the counting).
    pub counters: bool,
    /// The image fireflies stand out from (a reference); without one, each pixel's own mean,
    /// and at 1 spp, where a pixel has no mean but its one sample, zero (they are then the
    /// brightest samples).
    pub against: Option<&'a Image>,
}

/// Inspect the samples `samples` of pixel `(col, row)`: its exact sums, and its report (its
/// BVH counts if `counters`); `on_sample` is told, once the pixel is done, each sample's index
/// and kept radiance, and the pixel's colour.
pub fn inspect_pixel(
    scene: &RenderScene,
    (col, row): (u32, u32),
    samples: Range<u32>,
    counters: bool,
    stats: &mut RayStats,
    mut on_sample: impl FnMut(u32, Vec3A, Vec3A),
) -> (PixelSums, PixelReport) {
    let traversal = Traversal::default();
    let mut sums = PixelSums::default();
    let mut report = PixelReport::default();
    let mut own = RayStats::default();
    let (mut s1, mut s2) = (DVec3::ZERO, DVec3::ZERO);
    let (mut albedo, mut normal, mut depth) = (DVec3::ZERO, DVec3::ZERO, 0.0f64);
    let n = samples.len() as u64;
    let mut kept_samples = Vec::with_capacity(n as usize);
    for s in samples {
        // The sample, timed, its rays counted into this pixel's counters.
        let mut parts = Parts::default();
        let start = Instant::now();
        let (ray, sampler) = camera_ray(scene, col, row, s);
        let mut tracer = scene.tracer(sampler, &mut own);
        tracer.traversal = counters.then_some(&traversal);
        crate::shader::radiance(&scene.shader, &mut tracer, &ray, &mut parts);
        report.seconds += start.elapsed().as_secs_f64();
        // Kept or dropped as the render keeps it.
        let kept = parts.sample.kept(&mut own);
        if !parts.sample.failed() {
            sums.sum += kept;
            for (a, b) in sums.techniques.iter_mut().zip(&parts.techniques) {
                b.add_to(a);
            }
            for (a, b) in sums.bounces.iter_mut().zip(&parts.bounces) {
                b.add_to(a);
            }
        }
        let l = kept.mean(1);
        kept_samples.push((s, l));
        s1 += l.as_dvec3();
        s2 += (l * l).as_dvec3();
        // The first hit of the same camera ray, not counted (the render does not trace it).
        if let Some(hit) = scene.geometry.intersect(&ray) {
            let mut none = RayStats::default();
            let tr = scene.tracer(crate::sampling::Sampler::new(0, 0, 0), &mut none);
            let si = Interaction::new(&tr, &ray, hit);
            albedo += si.material().albedo().as_dvec3();
            normal += si.n.as_dvec3();
            depth += hit.t as f64;
        }
    }
    let nf = n.max(1) as f64;
    report.color = sums.sum.mean(n);
    for (s, l) in kept_samples {
        on_sample(s, l, report.color);
    }
    report.rays = own;
    report.nodes = traversal.nodes.get();
    report.prims = traversal.prims.get();
    report.path_length =
        ((own.camera + own.reflection + own.refraction + own.indirect) as f64 / nf) as f32;
    report.variance = if n >= 2 {
        // The samples' unbiased variance, over n: the variance of their mean.
        ((s2 - s1 * s1 / nf) / (nf - 1.0) / nf)
            .max(DVec3::ZERO)
            .as_vec3a()
    } else {
        Vec3A::ZERO
    };
    report.albedo = (albedo / nf).as_vec3a();
    report.normal = (normal / nf).as_vec3a();
    report.depth = (depth / nf) as f32;
    report.techniques = sums.techniques.map(|t| t.mean(n));
    report.bounces = sums.bounces.map(|b| b.mean(n));
    *stats += own;
    (sums, report)
}

/// Render `scene` inspected as `want` asks: every pixel's report, and the samples that stand
/// out most above their pixels (by luminance), with their paths. Tiles not started when `stop`
/// is set stay black.
pub fn inspect(
    scene: &RenderScene,
    want: Inspect,
    on_tile: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Inspected {
    let spp = scene.film.spp;
    let width = scene.film.width as u64;
    // Each tile keeps its own highest ranked, merged into these as it finishes.
    let all = Mutex::new(Largest {
        n: want.fireflies,
        kept: BinaryHeap::new(),
    });
    let tiled: Tiled<PixelReport> = by_tiles_with(
        scene,
        on_tile,
        stop,
        |col, row, stats, largest: &mut Largest| {
            largest.n = want.fireflies;
            let pixel = row as u64 * width + col as u64;
            let counters = want.counters;
            inspect_pixel(
                scene,
                (col, row),
                0..spp,
                counters,
                stats,
                |sample, l, color| {
                    if want.fireflies == 0 {
                        return;
                    }
                    let from = match want.against {
                        Some(image) => luminance(image.get(col, row)),
                        None if spp > 1 => luminance(color),
                        None => 0.0,
                    };
                    let excess = luminance(l) - from;
                    // Only samples above their pixel stand out.
                    if excess > 0.0 {
                        largest.offer(Candidate {
                            excess,
                            pixel,
                            sample,
                            radiance: l,
                        });
                    }
                },
            )
            .1
        },
        |largest| all.lock().expect("no tile panicked").merge(largest),
    );
    // The highest ranked of all, then each one's path.
    let all = all.into_inner().expect("no tile panicked").ranked();
    let fireflies = all
        .iter()
        .map(|c| {
            let (col, row) = ((c.pixel % width) as u32, (c.pixel / width) as u32);
            Firefly {
                pixel: [col, row],
                sample: c.sample,
                radiance: c.radiance.to_array(),
                luminance: luminance(c.radiance),
                excess: c.excess,
                path: replay(scene, col, row, c.sample).events,
            }
        })
        .collect();
    Inspected {
        image: Image {
            width: scene.film.width,
            height: scene.film.height,
            pixels: tiled.pixels.iter().map(|p| p.color).collect(),
        },
        pixels: tiled.pixels,
        stats: tiled.stats,
        seconds: tiled.seconds,
        fireflies,
        tiles_done: tiled.tiles_done,
        tiles: tiled.tiles,
    }
}

/// One sample traced again: what the render added for it, and its path.
#[derive(Clone, Debug)]
pub struct Replayed {
    /// The exact sum the render kept for the sample (zero if it failed).
    pub sum: RgbSum,
    /// True if one of its contributions was NaN, infinite or negative (the render dropped it).
    pub failed: bool,
    /// Its path, event by event (none for shaders other than Path).
    pub events: Vec<Event>,
    /// The rays it traced.
    pub stats: RayStats,
}

/// The recorder of a replay: the sample's sum, and every event.
#[derive(Default)]
struct Log {
    sample: SampleSum,
    events: Vec<Event>,
}

impl Record for Log {
    fn add(&mut self, l: Vec3A, technique: Technique, vertices: u32) {
        self.sample.add(l, technique, vertices);
    }

    fn event(&mut self, event: impl FnOnce() -> Event) {
        self.events.push(event());
    }
}

/// Trace sample `s` of pixel `(col, row)` again, as the render traced it, keeping its events.
pub fn replay(scene: &RenderScene, col: u32, row: u32, s: u32) -> Replayed {
    let mut stats = RayStats::default();
    let mut log = Log::default();
    trace_sample(scene, col, row, s, &mut stats, &mut log);
    Replayed {
        sum: log.sample.kept(&mut stats),
        failed: log.sample.failed(),
        events: log.events,
        stats,
    }
}

/// A named channel of an EXR file and its values, row-major.
pub type Channel = (String, Vec<f32>);

/// The image's channels `R`, `G`, `B`, then `prefix.R`, ... of each RGB part `part`.
fn rgb(prefix: &str, pixels: &[PixelReport], part: impl Fn(&PixelReport) -> Vec3A) -> Vec<Channel> {
    ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let values = pixels.iter().map(|p| part(p)[c]).collect();
            let name = match prefix {
                "" => name.to_string(),
                _ => format!("{prefix}.{name}"),
            };
            (name, values)
        })
        .collect()
}

/// The layers of `render --aov`: the image (`R`, `G`, `B`), then `time.us` (microseconds),
/// `rays.KIND`, `samples.dropped`, `bvh.nodes`, `bvh.prims`, `path.length`, `variance.R/G/B`, `albedo.R/G/B`,
/// `normal.X/Y/Z` and `depth.Z`.
pub fn aov_layers(r: &Inspected) -> Vec<Channel> {
    let px = &r.pixels;
    let one = |name: &str, f: &dyn Fn(&PixelReport) -> f32| -> Channel {
        (name.to_string(), px.iter().map(f).collect())
    };
    let mut layers = rgb("", px, |p| p.color);
    layers.push(one("time.us", &|p| (p.seconds * 1e6) as f32));
    layers.push(one("rays.camera", &|p| p.rays.camera as f32));
    layers.push(one("rays.shadow", &|p| p.rays.shadow as f32));
    layers.push(one("rays.reflection", &|p| p.rays.reflection as f32));
    layers.push(one("rays.refraction", &|p| p.rays.refraction as f32));
    layers.push(one("rays.indirect", &|p| p.rays.indirect as f32));
    layers.push(one("samples.dropped", &|p| p.rays.dropped as f32));
    layers.push(one("bvh.nodes", &|p| p.nodes as f32));
    layers.push(one("bvh.prims", &|p| p.prims as f32));
    layers.push(one("path.length", &|p| p.path_length));
    layers.extend(rgb("variance", px, |p| p.variance));
    layers.extend(rgb("albedo", px, |p| p.albedo));
    for (c, axis) in ["X", "Y", "Z"].iter().enumerate() {
        layers.push((
            format!("normal.{axis}"),
            px.iter().map(|p| p.normal[c]).collect(),
        ));
    }
    layers.push(one("depth.Z", &|p| p.depth));
    layers
}

/// The layers of `render --parts`: the image (`R`, `G`, `B`), then `technique.NAME.R/G/B` for
/// the path tracer's techniques and `bounce.NAME.R/G/B` for each bounce.
pub fn part_layers(r: &Inspected) -> Vec<Channel> {
    let px = &r.pixels;
    let mut layers = rgb("", px, |p| p.color);
    for t in Technique::PATH {
        layers.extend(rgb(&format!("technique.{}", t.name()), px, |p| {
            p.techniques[t.index()]
        }));
    }
    for (b, name) in crate::shader::record::BOUNCE_NAMES.iter().enumerate() {
        layers.extend(rgb(&format!("bounce.{name}"), px, |p| p.bounces[b]));
    }
    layers
}
