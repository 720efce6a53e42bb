//! Run long library calls with the GIL released and stop them on KeyboardInterrupt.
//!
//! The work runs on a scoped worker thread; the calling thread waits on a condition
//! variable in slices of 20 ms with the GIL released, and between slices takes the GIL
//! to run `Python::check_signals` (which executes Python's SIGINT handler). When that
//! raises, the `CancelToken` the work polls is set, the worker is joined (it stops
//! within one polling interval, ~10 ms of work) and the exception propagates. The
//! library itself installs no signal handler (it also runs inside Dask workers, where
//! `check_signals` is a no-op off the main thread).

use crate::error::err;
use pyo3::prelude::*;
use sdins_sim::cancel::CancelToken;
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// Run `work(token)` with the GIL released; see the module comment.
pub fn run<T: Send>(py: Python<'_>, work: impl FnOnce(&CancelToken) -> T + Send) -> PyResult<T> {
    let token = CancelToken::new();
    let done = (Mutex::new(false), Condvar::new());
    std::thread::scope(|s| {
        let tok = token.clone();
        let done_ref = &done;
        let handle = s.spawn(move || {
            let out = work(&tok);
            if let Ok(mut g) = done_ref.0.lock() {
                *g = true;
            }
            done_ref.1.notify_all();
            out
        });
        let mut interrupt: Option<PyErr> = None;
        loop {
            let finished = py.detach(|| match done.0.lock() {
                Ok(g) => match done
                    .1
                    .wait_timeout_while(g, Duration::from_millis(20), |d| !*d)
                {
                    Ok((g, _)) => *g,
                    Err(_) => true,
                },
                Err(_) => true,
            });
            if finished || handle.is_finished() {
                break;
            }
            if interrupt.is_none() {
                if let Err(e) = py.check_signals() {
                    token.cancel();
                    interrupt = Some(e);
                }
            }
        }
        let out = py.detach(|| handle.join());
        if let Some(e) = interrupt {
            return Err(e);
        }
        out.map_err(|_| err("internal error: the worker thread panicked"))
    })
}
