"""The `btc` package under a real Python: projects, plans and trees made
in-process are those the `btc` command makes from the same files, and bad
input of any kind raises `btc.BtcError` with diagnostics."""

import json
import os
import pathlib
import shutil
import subprocess
import sys
import types

import py_trees
import pytest

import btc

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = {
    "ariac": "plan.txt",
    "nist_kitting": "plan.plan",
    "p3_assembler": "plan.tplan",
    "two_robots": "plan.plan",
}


def btc_command():
    """The `btc` binary to compare with: `BTC_BIN`, or the debug build."""
    found = os.environ.get("BTC_BIN") or shutil.which("btc")
    built = ROOT / "target" / "debug" / "btc"
    if not found and built.exists():
        found = str(built)
    if not found:
        if os.environ.get("CI") == "true":
            pytest.fail("needs the btc binary: run `cargo build` or set BTC_BIN")
        pytest.skip("needs the btc binary: run `cargo build` or set BTC_BIN")
    return found


def run_btc(*args):
    out = subprocess.run(
        [btc_command(), *args], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_version_is_the_crates():
    cargo = (ROOT / "Cargo.toml").read_text()
    assert f'version = "{btc.__version__}"' in cargo


@pytest.mark.parametrize("example", sorted(EXAMPLES))
def test_a_tree_compiled_in_process_is_the_one_btc_compile_writes(example):
    folder = ROOT / "examples" / example
    project = btc.Project(folder / "rules.btrules")
    assert [d for d in project.check() if d.severity == "error"] == []
    plan_file = folder / EXAMPLES[example]
    plan = btc.Plan.parse(plan_file.read_text())
    tree = project.compile(plan)
    rel = f"examples/{example}"
    cli = run_btc(
        "compile", f"{rel}/rules.btrules", "--plan", f"{rel}/{EXAMPLES[example]}", "--emit", "btcpp"
    )
    assert tree.to_btcpp_xml() == cli
    mermaid = run_btc(
        "compile",
        f"{rel}/rules.btrules",
        "--plan",
        f"{rel}/{EXAMPLES[example]}",
        "--emit",
        "mermaid",
    )
    assert tree.to_mermaid() == mermaid


def test_plans_made_in_process_are_btc_plans():
    folder = ROOT / "examples" / "ariac"
    # Paths as str and as os.PathLike.
    ours = btc.plan(str(folder / "domain.pddl"), folder / "problem.pddl")
    cli = btc.Plan.parse(
        run_btc("plan", "examples/ariac/domain.pddl", "examples/ariac/problem.pddl", "--quiet")
    )
    assert ours == cli
    assert [s.action for s in ours.steps] == ["move", "grasp", "move", "place"]
    assert ours.cost == 4
    assert btc.Plan.parse(str(ours)) == ours
    project = btc.Project(str(folder / "rules.btrules"))
    assert project.plan() == ours
    assert project.plan(folder / "problem.pddl") == ours
    tree = project.compile(ours)
    assert tree.steps == [str(s) for s in ours.steps]


def test_a_project_from_texts_checks_plans_and_compiles():
    folder = ROOT / "examples" / "ariac"
    texts = btc.Project.from_texts(
        rules=(folder / "rules.btrules").read_text(),
        domain=(folder / "domain.pddl").read_text(),
        problem=(folder / "problem.pddl").read_text(),
    )
    disk = btc.Project(folder / "rules.btrules")
    assert [d.code for d in texts.check()] == [d.code for d in disk.check()]
    plan = texts.plan()
    assert texts.compile(plan).to_btcpp_xml() == disk.compile(plan).to_btcpp_xml()
    assert texts.compile(plan).to_json().startswith("{")
    assert texts.compile(plan).to_dot().startswith("digraph")


def test_diagnostics_say_what_and_where():
    domain = (ROOT / "examples" / "ariac" / "domain.pddl").read_text()
    project = btc.Project.from_texts(
        rules='domain "domain.pddl"\nrule (fly ?r) { Fly(r: ?r) }\n', domain=domain
    )
    diags = project.check()
    assert diags, "an action the domain lacks is reported"
    d = next(d for d in diags if d.severity == "error")
    assert d.path == "rules.btrules"
    assert d.line == 2
    assert d.column >= 1
    assert d.code.startswith("R")
    assert d.code in str(d)


def test_bad_input_raises_btc_error_with_diagnostics():
    with pytest.raises(btc.BtcError) as e:
        btc.Project("/nonexistent/rules.btrules")
    assert e.value.diagnostics[0].code == "F001"
    with pytest.raises(btc.BtcError) as e:
        btc.Plan.parse("0.000: (move a b [oops")
    assert all(d.path == "<plan>" and d.line == 1 for d in e.value.diagnostics)
    project = btc.Project(ROOT / "examples" / "ariac" / "rules.btrules")
    with pytest.raises(btc.BtcError) as e:
        project.compile(btc.Plan.parse("(fly robot1 moon)\n"))
    assert "fly" in str(e.value)
    assert any(d.severity == "error" for d in e.value.diagnostics)
    with pytest.raises(btc.BtcError):
        project.plan(ROOT / "examples" / "ariac" / "nope.pddl")
    with pytest.raises(TypeError):
        btc.Project(42)


HOSTILE = [
    "",
    "\0" * 64,
    "(" * 100_000,
    ")" * 1000,
    "rule",
    'domain "/dev/zero"',
    "\ufeff(define",
    "é" * 10_000,
    "\ud7ff\ue000",
    'domain "domain.pddl"\n' + "rule (a) { " * 5000,
]


@pytest.mark.parametrize("text", HOSTILE, ids=range(len(HOSTILE)))
def test_hostile_texts_never_crash_the_process(text):
    try:
        project = btc.Project.from_texts(rules=text, domain=text, problem=text)
    except btc.BtcError as e:
        assert e.diagnostics
    else:
        project.check()
        with pytest.raises(btc.BtcError):
            project.plan()
    try:
        btc.Plan.parse(text)
    except btc.BtcError as e:
        assert e.diagnostics


def test_the_package_carries_btcs_py_trees_runtime():
    import py_trees

    from btc import btc_runtime

    source = (ROOT / "emit" / "python" / "btc_runtime.py").read_text()
    assert pathlib.Path(btc_runtime.__file__).read_text() == source
    assert issubclass(btc_runtime.Action, py_trees.behaviour.Behaviour)


def generated_module_run(example, tmp_path):
    """The tree as `btc compile --emit pytrees` writes it, run by Python as a
    program: the route the package replaces, and what it must agree with."""
    rel = f"examples/{example}"
    module = tmp_path / f"{example}_tree.py"
    run_btc(
        "compile", f"{rel}/rules.btrules", "--plan", f"{rel}/{EXAMPLES[example]}",
        "--emit", "pytrees", "-o", str(module),
    )  # fmt: skip
    out = subprocess.run(
        [sys.executable, str(module), "--json"], capture_output=True, text=True, check=False
    )
    return json.loads(out.stdout)


@pytest.mark.parametrize("example", sorted(EXAMPLES))
def test_a_tree_built_in_process_runs_as_the_generated_module(example, tmp_path):
    from btc import btc_runtime

    folder = ROOT / "examples" / example
    project = btc.Project(folder / "rules.btrules")
    tree = project.compile(btc.Plan.parse((folder / EXAMPLES[example]).read_text()))
    root = tree.to_py_trees()
    assert isinstance(root, py_trees.behaviour.Behaviour)
    result = btc_runtime.run(root, tree.knowledge_base(), 10000)
    assert result.as_json() == generated_module_run(example, tmp_path)
    assert result.success()


def test_a_partial_node_mapping_keeps_btcs_own_leaves():
    from btc import btc_runtime

    ticks = []

    class Grasp(btc_runtime.Action):
        def update(self):
            ticks.append(self.name)
            return py_trees.common.Status.SUCCESS

    project = btc.Project(ROOT / "examples" / "ariac" / "rules.btrules")
    tree = project.compile(project.plan())
    # A mapping that names one action: MoveTo and Place stay simulated,
    # RobotNormal evaluates its formula.
    result = btc_runtime.run(tree.to_py_trees({"Grasp": Grasp}), tree.knowledge_base(), 100)
    assert result.success()
    assert len(ticks) == 1
    # The same through a module's attributes.
    module = types.ModuleType("my_nodes")
    module.Grasp = Grasp
    result = btc_runtime.run(tree.to_py_trees(module), tree.knowledge_base(), 100)
    assert result.success() and len(ticks) == 2
    # The condition is btc's: with the robot disabled the monitor fails.
    kb = tree.knowledge_base()
    kb.facts.discard(("is_enabled", "floor_robot"))
    result = btc_runtime.run(tree.to_py_trees({"Grasp": Grasp}), kb, 100)
    assert result.status == py_trees.common.Status.FAILURE


def test_ten_thousand_rounds_keep_the_blackboard_and_memory_flat():
    """An agent's life: plan, compile, build and run a tree, again and
    again, in one process. The blackboard's clients and the resident
    memory stay flat (the count is the test; the time is not)."""
    import gc
    import resource

    from btc import btc_runtime

    project = btc.Project(ROOT / "examples" / "ariac" / "rules.btrules")
    clients = py_trees.blackboard.Blackboard.clients

    def round_trip():
        tree = project.compile(project.plan())
        result = btc_runtime.run(tree.to_py_trees(), tree.knowledge_base(), 100)
        assert result.success()

    for _ in range(500):
        round_trip()
    gc.collect()
    settled = len(clients)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB
    for i in range(9500):
        round_trip()
        if i % 1000 == 999:
            gc.collect()
            assert len(clients) == settled, f"round {i + 501}: {len(clients)} clients"
    gc.collect()
    assert len(clients) == settled
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss
    assert grown < 16 * 1024, f"resident memory grew by {grown} KiB over 9,500 rounds"


def test_the_package_is_a_complete_install_with_the_btc_command():
    """`pip install` puts `btc` on the PATH: btc's command line, the same
    binary's code, run by the package's native module."""
    import importlib.metadata

    scripts = [
        e for e in importlib.metadata.entry_points(group="console_scripts") if e.name == "btc"
    ]
    installed = [e for e in scripts if e.value == "btc._cli:main"]
    if not installed:
        if os.environ.get("CI") == "true":
            pytest.fail("the installed package has no `btc` command")
        pytest.skip("the package is not installed (run from the source folder)")
    command = pathlib.Path(sys.executable).parent / "btc"
    assert command.exists(), command
    version = subprocess.run([command, "--version"], capture_output=True, text=True, check=False)
    assert version.returncode == 0
    assert version.stdout.strip() == f"btc {btc.__version__}"
    rules = ROOT / "examples" / "ariac" / "rules.btrules"
    plan = ROOT / "examples" / "ariac" / "plan.txt"
    args = ["compile", str(rules), "--plan", str(plan), "--emit", "btcpp"]
    ours = subprocess.run([command, *args], capture_output=True, text=True, check=False)
    theirs = run_btc(*args)
    assert ours.returncode == 0, ours.stderr
    assert ours.stdout == theirs
    # Bad input: the command's own error and exit status, no traceback.
    bad = subprocess.run(
        [command, "check", ROOT / "no_such.btrules"], capture_output=True, text=True, check=False
    )
    assert bad.returncode == 2
    assert "F001" in bad.stderr or "cannot read" in bad.stderr, bad.stderr
    assert "Traceback" not in bad.stderr
