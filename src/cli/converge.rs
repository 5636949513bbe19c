//! `rtis converge`: error against time for a ladder of shader settings.

use super::interrupt::{self, Graceful};
use super::{CliError, load};
use clap::Args;
use rtis::converge::{self, plot, report};
use rtis::render::pass::Pass;
use rtis::render::{self, output};
use std::path::PathBuf;
use std::sync::atomic::Ordering;

/// Arguments of `rtis converge`.
#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// The scene file (RON, or a Mitsuba `.xml`); the embedded Cornell box without one.
    scene: Option<PathBuf>,
    /// A reference image (linear EXR of the same size) instead of rendering one.
    #[arg(long, conflicts_with = "reference_spp")]
    reference: Option<PathBuf>,
    /// Samples per pixel of the rendered reference (Path, unbounded depth, the scene's model;
    /// at least 2: its two halves measure its noise).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(2..=1048576))]
    reference_spp: u32,
    /// Output folder for converge.csv, converge.md, converge.png, report.html and the reference.
    #[arg(long, default_value = "converge")]
    out: PathBuf,
    /// Width of every render (default 180; the height keeps the scene's aspect ratio).
    #[arg(long, default_value_t = 180, allow_negative_numbers = true, value_parser = super::render::side())]
    width: u32,
    /// Height (default: from the width and the scene's aspect ratio).
    #[arg(long, allow_negative_numbers = true, value_parser = super::render::side())]
    height: Option<u32>,
    /// Independent seeds per rung, at least 1 (2 or more for bias and variance).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    seeds: u32,
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
    std::fs::create_dir_all(&a.out)
        .map_err(|e| format!("{}: cannot create output folder: {e}", a.out.display()))?;
    let prepared = rtis::extract(&scene);

    let (reference, reference_noise, mut note) = match &a.reference {
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
            let note = format!("{} (given; its noise is unknown)", path.display());
            (img, 0.0, note)
        }
        None => {
            let spp = a.reference_spp;
            let key = converge::reference_key(&prepared, spp);
            let halves = [0, 1].map(|h| a.out.join(format!("reference-{key:016x}.half{h}.exr")));
            let cached = halves
                .iter()
                .map(|p| Pass::read(p))
                .collect::<Result<Vec<_>, _>>();
            let parts = match cached {
                Ok(parts) => {
                    eprintln!("reference: reusing {}", halves[0].display());
                    parts
                }
                Err(_) => {
                    eprintln!(
                        "reference: Path, {:?} model, {spp} spp at {}x{}, in two halves...",
                        prepared.model, prepared.film.width, prepared.film.height
                    );
                    let mut parts = Vec::new();
                    for (h, n) in [spp / 2, spp - spp / 2].into_iter().enumerate() {
                        let s = converge::reference_half(&prepared, n, h as u64);
                        let stop = std::sync::atomic::AtomicBool::new(false);
                        let sums = render::render_pass(&s, 0..n, &|| {}, &stop);
                        let p = Pass::from_render(&s, 0..n, sums.pixels);
                        p.write(&halves[h])?;
                        parts.push(p);
                    }
                    parts
                }
            };
            // Two independent renders of the whole pixel footprint (a range of sample indices
            // would cover only part of it under stratification): var(a - b) = s^2 (1/na +
            // 1/nb), and the reference, their exact pooled mean, has noise variance s^2 / spp.
            let (ha, hb) = (parts[0].image(), parts[1].image());
            let noise =
                converge::metrics::pooled_noise(&ha, parts[0].samples(), &hb, parts[1].samples());
            let mut pooled = parts[0].sums.clone();
            for (a, b) in pooled.iter_mut().zip(&parts[1].sums) {
                *a += *b;
            }
            let reference = rtis::render::film::Image {
                width: ha.width,
                height: ha.height,
                pixels: pooled.iter().map(|p| p.mean(spp as u64)).collect(),
            };
            let note = format!(
                "Path, unbounded depth, {:?} model, {spp} spp; its own noise (from its two \
                 independent halves) RMSE {:.5}",
                prepared.model,
                noise.sqrt()
            );
            (reference, noise, note)
        }
    };
    output::save(&reference, &a.out.join("reference.exr"), Default::default())?;

    let rungs = converge::ladder(&prepared);
    eprintln!(
        "{:<16} {:<10} {:>9} {:>10} {:>9} {:>9}",
        "family", "setting", "seconds", "Mrays", "RMSE", "FLIP"
    );
    // Ctrl-C while the rungs run finishes the rung in flight and writes what is done.
    let graceful = Graceful::begin("finishing the rung in flight, then writing the rungs done");
    let measured = converge::sweep(
        &prepared,
        &reference,
        reference_noise,
        &rungs,
        a.runs as usize,
        a.seeds,
        &mut |r| {
            eprintln!(
                "{:<16} {:<10} {:>9.3} {:>10.1} {:>9.5} {:>9.4}",
                r.family,
                r.label,
                r.seconds,
                r.rays as f64 / 1e6,
                r.rmse,
                r.flip
            );
            !interrupt::STOP.load(Ordering::SeqCst)
        },
    );
    drop(graceful);
    let rows: Vec<converge::Row> = measured.iter().map(|m| m.row.clone()).collect();
    if interrupt::STOP.load(Ordering::SeqCst) {
        // Interrupted: the table and plot of the rungs done, then exit 130 as a quit would.
        output::write_file(
            &a.out.join("converge.csv"),
            converge::to_csv(&rows).as_bytes(),
        )?;
        output::write_file(
            &a.out.join("converge.md"),
            converge::to_markdown(&rows, prepared.model).as_bytes(),
        )?;
        if !rows.is_empty() {
            plot::plot(&rows, "interrupted", &a.out.join("converge.png"))?;
        }
        // A report of an earlier run would not match these rungs.
        let _ = std::fs::remove_file(a.out.join("report.html"));
        eprintln!(
            "interrupted: wrote the {} of {} rungs done to {}/converge.csv, converge.md{} and \
             reference.exr",
            rows.len(),
            rungs.len(),
            a.out.display(),
            if rows.is_empty() {
                ""
            } else {
                ", converge.png"
            }
        );
        std::process::exit(130);
    }
    // Say so when the reference's noise is not small against the errors measured.
    let smallest = rows.iter().map(|r| r.rmse).fold(f64::MAX, f64::min);
    if reference_noise.sqrt() > 0.3 * smallest {
        let warning = format!(
            "the reference's own noise (RMSE {:.5}) is not small against the smallest error \
             measured ({smallest:.5}): the smallest errors are overestimated; raise \
             --reference-spp",
            reference_noise.sqrt()
        );
        eprintln!("warning: {warning}");
        note = format!("{note}. <strong class=\"note\">Warning: {warning}.</strong>");
    }
    // The table and plot first: a Ctrl-C during the effects' prices keeps them.
    let write = |name: &str, text: String| output::write_file(&a.out.join(name), text.as_bytes());
    write("converge.csv", converge::to_csv(&rows))?;
    write("converge.md", converge::to_markdown(&rows, prepared.model))?;
    let name = a.scene.as_deref().and_then(|p| p.file_name()).map_or_else(
        || "cornell.ron".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    let title = format!(
        "{name}: error vs time, {}x{}, {:?} model",
        prepared.film.width, prepared.film.height, prepared.model
    );
    plot::plot(&rows, &title, &a.out.join("converge.png"))?;
    eprintln!("the price of each effect of the scene's own shader...");
    let effects = converge::effect_prices(&prepared, &reference, a.runs as usize);
    let html = report::html(&report::Report {
        title,
        reference: &reference,
        reference_note: note,
        rungs: &measured,
        effects: &effects,
        transfer: prepared.film.transfer,
    });
    write("report.html", html)?;
    eprintln!(
        "wrote {}/converge.csv, converge.md, converge.png, report.html, reference.exr",
        a.out.display()
    );
    Ok(())
}
