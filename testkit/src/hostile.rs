//! Helpers for tests that feed btc input written to break it: deep nesting
//! run on a small stack, and the shape of the time a size takes (a ratio of
//! two sizes, never a wall-clock figure that depends on the machine).

use std::time::Duration;

/// Runs `f` on a thread with a 1 MiB stack: deep input must be refused,
/// not overflow it. 1 MiB holds every pass at the nesting limit, and is a
/// tenth of what ten times the limit would need if anything recursed past
/// it. Panics (failing the test) if `f` panics.
pub fn on_small_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new()
        .stack_size(1 << 20)
        .spawn(f)
        .expect("a thread")
        .join()
        .expect("no panic, no overflow")
}

/// The CPU time this thread has used: what a run costs, whatever else the
/// machine runs meanwhile (wall time on a loaded machine counts the other
/// processes' time slices too, and more of them for a longer run).
fn thread_cpu_time() -> Duration {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for the call to write.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } == 0;
    assert!(ok, "clock_gettime(CLOCK_THREAD_CPUTIME_ID)");
    Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
}

/// The fastest of three runs of `f`, in this thread's CPU time.
pub fn fastest(f: impl Fn()) -> Duration {
    (0..3)
        .map(|_| {
            let t = thread_cpu_time();
            f();
            thread_cpu_time().saturating_sub(t)
        })
        .min()
        .expect("three runs")
}

/// Asserts that `f` on ten times the input takes less than `bound` times
/// as long as on the input: linear work gives about 10, quadratic 100.
/// `make(n)` builds the input of size `n`.
pub fn assert_linear<I>(
    what: &str,
    n: usize,
    bound: f64,
    make: impl Fn(usize) -> I,
    f: impl Fn(&I),
) {
    let small = make(n);
    let large = make(10 * n);
    // Warm up caches and lazy statics before measuring.
    f(&small);
    // Quadratic work is over the bound every time; a busy machine (other
    // test binaries run in parallel) only now and then: measure again
    // before failing.
    let mut seen = Vec::new();
    for _ in 0..3 {
        let ts = fastest(|| f(&small));
        let tl = fastest(|| f(&large));
        let ratio = tl.as_secs_f64() / ts.as_secs_f64().max(1e-6);
        if ratio < bound {
            return;
        }
        seen.push(format!("{ratio:.1}x ({ts:?} -> {tl:?})"));
    }
    panic!(
        "{what}: 10x the input took, in three measurements, {}",
        seen.join(", ")
    );
}
