//! `rtis bench`: speed figures, printed, never asserted.

use super::CliError;
use clap::Args;
use rtis::RenderScene;
use rtis::converge::{reference_shader, with_settings};
use rtis::render::render;
use rtis::scene::load_default;
use rtis::shader::{Global, Shader};

/// Arguments of `rtis bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Renders per case; the median is printed.
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Divide the film size by this (for a quick look; 1 is the course's 720x576).
    #[arg(long, default_value_t = 1)]
    shrink: u32,
}

/// Peak resident set size of this process in MiB (Linux; 0 elsewhere).
pub fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

fn case(name: &str, scene: &RenderScene, runs: usize) {
    let mut results: Vec<_> = (0..runs.max(1)).map(|_| render(scene, &|| {})).collect();
    results.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
    let r = &results[results.len() / 2];
    println!(
        "{name:<34} {:>4}x{:<4} {:>5} spp {:>9.3} s {:>8.1} Mrays {:>7.1} Mrays/s {:>8.1} MiB peak",
        scene.film.width,
        scene.film.height,
        scene.film.spp,
        r.seconds,
        r.stats.total() as f64 / 1e6,
        r.mrays_per_second(),
        peak_rss_mib()
    );
}

/// Run `rtis bench`.
pub fn run(a: BenchArgs) -> Result<(), CliError> {
    if a.shrink == 0 {
        return Err("--shrink must be at least 1".into());
    }
    let threads = rayon::current_num_threads();
    println!(
        "rtis bench: {} cores available, {threads} threads, median of {} runs",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        a.runs
    );
    let mut scene = load_default();
    scene.settings.film.width /= a.shrink;
    scene.settings.film.height /= a.shrink;
    let base = RenderScene::prepare(&scene);
    let global = |samples, max_depth| {
        Shader::Global(Global {
            samples,
            max_depth,
            ambient: glam::Vec3A::splat(0.3),
            max_specular: 32,
        })
    };
    println!("-- the course's Cornell box");
    case(
        "Direct",
        &with_settings(&base, Shader::Direct { max_specular: 32 }, 1),
        a.runs,
    );
    case(
        "Global n=64 D=3",
        &with_settings(&base, global(64, 3), 1),
        a.runs,
    );
    case(
        "Path (Course model) 64 spp",
        &with_settings(&base, reference_shader(), 64),
        a.runs,
    );
    let mut physical = with_settings(&base, reference_shader(), 64);
    physical.model = rtis::scene::Model::Physical;
    case("Path (Physical model) 64 spp", &physical, a.runs);
    println!("-- cost against resolution and samples (Global n=16 D=2; should grow linearly)");
    for (div, spp) in [(2, 1), (1, 1), (2, 4), (1, 4)] {
        let mut s = with_settings(&base, global(16, 2), spp);
        s.film.width /= div;
        s.film.height /= div;
        case("Global n=16 D=2", &s, a.runs);
    }
    Ok(())
}
