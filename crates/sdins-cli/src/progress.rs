//! Progress bars (indicatif) on stderr: hidden when stderr is not a terminal or with
//! `--quiet`; and the process's signal handling. SIGINT and SIGTERM set the library's
//! [`CancelToken`], which every long library call polls, so a command stops within about a
//! second, removes its staged files and exits 130 (SIGINT) or 143 (SIGTERM). A second
//! signal exits at once.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sdins_sim::cancel::CancelToken;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

static TOKEN: OnceLock<CancelToken> = OnceLock::new();
static TERMINATED: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// Install the SIGINT/SIGTERM handlers (once). Registration failures leave the default
/// handlers in place (the process then dies on the signal, as any Unix tool).
pub fn install_signal_handlers() {
    let token = TOKEN.get_or_init(CancelToken::new).clone();
    let term = TERMINATED
        .get_or_init(|| Arc::new(AtomicBool::new(false)))
        .clone();
    use signal_hook::consts::{SIGINT, SIGTERM};
    for (sig, code) in [(SIGINT, 130), (SIGTERM, 143)] {
        // order matters: the conditional shutdown sees the flag of an earlier signal
        let _ = signal_hook::flag::register_conditional_shutdown(sig, code, token.flag());
        let _ = signal_hook::flag::register(sig, token.flag());
    }
    let _ = signal_hook::flag::register(SIGTERM, term);
}

/// The process's cancellation token (set by SIGINT/SIGTERM).
pub fn token() -> CancelToken {
    TOKEN.get_or_init(CancelToken::new).clone()
}

/// Whether a signal asked us to stop.
pub fn interrupted() -> bool {
    TOKEN.get().is_some_and(CancelToken::is_cancelled)
}

/// Exit code for a cancelled command: 143 after SIGTERM, else 130.
pub fn cancel_exit_code() -> u8 {
    if TERMINATED.get().is_some_and(|t| t.load(Ordering::Relaxed)) {
        143
    } else {
        130
    }
}

/// A progress bar that may be hidden.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// New bar for `total` steps.
    pub fn new(total: u64, what: &str, quiet: bool) -> Self {
        let bar = ProgressBar::new(total);
        if quiet || !std::io::stderr().is_terminal() {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        if let Ok(style) = ProgressStyle::with_template(
            "{msg:>10} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(what.to_string());
        Self { bar }
    }
    /// Set the position.
    pub fn set(&mut self, pos: u64) {
        self.bar.set_position(pos);
    }
    /// Finish and clear.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
