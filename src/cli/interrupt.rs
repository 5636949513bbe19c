//! Ctrl-C and SIGTERM: stop cleanly, keep what a long render has, leave nothing behind.
//!
//! A thread waits for the signals. SIGTERM, or SIGINT when no render is running, or a second
//! SIGINT, quits at once: temporary output files are removed (a write in progress is waited
//! for, so no file is ever half-written) and the process exits with 128 + the signal number
//! (130 for SIGINT, 143 for SIGTERM), as shells expect. The first SIGINT during a render sets
//! [`STOP`]: the tiles in flight are finished and `render` writes the image so far as a
//! partial image.

use rtis::render::output;
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set by the first Ctrl-C while a render that can stop early is running.
pub static STOP: AtomicBool = AtomicBool::new(false);

/// Whether a render that keeps its partial image is running (the first Ctrl-C then stops it).
static GRACEFUL: AtomicBool = AtomicBool::new(false);

/// What the first Ctrl-C of the running [`Graceful`] section does, said when it comes.
static WHAT: std::sync::Mutex<&str> = std::sync::Mutex::new("");

/// Start the signal thread. Call once, before any output file is written.
pub fn install() -> std::io::Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM])?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for sig in signals.forever() {
                if sig == SIGINT
                    && GRACEFUL.load(Ordering::SeqCst)
                    && !STOP.swap(true, Ordering::SeqCst)
                {
                    let what = *WHAT.lock().unwrap_or_else(|e| e.into_inner());
                    eprintln!("\ninterrupted: {what}; press Ctrl-C again to quit at once");
                    continue;
                }
                quit(sig);
            }
        })?;
    Ok(())
}

/// Remove temporary files and exit with `128 + sig`.
fn quit(sig: i32) -> ! {
    output::remove_pending();
    eprintln!("\ninterrupted: quit, no output written");
    std::process::exit(128 + sig)
}

/// While the guard lives, the first Ctrl-C stops the render instead of quitting.
pub struct Graceful;

impl Graceful {
    /// Enter a stoppable section; the first Ctrl-C will say it is `what` (as "finishing the
    /// tiles in flight, then writing the image so far").
    pub fn begin(what: &'static str) -> Self {
        *WHAT.lock().unwrap_or_else(|e| e.into_inner()) = what;
        GRACEFUL.store(true, Ordering::SeqCst);
        Graceful
    }
}

impl Drop for Graceful {
    fn drop(&mut self) {
        GRACEFUL.store(false, Ordering::SeqCst);
    }
}
