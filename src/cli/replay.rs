//! `rtis replay`: trace one camera sample again, as the render traced it, and print its path.

use super::CliError;
use super::render::{Overrides, load_overridden};
use clap::Args;
use rtis::render::inspect::{self, luminance};
use rtis::shader::record::{Event, ray_name};
use std::path::PathBuf;

/// Arguments of `rtis replay`.
#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// The scene file (RON, or a Mitsuba 3 scene `.xml`, converted). Without one, the embedded
    /// Cornell box of the course.
    scene: Option<PathBuf>,
    /// The pixel: column and row from the top left, as X,Y.
    #[arg(long, value_parser = parse_pixel, value_name = "X,Y", allow_hyphen_values = true)]
    pixel: (u32, u32),
    /// The sample's index in the pixel (0 to spp - 1).
    #[arg(long, value_name = "I")]
    sample: u32,
    /// The render's overrides of the scene's film and seed, if it had any (a sample depends on
    /// them): give the ones given to `rtis render`.
    #[command(flatten)]
    film: Overrides,
    /// Print the sample as JSON (the form of `render --fireflies`).
    #[arg(long)]
    json: bool,
}

/// Parse `X,Y`.
fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("--pixel {s}: write the column and row as X,Y, for example 12,40");
    let (x, y) = s.split_once(',').ok_or_else(bad)?;
    Ok((
        x.trim().parse().map_err(|_| bad())?,
        y.trim().parse().map_err(|_| bad())?,
    ))
}

/// Three numbers as `(x, y, z)`, each in the shortest form that reads back to its bits.
fn v3(v: [f32; 3]) -> String {
    format!("({:?}, {:?}, {:?})", v[0], v[1], v[2])
}

/// Run `rtis replay`.
pub fn run(a: ReplayArgs) -> Result<(), CliError> {
    let scene = load_overridden(a.scene.as_deref(), a.film, None)?;
    let film = scene.settings.film;
    let (x, y) = a.pixel;
    if x >= film.width || y >= film.height {
        return Err(format!(
            "--pixel {x},{y} is outside the {}x{} film (columns 0 to {}, rows 0 to {})",
            film.width,
            film.height,
            film.width - 1,
            film.height - 1
        )
        .into());
    }
    if a.sample >= film.spp {
        return Err(format!(
            "--sample {} is out of range: the render has {} samples per pixel (0 to {})",
            a.sample,
            film.spp,
            film.spp - 1
        )
        .into());
    }
    let prepared = rtis::extract(&scene);
    let r = inspect::replay(&prepared, x, y, a.sample);
    let l = r.sum.mean(1);
    if a.json {
        let json = serde_json::json!({
            "pixel": [x, y],
            "sample": a.sample,
            "spp": film.spp,
            "seed": prepared.seed,
            "radiance": l.to_array(),
            "luminance": luminance(l),
            "failed": r.failed,
            "rays": r.stats,
            "path": r.events,
        });
        println!("{}", serde_json::to_string_pretty(&json)?);
        return Ok(());
    }
    println!(
        "pixel {x},{y} sample {} of {} spp, seed {}",
        a.sample, film.spp, prepared.seed
    );
    let mut vertex = 0;
    for e in &r.events {
        match e {
            Event::Hit {
                p,
                n,
                material,
                kind,
                beta,
            } => {
                vertex += 1;
                println!(
                    "vertex {vertex}: p {} n {} material {material} ({kind}) beta {}",
                    v3(*p),
                    v3(*n),
                    v3(*beta)
                );
            }
            Event::Add { technique, l } => {
                println!("  + {} by {}", v3(*l), technique.name());
            }
            Event::Scatter {
                wi,
                pdf,
                weight,
                ray,
            } => match pdf {
                Some(pdf) => println!(
                    "  {} ray wi {} pdf {pdf:?} weight {}",
                    ray_name(*ray),
                    v3(*wi),
                    v3(*weight)
                ),
                None => println!(
                    "  {} ray wi {} (specular) weight {}",
                    ray_name(*ray),
                    v3(*wi),
                    v3(*weight)
                ),
            },
            Event::Roulette { q, survived } => println!(
                "  Russian roulette q {q:?}: {}",
                if *survived { "survived" } else { "ended" }
            ),
            Event::Escape { d } => println!("escaped in direction {}", v3(*d)),
        }
    }
    if r.failed {
        println!("a contribution was NaN, infinite or negative: the render dropped this sample");
    }
    println!(
        "radiance {} (the exact sum of the contributions, as the render added it), {} rays",
        v3(l.to_array()),
        r.stats.total()
    );
    Ok(())
}
