//! `rtis render`.

use super::interrupt::{self, Graceful};
use super::{CliError, Interrupted, load, runnable};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rtis::accel::Isa;
use rtis::render::estimate::{self, MAX_RAYS_UNFORCED, human_seconds};
use rtis::render::output::Transfer;
use rtis::render::pass::{self, Pass};
use rtis::render::{self, Film, output};
use std::path::{Path, PathBuf};

/// Arguments of `rtis render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene file (RON). Without one, the embedded Cornell box of the course is rendered.
    scene: Option<PathBuf>,
    /// Output image: .png (8-bit) or .exr (linear float). Default: the scene's name with .png.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Override the film width in pixels (1 to 32768; alone, the height keeps the aspect ratio).
    #[arg(long, allow_negative_numbers = true, value_parser = side())]
    width: Option<u32>,
    /// Override the film height in pixels (1 to 32768; alone, the width keeps the aspect ratio).
    #[arg(long, allow_negative_numbers = true, value_parser = side())]
    height: Option<u32>,
    /// Override the samples per pixel (1 to 1048576).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=rtis::render::MAX_SPP as i64))]
    spp: Option<u32>,
    /// Worker threads (default: one per core; at most 4 per core). The image does not depend
    /// on it.
    #[arg(long, allow_negative_numbers = true)]
    threads: Option<usize>,
    /// Override the scene's random seed.
    #[arg(long)]
    seed: Option<u64>,
    /// PNG transfer curve: srgb (default) or linear (the course's clamp-and-scale).
    #[arg(long, value_parser = parse_transfer)]
    transfer: Option<Transfer>,
    /// Write the ray statistics as JSON to this file.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Render even when the estimate is beyond 2e11 rays (about an hour on 2 cores).
    #[arg(long)]
    force: bool,
    /// Render only pass I of N (I from 0): a contiguous share of the sample indices, written as
    /// a pass EXR of exact sums for `rtis merge` (default name NAME.pass-I-of-N.exr).
    #[arg(long, value_parser = pass::parse_pass, value_name = "I/N")]
    pass: Option<(u32, u32)>,
    /// Instruction set of the SIMD code: the widest this CPU runs (auto), or one named, to
    /// measure what it is worth. The image is the same in each.
    #[arg(long, value_enum, default_value_t = IsaChoice::Auto)]
    isa: IsaChoice,
}

/// `--isa` of `rtis render`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum IsaChoice {
    /// The widest this CPU runs.
    Auto,
    /// Four-lane SSE2 (any x86-64 CPU).
    Baseline,
    /// Eight-lane AVX2.
    Avx2,
    /// Sixteen-lane AVX-512 for batched rays, AVX2's node test.
    Avx512,
}

impl IsaChoice {
    /// The instruction set meant, or an error if this CPU does not run it.
    fn isa(self) -> Result<Isa, CliError> {
        match self {
            IsaChoice::Auto => Ok(Isa::detect()),
            IsaChoice::Baseline => runnable(Isa::Baseline),
            IsaChoice::Avx2 => runnable(Isa::Avx2),
            IsaChoice::Avx512 => runnable(Isa::Avx512),
        }
    }
}

/// The parser of an image side: a whole number of pixels from 1 to [`render::MAX_SIDE`].
pub fn side() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(1..=render::MAX_SIDE as i64)
}

/// Film size from the scene's and the command line's: a side given alone keeps the scene's
/// aspect ratio.
pub fn film_size(scene: (u32, u32), width: Option<u32>, height: Option<u32>) -> (u32, u32) {
    let (w, h) = scene;
    let keep = |side: u32, num: u32, den: u32| {
        ((side as f64 * num as f64 / den as f64).round() as u32).max(1)
    };
    match (width, height) {
        (Some(w2), Some(h2)) => (w2, h2),
        (Some(w2), None) => (w2, keep(w2, h, w)),
        (None, Some(h2)) => (keep(h2, w, h), h2),
        (None, None) => (w, h),
    }
}

