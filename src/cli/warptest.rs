//! `rtis warptest`: chi-squared tests of every sampler against its pdf, with a histogram page.

use super::CliError;
use clap::Args;
use rtis::converge::warptest;
use rtis::render::output;
use std::path::PathBuf;

/// Arguments of `rtis warptest`.
#[derive(Args, Debug)]
pub struct WarptestArgs {
    /// Samples drawn per sampler.
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u64).range(1000..=100_000_000))]
    samples: u64,
    /// Seed of the samples.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Write the page of observed and expected histograms here.
    #[arg(short, long, default_value = "warptest.html")]
    output: PathBuf,
}

/// Run `rtis warptest`: one line per sampler, the page, and a non-zero exit if any is rejected.
pub fn run(a: WarptestArgs) -> Result<(), CliError> {
    output::check_folder(&a.output)?;
    let cases = warptest::cases();
    let alpha = warptest::per_test_alpha(cases.len());
    println!(
        "{} samples per sampler; chi-squared at significance {} overall ({alpha:.2e} per test)",
        a.samples,
        warptest::ALPHA
    );
    println!(
        "{:<52} {:>10} {:>5} {:>9}  verdict",
        "sampler", "chi2", "dof", "p-value"
    );
    let mut outcomes = Vec::new();
    for case in &cases {
        let o = warptest::run(case, a.samples, a.seed);
        println!(
            "{:<52} {:>10.1} {:>5} {:>9.4}  {}",
            o.name,
            o.chi2,
            o.dof,
            o.p_value,
            if o.p_value >= alpha {
                "accepted"
            } else {
                "REJECTED"
            }
        );
        outcomes.push(o);
    }
    output::write_file(&a.output, warptest::html(&outcomes, a.samples).as_bytes())?;
    println!("histograms -> {}", a.output.display());
    let rejected = outcomes.iter().filter(|o| o.p_value < alpha).count();
    if rejected > 0 {
        return Err(format!("{rejected} sampler(s) do not follow their pdf").into());
    }
    Ok(())
}
