//! Cooperative cancellation for long library calls.
//!
//! Every long computation in this crate (truth generation, navigation runs, Monte Carlo,
//! alignment windows, filters) takes a [`CancelToken`] and polls it at least about once per
//! second of work, returning [`Cancelled`] when it is set. The library never installs a
//! signal handler: the CLI's SIGINT/SIGTERM handlers set the token, the Python layer sets it
//! on `KeyboardInterrupt`, a Dask worker may set it from another thread.
//!
//! ```
//! use sdins_sim::cancel::CancelToken;
//! let token = CancelToken::new();
//! let worker = token.clone();
//! assert!(worker.check().is_ok());
//! token.cancel();
//! assert!(worker.check().is_err());
//! ```

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The computation was stopped through its [`CancelToken`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

/// A shared flag: clones see the same state. Cheap to poll (one relaxed atomic load).
#[derive(Clone, Debug, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    /// A token that is not set.
    pub fn new() -> Self {
        Self::default()
    }
    /// A token over an existing flag (for example one a signal handler sets).
    pub fn from_flag(flag: Arc<AtomicBool>) -> Self {
        Self(flag)
    }
    /// The shared flag (to register with a signal handler).
    pub fn flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.0)
    }
    /// Request cancellation (idempotent; visible to every clone).
    pub fn cancel(&self) {
        self.0.store(true, Ordering::SeqCst);
    }
    /// Whether cancellation was requested.
    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
    /// `Err(Cancelled)` once cancellation was requested.
    #[inline]
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

/// How many samples a streaming loop may process between polls: ~10 ms of work at the
/// slowest per-sample cost in this crate, so a set token is seen well within a second.
pub const POLL_EVERY_SAMPLES: u64 = 1 << 14;

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_flag_across_threads() {
        let t = CancelToken::new();
        let c = t.clone();
        assert!(!c.is_cancelled());
        std::thread::spawn(move || t.cancel()).join().unwrap();
        assert_eq!(c.check(), Err(Cancelled));
    }
}
