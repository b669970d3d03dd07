"""A temporal planner from the package index, run on a PDDL 2.1 domain and
problem through unified-planning: `peer.py PLANNER DOMAIN PROBLEM` with
PLANNER one of unified-planning's engine names (`tamer`, `aries`, `lpg`;
`pip install unified-planning up-tamer up-aries up-lpg`). Prints one JSON
object: the plan in the timed form (`0.000: (action args) [duration]`),
its makespan, and the planner's wall-clock seconds; or `skipped` with how
to install what is missing (exit 3); or the planner's status when it found
no plan (exit 1). The caller bounds its time: some engines ignore a
timeout."""

import json
import sys
import time


def main() -> int:
    name, domain, problem = sys.argv[1], sys.argv[2], sys.argv[3]
    try:
        from unified_planning.io import PDDLReader
        from unified_planning.shortcuts import OneshotPlanner, get_environment
    except ImportError:
        print(json.dumps({"skipped": "pip install unified-planning"}))
        return 3
    env = get_environment()
    env.credits_stream = None
    env.error_used_name = False
    task = PDDLReader().parse_problem(domain, problem)
    try:
        planner = OneshotPlanner(name=name)
    except Exception as e:  # noqa: BLE001 - the engine is not installed
        why = type(e).__name__
        print(json.dumps({"skipped": f"pip install up-{name} ({why})"}))
        return 3
    t0 = time.perf_counter()
    try:
        with planner:
            result = planner.solve(task)
    except Exception as e:  # noqa: BLE001 - the engine's own failure
        print(json.dumps({"status": f"failed: {e}"}))
        return 1
    seconds = time.perf_counter() - t0
    if result.plan is None:
        print(json.dumps({"status": result.status.name, "seconds": seconds}))
        return 1
    steps = []
    makespan = 0.0
    for start, action, duration in result.plan.timed_actions:
        start = float(start)
        duration = float(duration) if duration is not None else 0.0
        makespan = max(makespan, start + duration)
        args = "".join(f" {p}" for p in action.actual_parameters)
        steps.append(f"{start:.3f}: ({action.action.name}{args}) [{duration:.3f}]")
    print(json.dumps({"makespan": makespan, "seconds": seconds, "plan": steps}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
