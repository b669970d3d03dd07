//! The `btc` binary: the command line of `lib.rs`, with btc's allocator.

// Compiling large plans allocates many small strings; mimalloc is markedly
// faster at that than the system allocator. `alloc` says what it adds.
#[global_allocator]
static GLOBAL: btc::alloc::Alloc = btc::alloc::Alloc;

fn main() -> std::process::ExitCode {
    btc::run(std::env::args_os())
}
