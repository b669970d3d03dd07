"""btc.Agent under real py_trees against `btc run --replan`: on every ARIAC
fault scenario of examples/ariac/faults, behaviours that report the
scenario's fault when it would happen lead the loop to the same decisions
(the plans, the replans and what they changed, the goal reached) as btc's
own loop with the scenario injected."""

import json
import pathlib
import subprocess
import sys

import py_trees
import pytest

import btc
from btc import btc_runtime

sys.path.insert(0, str(pathlib.Path(__file__).parent))
from test_btc import ROOT, btc_command  # noqa: E402

ARIAC = ROOT / "examples" / "ariac"
SCENARIOS = sorted(p.stem for p in (ARIAC / "faults").glob("*.toml"))
FIELDS = ("name", "robot", "part", "duration", "retract", "add", "goal")

tomllib = pytest.importorskip("tomllib", reason="reading the scenarios needs Python 3.11")


class Player:
    """A scenario's faults, reported by the behaviours when they are due:
    at a tick, when a plan step starts, when an action starts (its n-th
    time)."""

    def __init__(self, scenario):
        self.faults = [dict(f) for f in tomllib.loads(scenario.read_text())["fault"]]
        self.seen = {}
        self.paused = 0
        self.failing = None

    def due(self, action, kb):
        self.seen[action.NODE_ID] = self.seen.get(action.NODE_ID, 0) + 1
        out = []
        for f in self.faults:
            if f.get("fired"):
                continue
            if "at_tick" in f:
                continue
            if "on_step" in f:
                fire = action.step is not None and action.step >= f["on_step"] - 1
            else:
                fire = f["on_action"] == action.NODE_ID and self.seen[action.NODE_ID] >= f.get(
                    "occurrence", 1
                )
            if fire:
                f["fired"] = True
                out.append(f)
        return out

    def before_tick(self, kb):
        """Faults at a tick come from outside the tree (an order arrives, a
        part is found missing), before the tree ticks."""
        for f in self.faults:
            if not f.get("fired") and f.get("at_tick") == kb.tick:
                f["fired"] = True
                kb.report_fault(f["kind"], **{k: f[k] for k in FIELDS if k in f})
                if f.get("duration"):
                    self.paused = f["duration"]


def behaviours(player, ids):
    """A class per action node id: btc's simulated action, reporting the
    scenario's faults as a real behaviour would."""

    class Scripted(btc_runtime.Action):
        def tick(self):
            if self.status != py_trees.common.Status.RUNNING:
                for f in player.due(self, self.kb):
                    fields = {k: f[k] for k in FIELDS if k in f}
                    self.kb.report_fault(f["kind"], reporter=self.name, **fields)
                    if f["kind"] in ("faulty_gripper", "robot_malfunction"):
                        # It lasts the attempt: the loop waits out the rest.
                        player.failing = (f, self.kb)
                    elif f.get("duration"):
                        player.paused = f["duration"]
            yield from super().tick()

        def update(self):
            if player.failing is not None:
                f, kb = player.failing
                robot_acts = f.get("robot") in self.ports.values()
                if robot_acts and kb is self.kb:
                    if f["kind"] == "faulty_gripper":
                        player.failing = None
                    self.feedback_message = "%s (fault `%s`)" % (f["kind"], f["kind"])
                    return py_trees.common.Status.FAILURE
            if player.paused > 0:
                player.paused -= 1
                return py_trees.common.Status.RUNNING
            return super().update()

    return {i: type(i, (Scripted,), {"NODE_ID": i}) for i in ids}


def decisions(report):
    """What the loop decided, without timings, ticks or words."""
    return {
        "goal_reached": report["goal_reached"],
        "plans": [a["plan"] for a in report["attempts"]],
        "replans": [
            (r["from_step"], r["action"], r["faults"], r["adjustments"]) for r in report["replans"]
        ],
        "faults": sorted(f["kind"] for f in report["faults"]),
        "goal": report["goal"],
    }


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_the_agent_decides_as_btc_run_replan(scenario):
    path = ARIAC / "faults" / f"{scenario}.toml"
    # It exits 1 where the goal is not reached: the report says why.
    out = subprocess.run(
        [
            btc_command(),
            "run",
            "examples/ariac/rules.btrules",
            "--problem",
            "examples/ariac/problem.pddl",
            "--replan",
            "--faults",
            str(path),
            "--format",
            "json",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode in (0, 1), out.stderr
    cli = json.loads(out.stdout)
    project = btc.Project(ARIAC / "rules.btrules")
    player = Player(path)
    nodes = behaviours(player, ("MoveTo", "Grasp", "Place", "Flip"))
    agent = btc.Agent(project, ARIAC / "problem.pddl", nodes, before_tick=player.before_tick)
    report = agent.run()
    ours = {
        "goal_reached": report.goal_reached,
        "attempts": [{"plan": a.plan} for a in report.attempts],
        "replans": [vars(r) for r in report.replans],
        "faults": [vars(f) for f in report.faults],
        "goal": report.goal,
    }
    assert decisions(ours) == decisions(cli)


def test_a_behaviours_exception_reaches_the_caller():
    class Broken(btc_runtime.Action):
        NODE_ID = "Grasp"

        def update(self):
            raise RuntimeError("the action server went away")

    project = btc.Project(ARIAC / "rules.btrules")
    with pytest.raises(RuntimeError, match="action server"):
        btc.Agent(project, nodes={"Grasp": Broken}).run()


def test_a_report_the_loop_cannot_take_raises_btc_error():
    class Confused(btc_runtime.Action):
        NODE_ID = "Grasp"

        def update(self):
            return self.report_fault("dropped", reason="a kind btc does not know")

    project = btc.Project(ARIAC / "rules.btrules")
    with pytest.raises(btc.BtcError) as e:
        btc.Agent(project, nodes={"Grasp": Confused}).run()
    assert "`dropped` is not a fault kind" in str(e.value)
    assert e.value.diagnostics


def test_a_dropped_part_is_picked_again():
    """The documented way: a behaviour standing in for an action client says
    the gripper dropped the part; the agent replans from where it lies."""

    class Grasp(btc_runtime.Action):
        NODE_ID = "Grasp"
        dropped = False

        def update(self):
            if not Grasp.dropped:
                Grasp.dropped = True
                return self.report_fault(
                    "faulty_gripper",
                    robot="floor_robot",
                    reason="the gripper dropped the part",
                )
            return super().update()

    class Place(btc_runtime.Action):
        NODE_ID = "Place"

    project = btc.Project(ARIAC / "rules.btrules")
    report = btc.Agent(project, nodes={"Grasp": Grasp, "Place": Place}).run()
    assert report.goal_reached
    assert [f.kind for f in report.faults] == ["faulty_gripper"]
    assert report.faults[0].ended == "recovered"
    assert report.attempts[0].records[0].node_id == "Grasp"
    assert report.attempts[0].records[0].reason == "the gripper dropped the part"
    assert report.attempts[0].records[0].faults == ["faulty_gripper"]


def test_the_embedding_example_recovers_from_its_fault():
    """examples/embed/python: an action-client behaviour, a faulty part, a
    replan with the spare."""
    out = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "embed" / "python" / "agent.py")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    assert "replanned after attempt 1" in out.stdout
    assert "(grasp floor_robot battery_red_2 bin5)" in out.stdout
    assert "goal (on battery_red_2 agv1): reached" in out.stdout
    assert "fault faulty_part: recovered" in out.stdout
