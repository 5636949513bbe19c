//! What a render will cost, before it starts: rays from the shader's rule, and seconds from a
//! short calibration that traces a few of the render's own samples.
//!
//! The course's shaders trace a number of rays per camera sample that their equations fix:
//! with `L` point lights (shadow rays when the shadows effect is on), a camera ray that meets
//! a Phong surface traces `1 + L` rays under Direct, and Global adds `n` hemisphere rays at
//! the first hit, each of which spawns the two rays of the n-bounce rule at every depth below
//! `D`: `(1 + L) (1 + n (2^D - 1))` in all. Area lights add `light_samples` shadow rays per
//! Phong hit to `L`. The rule counts a scene where every ray meets a
//! Phong surface; rays that escape trace fewer, mirror and glass chains more. The calibration
//! measures the real count on samples spread over the image and scales it; where one sample
//! would take too long to calibrate, it measures a shallower Global and scales by the rule.

use super::{RenderScene, render_sample};
use crate::shader::Shader;
use crate::stats::RayStats;
use std::time::Instant;

/// Rays a calibration traces at most (about 0.1 s on one thread).
pub const CALIBRATION_RAYS: f64 = 4e6;

/// Most camera samples a calibration traces.
pub const CALIBRATION_SAMPLES: u64 = 1024;

/// Estimates above this many rays need `--force` (about an hour on 2 cores).
pub const MAX_RAYS_UNFORCED: f64 = 2e11;

/// Rays per camera sample by the shader's rule, for a scene where every ray meets a Phong
/// surface; `None` for Path, whose path lengths Russian roulette and the scene decide.
pub fn rule_rays_per_sample(scene: &RenderScene) -> Option<f64> {
    let point = if scene.effects.shadows {
        scene.lights.len() as f64
    } else {
        0.0
    };
    // Shadow rays per Phong hit: one per point light and one per area-light sample.
    let lights = |light_samples: u32| {
        let area = scene.effects.shadows && scene.effects.emission;
        point + if area { light_samples as f64 } else { 0.0 }
    };
    match scene.shader {
        Shader::Intersection { .. } | Shader::Depth { .. } | Shader::Normal => Some(1.0),
        Shader::Direct { light_samples, .. } => Some(1.0 + lights(light_samples)),
        Shader::Global(g) => {
            let below = if g.max_depth == 0 || !scene.effects.indirect {
                0.0
            } else {
                g.samples as f64 * (2f64.powi(g.max_depth as i32) - 1.0)
            };
            Some((1.0 + lights(g.light_samples)) * (1.0 + below))
        }
        Shader::Path(_) => None,
    }
}

/// A render's estimated cost.
#[derive(Clone, Copy, Debug)]
pub struct Estimate {
    /// Camera samples in the render (pixels times spp).
    pub samples: u64,
    /// Rays per sample by the shader's rule (see [`rule_rays_per_sample`]).
    pub rule_per_sample: Option<f64>,
    /// Rays per sample measured by the calibration (scaled by the rule when it ran a shallower
    /// Global).
    pub rays_per_sample: f64,
    /// Seconds per ray on one thread, measured.
    pub seconds_per_ray: f64,
    /// Samples the calibration traced.
    pub calibration_samples: u64,
    /// Whether the calibration traced a shallower Global and scaled by the rule.
    pub proxy: bool,
}

impl Estimate {
    /// Rays the whole render will trace.
    pub fn rays(&self) -> f64 {
        self.rays_per_sample * self.samples as f64
    }

    /// The estimate for `spp` of the film's `of` samples per pixel (a pass's share).
    pub fn share(self, spp: u32, of: u32) -> Estimate {
        Estimate {
            samples: self.samples / of.max(1) as u64 * spp as u64,
            ..self
        }
    }

    /// Wall seconds on `threads` threads (assuming they scale linearly).
    pub fn seconds(&self, threads: usize) -> f64 {
        self.rays() * self.seconds_per_ray / threads.max(1) as f64
    }
}

/// The calibration scene: `scene` itself, or, when one sample of it would take more than
/// [`CALIBRATION_RAYS`], the same scene with a shallower Global.
fn calibration_scene(scene: &RenderScene) -> (RenderScene, bool) {
    let mut s = scene.clone();
    let mut proxy = false;
    while rule_rays_per_sample(&s).unwrap_or(0.0) > CALIBRATION_RAYS / 16.0 {
        match &mut s.shader {
            Shader::Global(g) if g.max_depth > 1 => g.max_depth -= 1,
            _ => break,
        }
        proxy = true;
    }
    (s, proxy)
}

/// Estimate the cost of rendering `scene` by tracing up to [`CALIBRATION_SAMPLES`] of its
/// samples, spread evenly over its pixels and sample indices, on this thread.
pub fn estimate(scene: &RenderScene) -> Estimate {
    let film = scene.film;
    let pixels = film.width as u64 * film.height as u64;
    let samples = pixels * film.spp as u64;
    let (cal, proxy) = calibration_scene(scene);
    let per = rule_rays_per_sample(&cal).unwrap_or(64.0).max(1.0);
    let n = ((CALIBRATION_RAYS / per) as u64).clamp(1, CALIBRATION_SAMPLES.min(samples));
    let mut stats = RayStats::default();
    let start = Instant::now();
    for k in 0..n {
        // Sample k of n, evenly spaced over (pixel, sample index) in the render's order.
        let i = (k as u128 * samples as u128 / n as u128) as u64 + samples / n / 2;
        let (pixel, s) = (i / film.spp as u64, (i % film.spp as u64) as u32);
        let (col, row) = (
            (pixel % film.width as u64) as u32,
            (pixel / film.width as u64) as u32,
        );
        render_sample(&cal, col, row, s, &mut stats);
    }
    let seconds = start.elapsed().as_secs_f64();
    let rays = stats.total().max(1) as f64;
    let measured = rays / n as f64;
    let rays_per_sample = match (proxy, rule_rays_per_sample(scene)) {
        // The shallower Global met `measured / rule(cal)` of its rule's rays; the render's own
        // rule scaled alike.
        (true, Some(full)) => full * measured / per,
        _ => measured,
    };
    Estimate {
        samples,
        rule_per_sample: rule_rays_per_sample(scene),
        rays_per_sample,
        seconds_per_ray: seconds / rays,
        calibration_samples: n,
        proxy,
    }
}

/// A duration for people: seconds, minutes, hours or days.
pub fn human_seconds(s: f64) -> String {
    match s {
        s if s < 120.0 => format!("{s:.1} s"),
        s if s < 7200.0 => format!("{:.1} min", s / 60.0),
        s if s < 172_800.0 => format!("{:.1} h", s / 3600.0),
        s => format!("{:.1} days", s / 86400.0),
    }
}
