//! Finds BehaviorTree.CPP 4.10 (an install prefix: `BTC_BTCPP`, or the
//! cache `integrations/btcpp/build-btcpp.sh` fills,
//! `${XDG_CACHE_HOME:-$HOME/.cache}/btc/btcpp-<sha256>`) and builds the
//! peer program (`runtime/peer/peer.cpp`) against it, once per change of
//! its source. Shared by the script fuzzing test and the engine benchmark.

use std::path::{Path, PathBuf};
use std::process::Command;

fn prefix() -> Result<PathBuf, String> {
    let ok = |p: &Path| p.join("include/behaviortree_cpp/bt_factory.h").is_file();
    if let Some(p) = std::env::var_os("BTC_BTCPP").map(PathBuf::from) {
        return if ok(&p) {
            Ok(p)
        } else {
            Err(format!("BTC_BTCPP={} is no BT.CPP install", p.display()))
        };
    }
    let cache = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .ok_or("neither XDG_CACHE_HOME nor HOME is set")?
        .join("btc");
    let found = std::fs::read_dir(&cache)
        .map_err(|e| format!("{}: {e}", cache.display()))?
        .filter_map(|d| d.ok().map(|d| d.path()))
        .find(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("btcpp-"))
                && ok(p)
        });
    found.ok_or_else(|| format!("no BT.CPP build in {}", cache.display()))
}

/// The peer program, built if needed.
pub fn peer() -> Result<PathBuf, String> {
    let prefix = prefix()?;
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let source = here.join("peer/peer.cpp");
    let out_dir = here.join("../target/btcpp-peer");
    let exe = out_dir.join("peer");
    let fresh = |exe: &Path| -> Option<bool> {
        let built = exe.metadata().ok()?.modified().ok()?;
        Some(built >= source.metadata().ok()?.modified().ok()?)
    };
    if fresh(&exe) == Some(true) {
        return Ok(exe);
    }
    std::fs::create_dir_all(&out_dir).map_err(|e| e.to_string())?;
    let lib = prefix.join("lib");
    let out = Command::new("g++")
        .args(["-O2", "-std=c++17", "-I"])
        .arg(prefix.join("include"))
        .arg(&source)
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(["-lbehaviortree_cpp", "-o"])
        .arg(&exe)
        .output()
        .map_err(|e| format!("g++ does not run: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "g++ failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(exe)
}
