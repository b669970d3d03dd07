//! Link the `btc` binary as a position-dependent executable on Linux: a
//! PIE of this size spends a third of `btc --version` in the dynamic
//! loader applying ~10,000 relative relocations before `main`.

fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    let env = std::env::var("CARGO_CFG_TARGET_ENV").unwrap_or_default();
    if os == "linux" && env == "gnu" {
        println!("cargo:rustc-link-arg-bin=btc=-no-pie");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
