//! Checked standard output: every line the commands print goes through [`outln!`] /
//! [`out!`], which write to the locked stdout and check the result.
//!
//! SIGPIPE stays ignored (Rust's default), so a closed pipe is an `EPIPE` error here, not a
//! death by signal that would leave the staging folder behind. A failed write leaves the
//! command at once by unwinding with a typed [`StdoutFailed`] payload (so that the 84 print
//! sites need no `?`); `main` catches it, removes the staging folders (the output folder
//! keeps its previous contents) and exits:
//!
//! * closed pipe (`sdins run --json | head -c1`): silently, with 141 (128 + SIGPIPE), as a
//!   shell reports a process killed by SIGPIPE;
//! * any other failure (`ENOSPC` on `/dev/full`, `EIO`): a one-line message, exit 1.

use std::io::Write;

/// The unwinding payload of a failed stdout write.
#[derive(Debug)]
pub struct StdoutFailed(pub std::io::Error);

/// Write `args` to stdout; on failure unwind with [`StdoutFailed`].
pub fn write_fmt(args: std::fmt::Arguments<'_>) {
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.flush()) {
        std::panic::resume_unwind(Box::new(StdoutFailed(e)));
    }
}

/// `println!` through the checked writer.
macro_rules! outln {
    () => {
        $crate::stdout::write_fmt(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::stdout::write_fmt(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` through the checked writer.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdout::write_fmt(format_args!($($arg)*))
    };
}

/// Exit code of a closed stdout: 128 + SIGPIPE, what a shell shows for a process killed by
/// the signal, printed nowhere.
pub const EXIT_CLOSED_PIPE: u8 = 141;

/// What `main` does with an unwinding payload: `Some(exit code)` for a failed stdout write
/// (message printed for everything but a closed pipe), `None` for a real panic.
pub fn exit_code_of(payload: &(dyn std::any::Any + Send)) -> Option<u8> {
    let StdoutFailed(e) = payload.downcast_ref::<StdoutFailed>()?;
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        Some(EXIT_CLOSED_PIPE)
    } else {
        eprintln!("sdins: error: writing to standard output: {e}");
        Some(1)
    }
}
