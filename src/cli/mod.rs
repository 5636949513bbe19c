//! Subcommands of the `rtis` binary.

pub mod allocator;
mod bench;
mod check;
mod converge;
mod diff;
mod import;
pub mod interrupt;
mod merge;
mod render;
mod replay;
mod warptest;
mod watch;

use clap::{Parser, Subcommand};
use rtis::scene::{self, Scene, SceneError};
use std::path::{Path, PathBuf};

/// rtis: a global-illumination ray tracer for learning, teaching and testing light transport.
#[derive(Parser, Debug)]
#[command(version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene to a PNG or EXR file.
    Render(render::RenderArgs),
    /// Render a scene live in a local web page, again whenever it or a file it reads changes.
    Watch(watch::WatchArgs),
    /// Validate a scene and print what it contains.
    Check {
        /// The scene file (RON, or a Mitsuba 3 scene `.xml`, converted).
        scene: PathBuf,
    },
    /// Convert a Mitsuba 3 scene (XML) into an rtis scene file.
    Import(import::ImportArgs),
    /// Compare two images (PNG or EXR): RMSE, relMSE, largest error, FLIP, and a FLIP heatmap.
    Diff(diff::DiffArgs),
    /// Merge pass files (`render --pass I/N`) into the image, bit-identical to one render.
    Merge(merge::MergeArgs),
    /// Measure error against time for a ladder of shader settings (CSV, table, plot,
    /// report.html).
    Converge(converge::ConvergeArgs),
    /// Test every sampler against its pdf (chi-squared), with a page of histograms.
    Warptest(warptest::WarptestArgs),
    /// Trace one camera sample again, exactly as the render traced it, and print its path
    /// vertex by vertex (a firefly's, say). Give it the --width, --height, --spp and --seed the
    /// render was given, if any: a sample depends on them.
    Replay(replay::ReplayArgs),
    /// Print speed figures: the course's Cornell box under each shader (seconds, Mrays/s, own
    /// peak memory), the price of each effect, and BVH build and ray rates for meshes.
    Bench(bench::BenchArgs),
}

/// Any error the CLI reports: already formatted for the user.
pub type CliError = Box<dyn std::error::Error>;

/// A render stopped by Ctrl-C after writing its partial image: exit 130, like a shell.
#[derive(Debug, thiserror::Error)]
#[error("interrupted")]
pub struct Interrupted;

/// Run one subcommand.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Render(args) => render::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Watch(args) => watch::run(args),
        Command::Check { scene } => check::run(&scene),
        Command::Import(args) => import::run(args),
        Command::Converge(args) => converge::run(args),
        Command::Diff(args) => diff::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Warptest(args) => warptest::run(args),
        Command::Bench(args) => bench::run(args),
    }
}

/// `isa`, or the error of `--isa` naming it if this CPU does not run it.
pub fn runnable(isa: rtis::accel::Isa) -> Result<rtis::accel::Isa, CliError> {
    match isa.available() {
        true => Ok(isa),
        false => Err(format!("--isa {}: this CPU does not run it", isa.name()).into()),
    }
}

/// Load the scene at `path`, or the embedded Cornell box when there is none.
pub fn load(path: Option<&Path>) -> Result<Scene, SceneError> {
    match path {
        Some(p) => rtis::import::load_scene(p),
        None => Ok(scene::load_default()),
    }
}