/// Most worker threads per core: more only add overhead.
pub const THREADS_PER_CORE: usize = 4;

/// The thread count to use for `--threads`, capped at [`THREADS_PER_CORE`] per core.
pub fn thread_count(asked: Option<usize>) -> Result<usize, CliError> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match asked {
        None => Ok(cores),
        Some(0) => Err("--threads must be at least 1".into()),
        Some(t) if t > THREADS_PER_CORE * cores => {
            let cap = THREADS_PER_CORE * cores;
            eprintln!(
                "warning: --threads {t} is more than {THREADS_PER_CORE} per core on this \
                 machine's {cores} cores; using {cap}"
            );
            Ok(cap)
        }
        Some(t) => Ok(t),
    }
}

/// Where a stopped render writes its image: `NAME.partial.EXT` beside the output.
pub fn partial_path(out: &Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map_or_else(|| "out".into(), |s| s.to_string_lossy().into_owned());
    let ext = out
        .extension()
        .map_or_else(|| "png".into(), |e| e.to_string_lossy().into_owned());
    out.with_file_name(format!("{stem}.partial.{ext}"))
}

fn parse_transfer(s: &str) -> Result<Transfer, String> {
    match s.to_ascii_lowercase().as_str() {
        "srgb" => Ok(Transfer::Srgb),
        "linear" => Ok(Transfer::Linear),
        _ => Err(format!("unknown transfer `{s}`: use srgb or linear")),
    }
}

