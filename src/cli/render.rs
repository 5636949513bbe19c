//! `rtis render`.

use super::{CliError, load};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rtis::render::output::Transfer;
use rtis::render::{self, Film, output};
use std::path::PathBuf;

/// Arguments of `rtis render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene file (RON). Without one, the embedded Cornell box of the course is rendered.
    scene: Option<PathBuf>,
    /// Output image: .png (8-bit) or .exr (linear float). Default: the scene's name with .png.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Override the film width in pixels.
    #[arg(long)]
    width: Option<u32>,
    /// Override the film height in pixels.
    #[arg(long)]
    height: Option<u32>,
    /// Override the samples per pixel.
    #[arg(long)]
    spp: Option<u32>,
    /// Worker threads (default: one per core). The image does not depend on it.
    #[arg(long)]
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
    let mut scene = load(a.scene.as_deref())?;
    let film = &mut scene.settings.film;
    let overridden = Film {
        width: a.width.unwrap_or(film.width),
        height: a.height.unwrap_or(film.height),
        spp: a.spp.unwrap_or(film.spp),
        transfer: a.transfer.unwrap_or(film.transfer),
    };
    *film = overridden
        .checked()
        .map_err(|e| format!("command-line film override: {e}"))?;
    if let Some(seed) = a.seed {
        scene.settings.seed = seed;
    }
    let out = a.output.clone().unwrap_or_else(|| {
        let stem = a
            .scene
            .as_deref()
            .and_then(|p| p.file_stem())
            .map_or_else(|| "cornell".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from(format!("{stem}.png"))
    });
    // Fail before a long render, not after it.
    output::check_writable(&out)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }

    let prepared = rtis::extract(&scene);
    for w in &prepared.warnings {
        eprintln!("warning: {w}");
    }
    eprintln!("effects {}", prepared.effects);
    let pool = {
        let mut b = rayon::ThreadPoolBuilder::new();
        if let Some(t) = a.threads {
            if t == 0 {
                return Err("--threads must be at least 1".into());
            }
            b = b.num_threads(t);
        }
        b.build()?
    };
    let bar = ProgressBar::new(render::tile_count(&prepared));
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}",
        )
        .expect("valid template"),
    );
    let tick = || bar.inc(1);
    let result = pool.install(|| render::render(&prepared, &tick));
    bar.finish_and_clear();

    output::save(&result.image, &out, prepared.film.transfer)?;
    if let Some(path) = &a.stats {
        let json = serde_json::to_string_pretty(&serde_json::json!({
            "seconds": result.seconds,
            "threads": pool.current_num_threads(),
            "rays": result.stats,
            "effects": prepared.effects,
            "total_rays": result.stats.total(),
            "mrays_per_second": result.mrays_per_second(),
        }))?;
        std::fs::write(path, json)
            .map_err(|e| format!("{}: cannot write stats: {e}", path.display()))?;
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
