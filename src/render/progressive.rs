//! Progressive rendering: the whole frame refined in rounds of samples.
//!
//! Round after round renders a further range of sample indices of every pixel and adds their
//! exact sums ([`super::exact`]) to a [`Pass`]. The rounds double the samples held (1, 2, 4,
//! 8, ... spp in all), so after every round the image is a valid render of the whole frame at
//! fewer samples. Because the sums are exact, the image after the last round has the bits of a
//! one-go [`super::render`], whatever the rounds were, and a render stopped after any round
//! and resumed from its [`Pass`] ends with the same bits too.
//!
//! A time budget shortens the schedule: before each round, its time is predicted from the
//! seconds per sample measured so far, and the round is cut to the samples that fit (or not
//! started when not one fits). The budget counts the wall time of the rounds (from the start
//! of [`refine`]). The first round of a run always runs, so there is an image; under a budget
//! it is one sample, to measure the rate.
//!
//! The pass holds 120 bytes per pixel (exact sums) and a round as much again while it runs, so
//! films above [`MAX_PIXELS`] are rendered in one go instead (`rtis render` says so).

use super::exact::RgbSum;
use super::pass::{Differs, Pass, RenderId};
use super::{RenderScene, Tiled, render_pass};
use crate::stats::RayStats;
use std::ops::Range;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Largest film rendered progressively (2^23 pixels, 4096 x 2048): at most about 360 bytes
/// per pixel while a round is assembled, 3 GiB.
pub const MAX_PIXELS: u64 = 1 << 23;

/// What a progressive render has after a round.
#[derive(Clone, Debug)]
pub struct Round {
    /// The sample indices this round rendered.
    pub samples: Range<u32>,
    /// Samples per pixel held after it (this round's and every earlier one's).
    pub held: u64,
    /// Seconds this run has spent tracing so far.
    pub seconds: f64,
    /// Rays this run has traced so far, by kind.
    pub stats: RayStats,
}

/// How a progressive render ended.
#[derive(Clone, Debug)]
pub enum Ending {
    /// Every sample of the film is held.
    Complete,
    /// `stop` was set: the round in flight was dropped, the earlier rounds are held.
    Stopped {
        /// The round in flight, with the tiles it finished (the others hold no sample): not
        /// part of [`Progress::pass`]; a caller whose pass holds nothing yet may show these
        /// tiles rather than no image.
        dropped: (Range<u32>, Tiled<RgbSum>),
    },
    /// The next round did not fit the time budget.
    OutOfTime,
    /// The `on_round` callback asked to end.
    Declined,
}

impl Ending {
    /// Whether every sample is held.
    pub fn is_complete(&self) -> bool {
        matches!(self, Ending::Complete)
    }
}

/// The result of [`refine`].
#[derive(Clone, Debug)]
pub struct Progress {
    /// The exact sums of the samples held (those resumed from, and those rendered).
    pub pass: Pass,
    /// Rays traced in this run, by kind.
    pub stats: RayStats,
    /// Seconds this run spent tracing.
    pub seconds: f64,
    /// Rounds completed in this run.
    pub rounds: u32,
    /// Why it ended.
    pub ending: Ending,
}

/// Samples of the next round: as many as are held already (so the total doubles), at least
/// one, taken from the first range the pass does not hold; `None` when every sample is held.
pub fn next_round(pass: &Pass) -> Option<Range<u32>> {
    let gap = pass.missing().into_iter().next()?;
    let size = (pass.samples() as u32).clamp(1, gap.len() as u32);
    Some(gap.start..gap.start + size)
}

/// Render rounds of `scene` into `pass` (an empty [`Pass::empty`], or one resumed from) until
/// every sample is held, `stop` is set, the budget `budget` of tracing time is spent, or
/// `on_round` returns false. `on_round` sees the pass after each completed round; `on_tile`
/// is called after each tile of each round with the round's samples per pixel (progress).
///
/// A round stopped midway is dropped whole, so the pass only ever holds whole rounds: every
/// pixel always has the same samples.
pub fn refine(
    scene: &RenderScene,
    mut pass: Pass,
    budget: Option<Duration>,
    on_tile: &(dyn Fn(u32) + Sync),
    stop: &AtomicBool,
    on_round: &mut dyn FnMut(&Pass, &Round) -> bool,
) -> Progress {
    let start = Instant::now();
    let (mut stats, mut seconds, mut rounds) = (RayStats::default(), 0.0, 0);
    let mut traced: u64 = 0;
    let ending = loop {
        let Some(mut samples) = next_round(&pass) else {
            break Ending::Complete;
        };
        // Fit the round to what is left of the budget, at the rate measured so far; a resumed
        // render's first round is one sample, to measure the rate.
        if let Some(budget) = budget {
            let left = budget.as_secs_f64() - start.elapsed().as_secs_f64();
            if rounds == 0 {
                samples.end = samples.start + 1;
            } else {
                let per_sample = seconds / traced as f64;
                let fit = (left / per_sample).floor().min(samples.len() as f64);
                if fit < 1.0 {
                    break Ending::OutOfTime;
                }
                samples.end = samples.start + fit as u32;
            }
        }
        let size = samples.len() as u32;
        let part = render_pass(scene, samples.clone(), &|| on_tile(size), stop);
        if part.tiles_done < part.tiles {
            break Ending::Stopped {
                dropped: (samples, part),
            };
        }
        pass.add(samples.clone(), &part.pixels);
        stats += part.stats;
        seconds += part.seconds;
        traced += samples.len() as u64;
        rounds += 1;
        let round = Round {
            samples,
            held: pass.samples(),
            seconds,
            stats,
        };
        if !on_round(&pass, &round) {
            break if pass.is_complete() {
                Ending::Complete
            } else {
                Ending::Declined
            };
        }
    };
    Progress {
        pass,
        stats,
        seconds,
        rounds,
        ending,
    }
}

/// Check that `pass` (read from a file) belongs to `scene` and may be resumed by [`refine`]:
/// the same size, fingerprint, seed and spp. The message names what differs.
pub fn check_resumable(scene: &RenderScene, pass: &Pass) -> Result<(), String> {
    let Some((part, file, now)) = pass.render().differs(&RenderId::of(scene)) else {
        return Ok(());
    };
    let (what, file) = match part {
        Differs::Size => ("film size", file),
        Differs::Fingerprint => ("scene", format!("fingerprint {file}")),
        Differs::Seed => ("seed", file),
        Differs::Spp => ("spp", file),
    };
    Err(format!(
        "it is a render of another {what} ({file}, the scene now gives {now}): resume only with \
         the scene, film, seed and settings it was rendered with"
    ))
}
