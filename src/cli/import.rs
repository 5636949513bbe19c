//! `rtis import`: a Mitsuba 3 scene (XML) written as an rtis scene file that a person can read
//! and edit, checked by loading it back.

use super::CliError;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `rtis import`.
#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The Mitsuba scene (`.xml`).
    pub scene: PathBuf,
    /// The rtis scene file to write (RON); printed when absent (with file names absolute, or
    /// relative to the current folder when it is the scene's).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Skip what rtis cannot render (plugins, properties), with a warning for each, instead
    /// of stopping at the first.
    #[arg(long)]
    pub lenient: bool,
}

/// Convert, check that the result loads, and write it (whole, or not at all).
pub fn run(args: ImportArgs) -> Result<(), CliError> {
    // The folder the text will be read from: the output's; printed, the current folder (where
    // a redirected copy most likely lands), so that file names are absolute unless it is the
    // scene's own folder.
    let to = match &args.output {
        Some(o) => o.parent().map(PathBuf::from).unwrap_or_default(),
        None => PathBuf::from("."),
    };
    let converted = rtis::import::import_with(&args.scene, &to, args.lenient)?;
    for w in &converted.warnings {
        eprintln!("warning: {w}");
    }
    // What is written must load: the loader's own checks run on it now.
    let name = format!("{} (as imported)", args.scene.display());
    let scene = rtis::scene::load_str(&converted.text, &name, Some(&to))?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    match &args.output {
        Some(path) => {
            rtis::render::output::write_file(path, converted.text.as_bytes())?;
            eprintln!("{} -> {}", args.scene.display(), path.display());
        }
        None => print!("{}", converted.text),
    }
    Ok(())
}
