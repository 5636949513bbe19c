//! `rtis merge PARTS... -o OUT`: passes rendered anywhere, merged into the image.

use super::CliError;
use clap::Args;
use rtis::render::output;
use rtis::render::pass::{Pass, describe_missing};
use std::path::PathBuf;

/// Arguments of `rtis merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Pass files written by `rtis render --pass I/N`.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The image (.png or .exr), or with --partial a pass file (.exr) for further merging.
    #[arg(short, long)]
    output: PathBuf,
    /// Allow missing samples and write a pass file of what the parts hold (merging as passes
    /// arrive).
    #[arg(long)]
    partial: bool,
}

/// Run `rtis merge`: check that the parts belong together and cover every sample once, then
/// write the image, bit-identical to a single render of the scene.
pub fn run(a: MergeArgs) -> Result<(), CliError> {
    if a.partial
        && !a
            .output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        return Err(format!(
            "{}: --partial writes a pass, an .exr file",
            a.output.display()
        )
        .into());
    }
    output::check_writable(&a.output)?;
    let parts = a
        .parts
        .iter()
        .map(|p| Ok((p.display().to_string(), Pass::read(p)?)))
        .collect::<Result<Vec<_>, String>>()?;
    let merged = Pass::merge(parts)?;
    if a.partial {
        merged.write(&a.output)?;
    } else {
        if !merged.is_complete() {
            return Err(format!(
                "samples {} of {} spp are in no part: render them with rtis render --pass, or \
                 merge with --partial",
                describe_missing(&merged),
                merged.spp
            )
            .into());
        }
        output::save(&merged.image(), &a.output, merged.transfer)?;
    }
    eprintln!(
        "merged {} parts: samples {} of {} spp, {}x{} -> {}",
        a.parts.len(),
        merged
            .ranges
            .iter()
            .map(|r| format!("{}..{}", r.start, r.end))
            .collect::<Vec<_>>()
            .join(","),
        merged.spp,
        merged.width,
        merged.height,
        a.output.display()
    );
    Ok(())
}
