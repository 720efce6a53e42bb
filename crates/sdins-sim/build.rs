//! `cfg(shared_data)` when the external validation data (`../shared/data` beside the
//! project, or `$SDINS_SHARED_DATA`) is present: the tests that read it are `#[ignore]`d
//! otherwise, so `cargo test` shows them as ignored instead of passing without running.
fn main() {
    println!("cargo::rustc-check-cfg=cfg(shared_data)");
    println!("cargo::rerun-if-env-changed=SDINS_SHARED_DATA");
    let dir = std::env::var_os("SDINS_SHARED_DATA")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            let manifest = std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default();
            std::path::Path::new(&manifest).join("../../../shared/data")
        });
    println!("cargo::rerun-if-changed={}", dir.display());
    if dir.is_dir() {
        println!("cargo::rustc-cfg=shared_data");
    }
}
