//! The `rtis` command line.

mod cli;

use clap::Parser;
use std::process::ExitCode;

/// The system allocator, with huge pages for large blocks (`cli/allocator.rs`).
#[global_allocator]
static ALLOCATOR: cli::allocator::HugePages = cli::allocator::HugePages;

fn main() -> ExitCode {
    // Like every Unix filter: a closed pipe (`rtis bench | head`) ends the process quietly
    // instead of making each print fail.
    // SAFETY: restores the default action of one signal before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let args = cli::Cli::parse();
    if let Err(e) = cli::interrupt::install() {
        eprintln!("error: cannot handle Ctrl-C: {e}");
        return ExitCode::FAILURE;
    }
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        // The partial image and the message are out already.
        Err(e) if e.is::<cli::Interrupted>() => ExitCode::from(130),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
