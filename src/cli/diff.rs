//! `rtis diff A B [-o DIFF.png]`: how two images differ, in numbers and as a heatmap.

use super::CliError;
use clap::Args;
use rtis::converge::metrics;
use rtis::render::output;
use std::path::PathBuf;

/// Arguments of `rtis diff`.
#[derive(Args, Debug)]
pub struct DiffArgs {
    /// The image under test (PNG, read as sRGB, or EXR, linear).
    test: PathBuf,
    /// The reference image, of the same size.
    reference: PathBuf,
    /// Write the FLIP heatmap here (PNG; black where no difference is seen).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Run `rtis diff`: print RMSE, relMSE, the largest error and mean FLIP, and write the map.
pub fn run(a: DiffArgs) -> Result<(), CliError> {
    if let Some(out) = &a.output {
        output::check_writable(out)?;
    }
    let test = output::load(&a.test)?;
    let reference = output::load(&a.reference)?;
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(format!(
            "{} is {}x{} but {} is {}x{}: diff compares images of one size",
            a.test.display(),
            test.width,
            test.height,
            a.reference.display(),
            reference.width,
            reference.height
        )
        .into());
    }
    let flip = metrics::flip(&test, &reference);
    let differing = test
        .pixels
        .iter()
        .zip(&reference.pixels)
        .filter(|(p, r)| p != r)
        .count();
    println!(
        "{} against {} ({}x{}, linear values):",
        a.test.display(),
        a.reference.display(),
        test.width,
        test.height
    );
    println!("  RMSE        {:.6}", metrics::rmse(&test, &reference));
    println!("  relMSE      {:.6}", metrics::rel_mse(&test, &reference));
    println!(
        "  max error   {:.6}",
        metrics::max_abs_error(&test, &reference)
    );
    println!("  mean FLIP   {:.6}", flip.mean);
    println!("  pixels that differ  {differing} of {}", test.pixels.len());
    if let Some(out) = &a.output {
        let mut png = Vec::new();
        flip.heatmap
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
        output::write_file(out, &png)?;
        println!("  FLIP heatmap -> {}", out.display());
    }
    Ok(())
}