/// Run `rtis render`.
pub fn run(a: RenderArgs) -> Result<(), CliError> {
    // Refused before the scene is read.
    let isa = a.isa.isa()?;
    let mut scene = load(a.scene.as_deref())?;
    let film = &mut scene.settings.film;
    let (width, height) = film_size((film.width, film.height), a.width, a.height);
    let overridden = Film {
        width,
        height,
        spp: a.spp.unwrap_or(film.spp),
        transfer: a.transfer.unwrap_or(film.transfer),
    };
    *film = overridden
        .checked()
        .map_err(|e| format!("command-line film override: {e}"))?;
    if let Some(seed) = a.seed {
        scene.settings.seed = seed;
    }
    let stem = a
        .scene
        .as_deref()
        .and_then(|p| p.file_stem())
        .map_or_else(|| "cornell".into(), |s| s.to_string_lossy().into_owned());
    let out = a.output.clone().unwrap_or_else(|| match a.pass {
        Some((i, n)) => PathBuf::from(format!("{stem}.pass-{i}-of-{n}.exr")),
        None => PathBuf::from(format!("{stem}.png")),
    });
    // Fail before a long render, not after it.
    output::check_writable(&out)?;
    let samples = match a.pass {
        Some((i, n)) => {
            if !out
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
            {
                return Err(format!(
                    "{}: a pass is written as an .exr file of exact sums (see rtis merge)",
                    out.display()
                )
                .into());
            }
            pass::pass_range(i, n, scene.settings.film.spp)?
        }
        None => 0..scene.settings.film.spp,
    };
    if let Some(path) = &a.stats {
        output::check_folder(path)?;
    }
    let threads = thread_count(a.threads)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }

    let mut prepared = rtis::extract(&scene);
    assert!(
        prepared.geometry.bvh.set_isa(isa),
        "checked by IsaChoice::isa"
    );
    for w in &prepared.warnings {
        eprintln!("warning: {w}");
    }
    eprintln!("effects {}", prepared.effects);
    eprintln!("SIMD: {}, {} rays per batch", isa.name(), isa.lanes());
    if prepared.geometry.in_bvh > 0 {
        eprintln!(
            "BVH: {} primitives, node test in {}",
            prepared.geometry.in_bvh,
            isa.node_test().name()
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;

    // What it will cost: the shader's rule and a short calibration (for a pass, its share).
    let est = estimate::estimate(&prepared).share(samples.len() as u32, prepared.film.spp);
    eprintln!(
        "estimate: {:.3e} rays, about {} on {threads} threads (calibrated on {} samples{})",
        est.rays(),
        human_seconds(est.seconds(threads)),
        est.calibration_samples,
        if est.proxy {
            ", a shallower Global scaled by the rule"
        } else {
            ""
        }
    );
    if est.rays() > MAX_RAYS_UNFORCED && !a.force {
        return Err(format!(
            "the estimate of {:.3e} rays is beyond the {MAX_RAYS_UNFORCED:.0e} rays rtis starts \
             without --force; lower the film size, spp or the shader's samples and depth, or \
             pass --force",
            est.rays()
        )
        .into());
    }

    let bar = ProgressBar::new(render::tile_count(&prepared));
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}",
        )
        .expect("valid template"),
    );
    let tick = || bar.inc(1);
    if a.pass.is_some() {
        // A pass is all or nothing: Ctrl-C quits at once (no Graceful), nothing is written.
        let sums = pool
            .install(|| render::render_pass(&prepared, samples.clone(), &tick, &interrupt::STOP));
        bar.finish_and_clear();
        Pass::from_render(&prepared, samples.clone(), sums.pixels).write(&out)?;
        eprintln!(
            "pass of samples {}..{} of {}: {}x{} in {:.2} s on {} threads, {} rays -> {}",
            samples.start,
            samples.end,
            prepared.film.spp,
            prepared.film.width,
            prepared.film.height,
            sums.seconds,
            pool.current_num_threads(),
            sums.stats.total(),
            out.display()
        );
        return Ok(());
    }
    let result = {
        let _graceful =
            Graceful::begin("finishing the tiles in flight, then writing the image so far");
        eprintln!(
            "rendering {} tiles; Ctrl-C keeps the image so far, twice quits",
            render::tile_count(&prepared)
        );
        pool.install(|| render::render_until(&prepared, &tick, &interrupt::STOP))
    };
    bar.finish_and_clear();

    if !result.is_complete() {
        // Interrupted: keep what the render has, under a name that says so.
        let partial = partial_path(&out);
        output::save(&result.image, &partial, prepared.film.transfer)?;
        eprintln!(
            "interrupted after {:.2} s: {} of {} tiles rendered ({:.1}% of the pixels, each with \
             all {} spp; the rest is black) -> {}",
            result.seconds,
            result.tiles_done,
            result.tiles,
            100.0 * result.tiles_done as f64 / result.tiles as f64,
            prepared.film.spp,
            partial.display()
        );
        return Err(Box::new(Interrupted));
    }
    output::save(&result.image, &out, prepared.film.transfer)?;
    if let Some(path) = &a.stats {
        let json = serde_json::to_string_pretty(&serde_json::json!({
            "seconds": result.seconds,
            "threads": pool.current_num_threads(),
            "rays": result.stats,
            "effects": prepared.effects,
            "total_rays": result.stats.total(),
            "estimated_rays": est.rays(),
            "mrays_per_second": result.mrays_per_second(),
        }))?;
        output::write_file(path, json.as_bytes())
            .map_err(|e| format!("cannot write stats: {e}"))?;
    }
    let s = &result.stats;
    if s.dropped > 0 {
        eprintln!(
            "warning: {} sample(s) came out NaN, infinite or negative and were dropped \
             (counted as black); the scene has a numerical problem worth reporting",
            s.dropped
        );
    }
    eprintln!(
        "{}x{} at {} spp in {:.2} s on {} threads: {} rays (camera {}, shadow {}, reflection {}, \
         refraction {}, indirect {}), {} dropped samples, {:.1} Mrays/s -> {}",
        prepared.film.width,
        prepared.film.height,
        prepared.film.spp,
        result.seconds,
        pool.current_num_threads(),
        s.total(),
        s.camera,
        s.shadow,
        s.reflection,
        s.refraction,
        s.indirect,
        s.dropped,
        result.mrays_per_second(),
        out.display()
    );
    Ok(())
}
