//! `rtis converge`: error against time for a ladder of shader settings.

use super::{CliError, load};
use clap::Args;
use rtis::converge::{self, plot};
use rtis::render::{self, output};
use std::path::PathBuf;

/// Arguments of `rtis converge`.
#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// The scene file (RON); the embedded Cornell box without one.
    scene: Option<PathBuf>,
    /// A reference image (linear EXR of the same size) instead of rendering one.
    #[arg(long, conflicts_with = "reference_spp")]
    reference: Option<PathBuf>,
    /// Samples per pixel of the rendered reference (Path, unbounded depth, the scene's model).
    #[arg(long, default_value_t = 1024)]
    reference_spp: u32,
    /// Output folder for converge.csv, converge.md, converge.png and the reference.
    #[arg(long, default_value = "converge")]
    out: PathBuf,
    /// Width of every render (default 180; the height keeps the scene's aspect ratio).
    #[arg(long, default_value_t = 180, allow_negative_numbers = true, value_parser = super::render::side())]
    width: u32,
    /// Height (default: from the width and the scene's aspect ratio).
    #[arg(long, allow_negative_numbers = true, value_parser = super::render::side())]
    height: Option<u32>,
    /// Renders per rung, at least 1; the median time is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    runs: u32,
}

/// Run `rtis converge`.
pub fn run(a: ConvergeArgs) -> Result<(), CliError> {
    let mut scene = load(a.scene.as_deref())?;
    let film = &mut scene.settings.film;
    let height = a.height.unwrap_or_else(|| {
        ((a.width as f64 * film.height as f64 / film.width as f64).round() as u32).max(1)
    });
    film.width = a.width;
    film.height = height;
    *film = film.checked()?;
    if a.reference_spp == 0 {
        return Err("--reference-spp must be at least 1".into());
    }
    std::fs::create_dir_all(&a.out)
        .map_err(|e| format!("{}: cannot create output folder: {e}", a.out.display()))?;
    let prepared = rtis::extract(&scene);

    let reference = match &a.reference {
        Some(path) => {
            let img = output::load(path)?;
            if (img.width, img.height) != (prepared.film.width, prepared.film.height) {
                return Err(format!(
                    "{}: reference is {}x{}, the renders are {}x{} (use --width/--height)",
                    path.display(),
                    img.width,
                    img.height,
                    prepared.film.width,
                    prepared.film.height
                )
                .into());
            }
            img
        }
        None => {
            let key = converge::reference_key(&prepared, a.reference_spp);
            let cached = a.out.join(format!("reference-{key:016x}.exr"));
            match output::load(&cached) {
                Ok(img) => {
                    eprintln!("reference: reusing {}", cached.display());
                    img
                }
                Err(_) => {
                    eprintln!(
                        "reference: Path, {:?} model, {} spp at {}x{}...",
                        prepared.model, a.reference_spp, prepared.film.width, prepared.film.height
                    );
                    let s = converge::reference_scene(&prepared, a.reference_spp);
                    let r = render::render(&s, &|| {});
                    eprintln!(
                        "reference: {:.1} s, {:.1} Mrays/s",
                        r.seconds,
                        r.mrays_per_second()
                    );
                    output::save(&r.image, &cached, Default::default())?;
                    r.image
                }
            }
        }
    };
    output::save(&reference, &a.out.join("reference.exr"), Default::default())?;

    let rungs = converge::ladder(&prepared);
    eprintln!(
        "{:<16} {:<10} {:>9} {:>10} {:>9}",
        "family", "setting", "seconds", "Mrays", "RMSE"
    );
    let rows = converge::sweep(&prepared, &reference, &rungs, a.runs as usize, &mut |r| {
        eprintln!(
            "{:<16} {:<10} {:>9.3} {:>10.1} {:>9.5}",
            r.family,
            r.label,
            r.seconds,
            r.rays as f64 / 1e6,
            r.rmse
        )
    });
    let write = |name: &str, text: String| output::write_file(&a.out.join(name), text.as_bytes());
    write("converge.csv", converge::to_csv(&rows))?;
    write("converge.md", converge::to_markdown(&rows, prepared.model))?;
    let name = a.scene.as_deref().and_then(|p| p.file_name()).map_or_else(
        || "cornell.ron".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    plot::plot(
        &rows,
        &format!(
            "{name}: error vs time, {}x{}, {:?} model",
            prepared.film.width, prepared.film.height, prepared.model
        ),
        &a.out.join("converge.png"),
    )?;
    eprintln!(
        "wrote {}/converge.csv, converge.md, converge.png, reference.exr",
        a.out.display()
    );
    Ok(())
}
