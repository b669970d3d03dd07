"""The fourth execution: a tree built in-process by `Tree.to_py_trees()`
and ticked under real py_trees means what `btc run` says it means. On
every example with a plan and every corpus plan of a domain with rules
(`tests/corpus_rules/`), both give the same step starts and ends (with
their ticks), the same final KB, the same status and the same goal
verdict. (`runtime/tests/three_way.rs` holds the other three: btc's
engine on the IR and on the XML, the generated module under py_trees.)

The corpus jobs need `../shared/corpus/ipc` (or `BTC_CORPUS`): skipped
without it, required under `CI=true`."""

import json
import os
import pathlib
import subprocess
import sys

import pytest

import btc
from btc import btc_runtime

sys.path.insert(0, str(pathlib.Path(__file__).parent))
from test_btc import EXAMPLES, ROOT, btc_command  # noqa: E402

MAX_TICKS = 100_000


def corpus():
    found = pathlib.Path(os.environ.get("BTC_CORPUS", ROOT.parent / "shared" / "corpus" / "ipc"))
    return found if found.is_dir() else None


def jobs():
    """`(name, rules, plan, problem)`: the examples, then the corpus's."""
    out = [
        (f"examples/{e}", ROOT / "examples" / e / "rules.btrules", ROOT / "examples" / e / p, None)
        for e, p in sorted(EXAMPLES.items())
    ]
    ipc = corpus()
    if ipc is None:
        return out
    for rules_dir in sorted((ROOT / "tests" / "corpus_rules").iterdir()):
        folder = ipc / rules_dir.name
        for plan in sorted(folder.glob("*.plan")) + sorted(folder.glob("*.tplan")):
            problem = folder / f"{plan.stem}.pddl"
            out.append(
                (f"{rules_dir.name}/{plan.name}", rules_dir / "rules.btrules", plan, problem)
            )
    return out


def by_btc_run(rules, plan, problem, tmp_path):
    """`btc run` on the same files: its summary and its trace's step events."""
    trace = tmp_path / "trace.jsonl"
    args = [btc_command(), "run", str(rules), "--plan", str(plan), "--format", "json"]
    args += ["--trace", str(trace), "--max-ticks", str(MAX_TICKS)]
    if problem is not None:
        args += ["--problem", str(problem)]
    out = subprocess.run(args, cwd=ROOT, capture_output=True, text=True, check=False)
    assert out.returncode in (0, 1), out.stderr
    summary = json.loads(out.stdout)
    events = []
    for line in trace.read_text().splitlines():
        e = json.loads(line)
        if e.get("event") in ("step_started", "step_finished"):
            events.append(
                [e["tick"], "start" if e["event"] == "step_started" else "end", e["step"]]
            )
    return {
        "status": summary["status"].upper(),
        "goal_reached": summary["goal_reached"],
        "events": events,
        "kb": summary["kb"],
    }


def in_process(rules, plan, problem):
    project = btc.Project(rules)
    tree = project.compile(btc.Plan.parse(plan.read_text()), problem)
    result = btc_runtime.run(tree.to_py_trees(), tree.knowledge_base(), MAX_TICKS).as_json()
    del result["ticks"]
    return result


def test_the_corpus_is_there_under_ci():
    if corpus() is None:
        if os.environ.get("CI") == "true":
            pytest.fail("the corpus jobs need ../shared/corpus/ipc (or BTC_CORPUS)")
        pytest.skip("the corpus jobs need ../shared/corpus/ipc (or BTC_CORPUS)")
    assert len(jobs()) >= len(EXAMPLES) + 12


@pytest.mark.parametrize("job", jobs(), ids=lambda j: j[0])
def test_a_tree_built_in_process_runs_as_btc_run_runs_it(job, tmp_path):
    _, rules, plan, problem = job
    ours = in_process(rules, plan, problem)
    theirs = by_btc_run(rules, plan, problem, tmp_path)
    assert ours == theirs
    assert ours["goal_reached"] and ours["status"] == "SUCCESS"
