"""One plan -> tree round on the ARIAC part task, as an agent meets it:
plan from the problem, compile the plan, build the py_trees tree.

In-process through the `btc` package, and by the subprocess route a team
uses without it (`btc plan`, `btc compile --emit pytrees`, import the
written module and build its tree), in the same run. Prints the medians
and the target; `cargo bench --bench embed` calls it.

    python round.py [--btc PATH] [--rounds N]
"""

import argparse
import importlib.util
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import btc

ROOT = pathlib.Path(__file__).resolve().parents[2]
ARIAC = ROOT / "examples" / "ariac"
TARGET_MS = 1.0


def in_process(project):
    plan = project.plan()
    tree = project.compile(plan)
    return tree.to_py_trees()


def by_subprocess(exe, work, n):
    plan = work / "plan.txt"
    module = work / f"tree_{n}.py"
    subprocess.run(
        [exe, "plan", str(ARIAC / "domain.pddl"), str(ARIAC / "problem.pddl"), "-o", str(plan),
         "--quiet"],
        check=True, capture_output=True,
    )  # fmt: skip
    subprocess.run(
        [exe, "compile", str(ARIAC / "rules.btrules"), "--plan", str(plan),
         "--problem", str(ARIAC / "problem.pddl"), "--emit", "pytrees", "-o", str(module)],
        check=True, capture_output=True,
    )  # fmt: skip
    spec = importlib.util.spec_from_file_location(f"tree_{n}", module)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.create_behavior_tree()


def median_ms(fn, rounds):
    times = []
    for i in range(rounds):
        t0 = time.perf_counter()
        fn(i)
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times), sorted(times)[int(0.99 * (len(times) - 1))]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--btc", default=str(ROOT / "target" / "release" / "btc"))
    ap.add_argument("--rounds", type=int, default=2000)
    args = ap.parse_args()
    project = btc.Project(ARIAC / "rules.btrules")
    for _ in range(50):
        in_process(project)
    p50, p99 = median_ms(lambda _: in_process(project), args.rounds)
    print(
        f"in-process from Python: p50 {p50:.3f} ms, p99 {p99:.3f} ms (target p50 < {TARGET_MS} ms)"
    )
    if pathlib.Path(args.btc).exists():
        with tempfile.TemporaryDirectory() as d:
            sub50, sub99 = median_ms(
                lambda n: by_subprocess(args.btc, pathlib.Path(d), n), max(args.rounds // 20, 20)
            )
        print(
            f"subprocess route:       p50 {sub50:.3f} ms, p99 {sub99:.3f} ms "
            f"({sub50 / p50:.1f}x the in-process round)"
        )
    else:
        print(f"subprocess route: skipped, no btc binary at {args.btc} (cargo build --release)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
