//! Peak heap of the forward filter plus smoother on one hour of 200 Hz IMU data with
//! 1 Hz GNSS (covariance at 10 Hz, full-rate smoothed output streamed to the observer):
//! at most 300 MB including the input held in memory. Release:
//! `cargo test --release -p sdins-sim --test fuse_memory -- --ignored --nocapture`.
#![allow(clippy::unwrap_used)]

use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::records::{
    fuse_records, record_from_scenario, RecordEvent, RecordInit, RecordModel, RecordOptions,
};
use sdins_sim::fusion::simulated::InitSigma;
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::gnss::GnssConfig;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(l.size(), Ordering::Relaxed) + l.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        CURRENT.fetch_sub(l.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static A: Counting = Counting;

/// One hour of 200 Hz driving-like motion (turns, accelerations), tactical grade.
pub fn hour_scenario() -> Scenario {
    Scenario::from_toml(
        include_str!("../../../bench/scenarios/drive-1h-200hz.toml"),
        "bench/scenarios/drive-1h-200hz.toml",
    )
    .unwrap()
}

#[test]
#[ignore]
fn one_hour_at_200hz_filter_and_smoother_peak_heap_below_300mb() {
    let scn = hour_scenario();
    let (imu, fixes) = record_from_scenario(&scn, &GnssConfig::default(), 0).unwrap();
    assert_eq!(imu.increments.len(), 720_000);
    let input = CURRENT.load(Ordering::Relaxed);
    PEAK.store(input, Ordering::Relaxed);
    let model = RecordModel::from_error_model(&scn.imu.model);
    let truth0 =
        sdins_sim::truth::TruthGenerator::new(&scn.trajectory, scn.truth_config()).initial_state();
    let init = RecordInit::Given {
        state: truth0,
        sigma: InitSigma::default(),
    };
    let opts = RecordOptions {
        smooth: true,
        ..Default::default()
    };
    let (mut fwd, mut smo) = (0u64, 0u64);
    let t = std::time::Instant::now();
    let s = fuse_records(
        &imu,
        &fixes,
        &model,
        &init,
        &opts,
        &CancelToken::new(),
        |ev| match ev {
            RecordEvent::Forward(_) => fwd += 1,
            RecordEvent::Smoothed(_) => smo += 1,
            _ => {}
        },
    )
    .unwrap();
    let el = t.elapsed().as_secs_f64();
    let peak = PEAK.load(Ordering::Relaxed);
    println!(
        "1 h at 200 Hz: input {:.1} MB, peak heap {:.1} MB (smoother log {:.1} MB, {} epochs), {} forward and {} smoothed points, {} fixes, {el:.2} s",
        input as f64 / 1e6,
        peak as f64 / 1e6,
        s.smoother_bytes as f64 / 1e6,
        s.cov_epochs,
        fwd,
        smo,
        s.fixes_used
    );
    assert_eq!(fwd, 360_001);
    assert_eq!(smo, fwd);
    assert!(peak <= 300_000_000, "peak heap {peak} B");
}
