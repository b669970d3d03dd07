"""The closed loop under real py_trees: plan, build the tree with your
behaviours, tick it, and when it fails (or a behaviour reports a fault),
plan again from the state it left, as ``btc run --replan`` does.

btc's loop (in Rust) plans and compiles each attempt and decides what comes
next; this module is its executor: it builds the attempt's py_trees tree,
ticks it, and reports the knowledge base, the failing nodes and the faults
your behaviours reported.
"""

from __future__ import annotations

import dataclasses
import json
import os
from typing import Any, Callable, Mapping

import py_trees

from . import btc_runtime

Status = py_trees.common.Status
_DONE = (Status.SUCCESS, Status.FAILURE)


@dataclasses.dataclass(frozen=True)
class Record:
    """Why a node failed: the failure a replan starts from."""

    tick: int
    node_id: str
    node_name: str
    step: int | None
    action: str | None
    reason: str
    faults: list
    kb: list


@dataclasses.dataclass(frozen=True)
class Attempt:
    """One plan and its run."""

    attempt: int
    source: str
    goal: str
    plan: list
    status: str
    steps_done: int
    steps_total: int
    start_tick: int
    end_tick: int
    waited_ticks: int
    preempted: bool
    records: list
    planning_ms: float
    compile_ms: float
    run_ms: float
    expanded: int


@dataclasses.dataclass(frozen=True)
class Replan:
    """Why the loop planned again, from where, and what changed in the goal."""

    after_attempt: int
    tick: int
    why: str
    from_step: int | None
    action: str | None
    faults: list
    adjustments: list


@dataclasses.dataclass(frozen=True)
class FaultOutcome:
    fault: str
    kind: str
    met_at: int | None
    ended: str


@dataclasses.dataclass(frozen=True)
class AgentReport:
    """What the loop came to."""

    attempts: list
    replans: list
    faults: list
    goal: str
    goal_reached: bool
    goal_failure: str | None
    ticks: int
    stopped: list
    unreachable: list

    @staticmethod
    def _from(data: dict) -> AgentReport:
        attempts = [
            _make(Attempt, dict(a, records=[_make(Record, r) for r in a["records"]]))
            for a in data["attempts"]
        ]
        return AgentReport(
            attempts=attempts,
            replans=[_make(Replan, r) for r in data["replans"]],
            faults=[_make(FaultOutcome, f) for f in data["faults"]],
            goal=data["goal"],
            goal_reached=data["goal_reached"],
            goal_failure=data["goal_failure"],
            ticks=data["ticks"],
            stopped=data["stopped"],
            unreachable=data["unreachable"],
        )


def _make(cls, data: dict):
    """A report's value from its JSON object: the fields the class has (an
    engine record's node index means nothing outside btc's engine)."""
    return cls(**{f.name: data[f.name] for f in dataclasses.fields(cls)})


def _formula(text: str):
    """A goal's text as the runtime's formula (atoms, and, or, not)."""
    tokens = text.replace("(", " ( ").replace(")", " ) ").split()

    def read(i):
        if tokens[i] != "(":
            return tokens[i], i + 1
        i += 1
        head = tokens[i]
        if head in ("and", "or", "not"):
            parts, i = [":" + head], i + 1
            while tokens[i] != ")":
                part, i = read(i)
                parts.append(part)
            return tuple(parts), i + 1
        words = []
        while tokens[i] != ")":
            words.append(tokens[i])
            i += 1
        return tuple(words), i + 1

    return read(0)[0]


class _FailureWatcher(py_trees.visitors.VisitorBase):
    """Sees every ticked behaviour: the leaves that fail are the records."""

    def __init__(self, kb):
        super().__init__(full=False)
        self.kb = kb
        self.failed = []

    def run(self, behaviour):
        if behaviour.status == Status.FAILURE and not behaviour.children:
            self.failed.append((self.kb.tick, behaviour))


def _step_of(behaviour, kb):
    """The 1-based plan step a node belongs to, or the one running."""
    node = behaviour
    while node is not None:
        step = getattr(node, "step", None)
        if isinstance(step, int):
            return step + 1
        node = node.parent
    for k, (started, finished) in enumerate(zip(kb.started, kb.finished)):
        if started and not finished:
            return k + 1
    return None


