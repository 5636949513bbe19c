//! `rtis render`.

use super::interrupt::{self, Graceful};
use super::{CliError, Interrupted, load, runnable};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rtis::accel::Isa;
use rtis::render::estimate::{self, MAX_RAYS_UNFORCED, human_seconds};
use rtis::render::film::Image;
use rtis::render::inspect;
use rtis::render::output::Transfer;
use rtis::render::pass::{self, Pass};
use rtis::render::progressive::{self, Ending};
use rtis::render::tev::Display;
use rtis::render::{self, Film, output};
use rtis::sampling::SamplerKind;
use rtis::stats::RayStats;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `rtis render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene file (RON, or a Mitsuba 3 scene `.xml`, converted). Without one, the embedded Cornell box of the course is rendered.
    scene: Option<PathBuf>,
    /// Output image: .png (8-bit) or .exr (linear float). Default: the scene's name with .png.
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    film: Overrides,
    /// Worker threads (default: one per core; at most 4 per core). The image does not depend
    /// on it.
    #[arg(long, allow_negative_numbers = true)]
    threads: Option<usize>,
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
    /// Stop after the round of samples that fits this much time of rendering rounds (e.g. 30s,
    /// 2m, 1h, 500ms; a bare number is seconds). The image then holds fewer spp and says so;
    /// its pass (NAME.partial.exr beside a PNG, or the .exr output itself) resumes with
    /// --resume.
    #[arg(long, value_parser = parse_duration, value_name = "DURATION", conflicts_with = "pass")]
    time: Option<Duration>,
    /// Continue the render held by this pass file (written by a stopped or timed render, or by
    /// --pass): the scene, film, seed and settings must be the ones it was rendered with. The
    /// image then has the bits of a render never stopped.
    #[arg(long, value_name = "PASS.exr", conflicts_with = "pass")]
    resume: Option<PathBuf>,
    /// Stream each progressive round to the tev image viewer listening at HOST:PORT (tev's
    /// default is 127.0.0.1:14158), as pbrt-v4's --display-server does.
    #[arg(long, value_name = "HOST:PORT", conflicts_with = "pass")]
    display: Option<String>,
    /// Instruction set of the SIMD code: the widest this CPU runs (auto), or one named, to
    /// measure what it is worth. The image is the same in each.
    #[arg(long, value_enum, default_value_t = IsaChoice::Auto)]
    isa: IsaChoice,
    /// Also write per-pixel statistics as layers of this EXR: time, rays by kind, dropped
    /// samples, BVH node and primitive tests, path length, variance of the estimate, and
    /// albedo, normal and depth at the first hit (docs/inspect.md). The image is the same, to
    /// the bit.
    #[arg(long, value_name = "FILE.exr", conflicts_with_all = INSPECT_CONFLICTS)]
    aov: Option<PathBuf>,
    /// Also write the image split by technique (emitted, light-sampled, BSDF-sampled, each
    /// with its MIS weight) and by bounce (direct, 1, 2, 3+) as layers of this EXR: the parts'
    /// exact sums add up to the image's, bit for bit (the layers, each rounded to f32, to
    /// within rounding). Path only.
    #[arg(long, value_name = "FILE.exr", conflicts_with_all = INSPECT_CONFLICTS)]
    parts: Option<PathBuf>,
    /// Keep the N single samples that stand out most above their pixel's mean by luminance (at
    /// 1 spp the brightest), with the path of each, as JSON in NAME.fireflies.json beside the
    /// image (at most 10000).
    #[arg(long, value_name = "N", conflicts_with_all = INSPECT_CONFLICTS,
          value_parser = clap::value_parser!(u32).range(1..=MAX_FIREFLIES as i64))]
    fireflies: Option<u32>,
}

/// True if `a` and `b` name one file: the same name in the same folder, the folders resolved
/// (`..`, links) where they exist.
fn same_file(a: &Path, b: &Path) -> bool {
    let resolved = |p: &Path| {
        let folder = match p.parent() {
            Some(f) if !f.as_os_str().is_empty() => f,
            _ => Path::new("."),
        };
        let folder = folder
            .canonicalize()
            .or_else(|_| std::path::absolute(folder))
            .unwrap_or_else(|_| folder.to_path_buf());
        (folder, p.file_name().map(|n| n.to_os_string()))
    };
    resolved(a) == resolved(b)
}

/// Where `--fireflies` writes: NAME.fireflies.json beside the image NAME.EXT.
fn fireflies_path(image: &Path) -> PathBuf {
    image.with_extension("fireflies.json")
}

/// Most fireflies `--fireflies` keeps.
pub const MAX_FIREFLIES: u32 = 10_000;

/// What an inspected render (`--aov`, `--parts`, `--fireflies`) cannot be combined with: it
/// renders all the samples in one go.
const INSPECT_CONFLICTS: [&str; 4] = ["pass", "time", "resume", "display"];

impl RenderArgs {
    /// True if the render is inspected (`--aov`, `--parts` or `--fireflies`).
    fn inspected(&self) -> bool {
        self.aov.is_some() || self.parts.is_some() || self.fireflies.is_some()
    }
}

/// The film size, spp, sampler and seed of a render where the command line overrides the
/// scene's (the same for `rtis replay`, whose sample depends on them).
#[derive(Args, Debug, Clone, Copy)]
pub struct Overrides {
    /// Override the film width in pixels (1 to 32768; alone, the height keeps the aspect ratio).
    #[arg(long, allow_negative_numbers = true, value_parser = side())]
    width: Option<u32>,
    /// Override the film height in pixels (1 to 32768; alone, the width keeps the aspect ratio).
    #[arg(long, allow_negative_numbers = true, value_parser = side())]
    height: Option<u32>,
    /// Override the samples per pixel (1 to 1048576).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=rtis::render::MAX_SPP as i64))]
    spp: Option<u32>,
    /// Override the scene's random seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Override the film's sampler: independent numbers, or Sobol' points.
    #[arg(long, value_enum)]
    sampler: Option<SamplerChoice>,
}

/// `--sampler`: the film's `sampler`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplerChoice {
    /// Independent uniform numbers (PCG32).
    Independent,
    /// Padded, Owen-scrambled Sobol' points.
    Sobol,
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

/// The scene at `path` (the embedded box if none) with the command line's film size, spp,
/// sampler and seed (`over`) and transfer, where given.
pub fn load_overridden(
    path: Option<&Path>,
    over: Overrides,
    transfer: Option<Transfer>,
) -> Result<rtis::scene::Scene, CliError> {
    let mut scene = load(path)?;
    let film = &mut scene.settings.film;
    let (width, height) = film_size((film.width, film.height), over.width, over.height);
    let overridden = Film {
        width,
        height,
        spp: over.spp.unwrap_or(film.spp),
        transfer: transfer.unwrap_or(film.transfer),
        sampler: match over.sampler {
            Some(SamplerChoice::Independent) => SamplerKind::Independent,
            Some(SamplerChoice::Sobol) => SamplerKind::Sobol,
            None => film.sampler,
        },
        ..*film
    };
    *film = overridden
        .checked()
        .map_err(|e| format!("command-line film override: {e}"))?;
    if let Some(seed) = over.seed {
        scene.settings.seed = seed;
    }
    Ok(scene)
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

/// Parse a duration: a number with `ms`, `s`, `m` or `h`, or a bare number of seconds.
pub fn parse_duration(s: &str) -> Result<Duration, String> {
    let t = s.trim();
    let (number, unit) = match t.rfind(|c: char| c.is_ascii_digit() || c == '.') {
        // A bare number (1e3 included) is seconds.
        _ if t.parse::<f64>().is_ok() => (t, "s"),
        Some(i) => t.split_at(i + 1),
        None => (t, "?"),
    };
    let scale = match unit.trim() {
        "ms" => 1e-3,
        "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        _ => return Err(format!("`{s}`: write a duration as 30s, 2m, 1h or 500ms")),
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v * scale <= 1e9 => {
            Ok(Duration::from_secs_f64(v * scale))
        }
        _ => Err(format!(
            "`{s}`: a duration is a positive number with a unit, as 30s, 2m, 1h or 500ms"
        )),
    }
}

fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Write an image that holds fewer samples than the film asks (a stopped or timed render) and
/// its pass `pass_file` for `--resume`: when `image` is an .exr it is that pass (a pass file is
/// an EXR whose R, G, B show the image); a PNG notes its spp in a `Comment` text.
fn save_unfinished(
    pass: &Pass,
    image: &Path,
    pass_file: &Path,
    transfer: Transfer,
) -> Result<(), CliError> {
    pass.write(pass_file)?;
    if image != pass_file {
        let note = format!(
            "rtis: {} of {} samples per pixel (samples {})",
            pass.samples(),
            pass.spp,
            pass::describe_held(pass)
        );
        output::save_noted(&pass.image(), image, transfer, &note)?;
    }
    Ok(())
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
    let scene = load_overridden(a.scene.as_deref(), a.film, a.transfer)?;
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
            if !is_exr(&out) {
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
    // Every file written is its own: a layer file over the image would replace it.
    let fireflies_file = a.fireflies.map(|_| fireflies_path(&out));
    let written: Vec<&Path> = [
        Some(out.as_path()),
        a.aov.as_deref(),
        a.parts.as_deref(),
        fireflies_file.as_deref(),
        a.stats.as_deref(),
    ]
    .into_iter()
    .flatten()
    .collect();
    for (i, p) in written.iter().enumerate() {
        if written[..i].iter().any(|q| same_file(q, p)) {
            return Err(format!(
                "{}: written twice (the image, --aov, --parts, the fireflies' JSON and --stats \
                 each need their own file)",
                p.display()
            )
            .into());
        }
    }
    if a.inspected() {
        let (w, h) = (scene.settings.film.width, scene.settings.film.height);
        if w as u64 * h as u64 > progressive::MAX_PIXELS {
            return Err(format!(
                "--aov, --parts and --fireflies hold up to 800 bytes per pixel while they render: \
                 at most {} pixels, and this film has {w}x{h}",
                progressive::MAX_PIXELS,
            )
            .into());
        }
    }
    for path in [&a.aov, &a.parts].into_iter().flatten() {
        if !is_exr(path) {
            return Err(format!(
                "{}: per-pixel layers are written as an .exr file",
                path.display()
            )
            .into());
        }
        output::check_writable(path)?;
    }

    let threads = thread_count(a.threads)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }

    let mut prepared = rtis::extract(&scene);
    if a.parts.is_some() && !matches!(prepared.shader, rtis::shader::Shader::Path(_)) {
        return Err(
            "--parts splits the path tracer's light by technique and bounce: the scene's \
             shader is not Path (set shader: Path(...) in the scene)"
                .into(),
        );
    }
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
    // The samples a resumed render already holds.
    let start = match &a.resume {
        Some(path) => {
            let held = Pass::read(path)?;
            progressive::check_resumable(&prepared, &held)
                .map_err(|e| format!("{}: cannot resume: {e}", path.display()))?;
            eprintln!(
                "resuming from {}: {} of {} spp held",
                path.display(),
                held.samples(),
                held.spp
            );
            Some(held)
        }
        // Only a progressive render holds a pass (120 bytes per pixel) while it runs.
        None => None,
    };
    let to_render = match (a.pass, &start) {
        (Some(_), _) => samples.len() as u32,
        (None, Some(held)) => prepared.film.spp - held.samples() as u32,
        (None, None) => prepared.film.spp,
    };

    // What it will cost: the shader's rule and a short calibration (for a pass, its share).
    let est = estimate::estimate(&prepared).share(to_render, prepared.film.spp);
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
    if a.inspected() {
        return inspected(&prepared, &pool, &bar, &out, &a, &est);
    }
    let film = prepared.film;
    if film.width as u64 * film.height as u64 > progressive::MAX_PIXELS {
        // Too large to hold a pass of exact sums: one go, as a pass-free render.
        if a.time.is_some() || a.resume.is_some() || a.display.is_some() {
            return Err(format!(
                "--time, --resume and --display render progressively, which holds 120 bytes \
                 per pixel: at most {} pixels, and this film has {}x{}",
                progressive::MAX_PIXELS,
                film.width,
                film.height
            )
            .into());
        }
        return render_in_one_go(&prepared, &pool, &bar, &out, a.stats.as_deref(), &est);
    }
    let mut display = match &a.display {
        Some(address) => {
            let name = out
                .file_name()
                .map_or_else(|| stem.clone(), |n| n.to_string_lossy().into_owned());
            let d = Display::connect(address, &name, film.width, film.height)?;
            eprintln!("streaming each round to tev at {address} as `{name}`");
            Some(d)
        }
        None => None,
    };
    if to_render == 0 {
        eprintln!("every sample is held already: writing the image");
    }
    // Progressive rounds over the whole frame; the bar counts pixel-samples.
    bar.set_length(render::tile_count(&prepared) * to_render as u64);
    let tick = |samples: u32| bar.inc(samples as u64);
    let progress = {
        let _graceful = Graceful::begin(
            "dropping the round in flight, then writing the image of the rounds done",
        );
        eprintln!(
            "rendering in rounds of doubling spp; Ctrl-C keeps the last whole round, twice quits"
        );
        let mut on_round = |held: &Pass, r: &progressive::Round| {
            bar.suspend(|| {
                eprintln!(
                    "round: samples {}..{}, {} of {} spp after {:.2} s",
                    r.samples.start, r.samples.end, r.held, film.spp, r.seconds
                )
            });
            if let Some(d) = &mut display
                && let Err(e) = d.show(&held.image())
            {
                bar.suspend(|| eprintln!("warning: tev stopped taking images ({e}); rendering on"));
                display = None;
            }
            true
        };
        pool.install(|| {
            progressive::refine(
                &prepared,
                start.unwrap_or_else(|| Pass::empty(&prepared)),
                a.time,
                &tick,
                &interrupt::STOP,
                &mut on_round,
            )
        })
    };
    bar.finish_and_clear();
    let pass = &progress.pass;
    // The pass of an unfinished render, for --resume: the output itself when it is an EXR,
    // else NAME.partial.exr beside it.
    let partial = partial_path(&out);
    let pass_file = |image: &Path| {
        if is_exr(image) {
            image.to_path_buf()
        } else {
            partial.with_extension("exr")
        }
    };
    match &progress.ending {
        Ending::Stopped {
            dropped: (samples, tiles),
        } if pass.samples() == 0 => {
            // Stopped in the first round (a scene of few spp, as the course's 1 spp with
            // Global): keep its finished tiles, each with all the round's samples.
            if tiles.tiles_done == 0 {
                eprintln!("interrupted before a tile was finished: no image written");
                return Err(Box::new(Interrupted));
            }
            let n = samples.len() as u64;
            let image = Image {
                width: film.width,
                height: film.height,
                pixels: tiles.pixels.iter().map(|s| s.mean(n)).collect(),
            };
            output::save(&image, &partial, film.transfer)?;
            eprintln!(
                "interrupted after {:.2} s in the first round: {} of {} tiles rendered ({:.1}% of \
                 the pixels, each with {n} spp; the rest is black) -> {}",
                tiles.seconds,
                tiles.tiles_done,
                tiles.tiles,
                100.0 * tiles.tiles_done as f64 / tiles.tiles as f64,
                partial.display()
            );
            return Err(Box::new(Interrupted));
        }
        Ending::Stopped { .. } => {
            // Interrupted: keep the last whole round, under a name that says so.
            let resume = pass_file(&partial);
            save_unfinished(pass, &partial, &resume, film.transfer)?;
            eprintln!(
                "interrupted after {:.2} s: the whole frame at {} of {} spp -> {}; continue with \
                 --resume {}",
                progress.seconds,
                pass.samples(),
                film.spp,
                partial.display(),
                resume.display()
            );
            return Err(Box::new(Interrupted));
        }
        Ending::OutOfTime | Ending::Declined => {
            let resume = pass_file(&out);
            save_unfinished(pass, &out, &resume, film.transfer)?;
            eprintln!(
                "time budget spent: the whole frame at {} of {} spp -> {}; continue with \
                 --resume {}",
                pass.samples(),
                film.spp,
                out.display(),
                resume.display()
            );
        }
        Ending::Complete => output::save(&pass.image(), &out, film.transfer)?,
    }
    summary(
        &prepared,
        &pool,
        &Summary {
            spp: pass.samples(),
            rounds: progress.rounds,
            seconds: progress.seconds,
            stats: progress.stats,
        },
        &out,
        a.stats.as_deref(),
        &est,
    )
}

/// What a finished render reports.
struct Summary {
    /// Samples per pixel in the image written.
    spp: u64,
    /// Progressive rounds (1 for a render in one go).
    rounds: u32,
    /// Seconds spent tracing.
    seconds: f64,
    /// Rays by kind.
    stats: RayStats,
}

impl Summary {
    /// A render of all the film's samples in one round.
    fn one_go(prepared: &rtis::RenderScene, seconds: f64, stats: RayStats) -> Summary {
        Summary {
            spp: prepared.film.spp as u64,
            rounds: 1,
            seconds,
            stats,
        }
    }
}

/// A film too large for a progressive pass: tiles rendered once each with all their samples,
/// as before progressive rendering; Ctrl-C keeps the tiles finished.
fn render_in_one_go(
    prepared: &rtis::RenderScene,
    pool: &rayon::ThreadPool,
    bar: &ProgressBar,
    out: &Path,
    stats: Option<&Path>,
    est: &estimate::Estimate,
) -> Result<(), CliError> {
    let tick = || bar.inc(1);
    let result = {
        let _graceful =
            Graceful::begin("finishing the tiles in flight, then writing the image so far");
        eprintln!(
            "rendering {} tiles in one go (a film above {} pixels is not progressive); Ctrl-C \
             keeps the tiles finished, twice quits",
            render::tile_count(prepared),
            progressive::MAX_PIXELS
        );
        pool.install(|| render::render_until(prepared, &tick, &interrupt::STOP))
    };
    bar.finish_and_clear();
    let film = prepared.film;
    if !result.is_complete() {
        let partial = partial_path(out);
        output::save(&result.image, &partial, film.transfer)?;
        eprintln!(
            "interrupted after {:.2} s: {} of {} tiles rendered (each with all {} spp; the rest \
             is black) -> {}",
            result.seconds,
            result.tiles_done,
            result.tiles,
            film.spp,
            partial.display()
        );
        return Err(Box::new(Interrupted));
    }
    output::save(&result.image, out, film.transfer)?;
    let run = Summary::one_go(prepared, result.seconds, result.stats);
    summary(prepared, pool, &run, out, stats, est)
}

/// An inspected render: all the samples in one go, measured pixel by pixel; the image, then
/// the layers and fireflies asked for. Ctrl-C writes nothing.
fn inspected(
    prepared: &rtis::RenderScene,
    pool: &rayon::ThreadPool,
    bar: &ProgressBar,
    out: &Path,
    a: &RenderArgs,
    est: &estimate::Estimate,
) -> Result<(), CliError> {
    let tick = || bar.inc(1);
    let fireflies = a.fireflies.unwrap_or(0) as usize;
    let result = {
        let _graceful = Graceful::begin("stopping: an inspected render writes nothing unfinished");
        eprintln!(
            "rendering {} tiles in one go, inspected (Ctrl-C stops and writes nothing)",
            render::tile_count(prepared)
        );
        let want = inspect::Inspect {
            fireflies,
            counters: a.aov.is_some(),
            against: None,
        };
        pool.install(|| inspect::inspect(prepared, want, &tick, &interrupt::STOP))
    };
    bar.finish_and_clear();
    if result.tiles_done < result.tiles {
        eprintln!("interrupted: an inspected render writes nothing unfinished");
        return Err(Box::new(Interrupted));
    }
    let film = prepared.film;
    output::save(&result.image, out, film.transfer)?;
    if let Some(path) = &a.aov {
        output::write_layers(path, film.width, film.height, inspect::aov_layers(&result))?;
        let nodes: u64 = result.pixels.iter().map(|p| p.nodes).sum();
        let prims: u64 = result.pixels.iter().map(|p| p.prims).sum();
        eprintln!(
            "per-pixel statistics -> {} ({nodes} BVH node tests, {prims} primitive tests)",
            path.display()
        );
    }
    if let Some(path) = &a.parts {
        output::write_layers(path, film.width, film.height, inspect::part_layers(&result))?;
        eprintln!("image by technique and by bounce -> {}", path.display());
    }
    if fireflies > 0 {
        let path = fireflies_path(out);
        let json = serde_json::to_string_pretty(&serde_json::json!({
            "scene": a.scene.as_ref().map(|p| p.display().to_string()),
            "width": film.width,
            "height": film.height,
            "spp": film.spp,
            "seed": prepared.seed,
            "fireflies": result.fireflies,
        }))?;
        output::write_file(&path, json.as_bytes())?;
        if let Some(f) = result.fireflies.first() {
            // The command that replays it: the scene and the overrides this render was given.
            let mut replay = String::from("rtis replay");
            if let Some(scene) = &a.scene {
                replay += &format!(" {}", scene.display());
            }
            let o = a.film;
            for (flag, v) in [("width", o.width), ("height", o.height), ("spp", o.spp)] {
                if let Some(v) = v {
                    replay += &format!(" --{flag} {v}");
                }
            }
            if let Some(seed) = o.seed {
                replay += &format!(" --seed {seed}");
            }
            eprintln!(
                "{} fireflies -> {}; the largest: pixel {},{} sample {}, luminance {} (replay \
                 it with {replay} --pixel {},{} --sample {})",
                result.fireflies.len(),
                path.display(),
                f.pixel[0],
                f.pixel[1],
                f.sample,
                f.luminance,
                f.pixel[0],
                f.pixel[1],
                f.sample
            );
        }
    }
    let run = Summary::one_go(prepared, result.seconds, result.stats);
    summary(prepared, pool, &run, out, a.stats.as_deref(), est)
}

/// Write the statistics file (if asked) and print the summary line.
fn summary(
    prepared: &rtis::RenderScene,
    pool: &rayon::ThreadPool,
    run: &Summary,
    out: &Path,
    stats_path: Option<&Path>,
    est: &estimate::Estimate,
) -> Result<(), CliError> {
    let mrays_per_second = run.stats.total() as f64 / run.seconds.max(1e-9) / 1e6;
    if let Some(path) = stats_path {
        let json = serde_json::to_string_pretty(&serde_json::json!({
            "seconds": run.seconds,
            "threads": pool.current_num_threads(),
            "spp": run.spp,
            "rounds": run.rounds,
            "rays": run.stats,
            "effects": prepared.effects,
            "total_rays": run.stats.total(),
            "estimated_rays": est.rays(),
            "mrays_per_second": mrays_per_second,
        }))?;
        output::write_file(path, json.as_bytes())
            .map_err(|e| format!("cannot write stats: {e}"))?;
    }
    let s = &run.stats;
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
        run.spp,
        run.seconds,
        pool.current_num_threads(),
        s.total(),
        s.camera,
        s.shadow,
        s.reflection,
        s.refraction,
        s.indirect,
        s.dropped,
        mrays_per_second,
        out.display()
    );
    Ok(())
}
