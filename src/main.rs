//! The `btc` binary: the command line of `lib.rs`, with btc's allocator.

// Compiling large plans allocates many small strings; mimalloc is markedly
// faster at that than the system allocator.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    btc::run(std::env::args_os())
}