def _record(tick, behaviour, kb, faults):
    return {
        "tick": tick,
        "node_id": getattr(type(behaviour), "NODE_ID", None) or type(behaviour).__name__,
        "node_name": behaviour.name,
        "reason": behaviour.feedback_message or "it returned FAILURE",
        "step": _step_of(behaviour, kb),
        "faults": faults,
    }


class Agent:
    """The closed loop with your behaviours, under real py_trees.

    ``nodes`` names your behaviour classes (a module, or a mapping of node
    id -> class); node ids it does not name are btc's own leaves. A
    behaviour says a fault happened with ``self.report_fault(kind, ...)``
    (``btc.btc_runtime.Action``) or ``kb.report_fault(kind, ...)``: the
    knowledge base changes as the fault says, and the loop replans as
    ``btc run --replan`` does (a discarded part replaced by a spare, a
    priority order first). A reported ``high_priority_order`` whose goal
    does not hold halts the tree at once: the order comes first.

    ``before_tick(kb)``, if given, is called before each tick with the
    knowledge base: where news from outside the tree comes in (perception
    updating facts, an order arriving: ``kb.report_fault(...)``).
    """

    def __init__(
        self,
        project,
        problem: str | os.PathLike | None = None,
        nodes: Mapping[str, Any] | Any | None = None,
        *,
        ticks_per_action: int = 1,
        ms_per_tick: int = 10,
        before_tick: Callable[[Any], None] | None = None,
    ):
        self.project = project
        self.problem = None if problem is None else os.fspath(problem)
        self.nodes = nodes
        self.ticks_per_action = ticks_per_action
        self.ms_per_tick = ms_per_tick
        self.before_tick = before_tick

    def run(self, *, max_replans: int = 5, max_ticks: int = 100_000) -> AgentReport:
        """Plans, runs and replans until the goal holds or the loop must stop
        (no plan reaches the goal, or a limit); bad input raises
        ``btc.BtcError``, an exception of a behaviour propagates."""
        text = self.project._run_agent(self._execute, self.problem, max_replans, max_ticks)
        return AgentReport._from(json.loads(text))

    def _execute(self, attempt: dict) -> dict:
        """One attempt: the tree built and ticked from the loop's state."""
        tree = attempt["tree"]
        kb = tree.knowledge_base(self.ticks_per_action, self.ms_per_tick)
        root = tree.to_py_trees(self.nodes)
        watcher = _FailureWatcher(kb)
        writer = btc_runtime.put_kb(kb)
        bt = py_trees.trees.BehaviourTree(root)
        bt.visitors.append(watcher)
        try:
            bt.setup()
            status = Status.RUNNING
            while kb.tick < attempt["max_ticks"]:
                kb.tick += 1
                if self.before_tick is not None:
                    self.before_tick(kb)
                    if self._order_first(kb):
                        break
                bt.tick()
                status = root.status
                if status in _DONE or self._order_first(kb):
                    break
            if status not in _DONE:
                root.stop(Status.INVALID)
        finally:
            bt.shutdown()
            writer.unregister(clear=False)
        labels = [f.get("name") or f["kind"] for f in kb.faults]
        records = [
            _record(t, b, kb, labels)
            for t, b in watcher.failed
            if any(f.get("reporter") == b.name for f in kb.faults)
        ]
        if status == Status.FAILURE and watcher.failed:
            t, b = watcher.failed[-1]
            last = _record(t, b, kb, labels)
            if not records or records[-1] != last:
                records.append(last)
        return {
            "status": status.name if status in _DONE else "RUNNING",
            "state": kb.snapshot(),
            "ticks": kb.tick,
            "steps_done": sum(kb.finished),
            "records": records,
            "faults": kb.faults,
        }

    @staticmethod
    def _order_first(kb) -> bool:
        """A reported order whose goal does not hold preempts the tree."""
        return any(
            f["kind"] == "high_priority_order"
            and f.get("goal")
            and not kb.holds(_formula(f["goal"]))
            for f in kb.faults
        )
