"""btc: PDDL plans into behaviour trees, in your own process.

A project is a rules file (``.btrules``) and the PDDL domain and problem it
names. Check it, plan, compile the plan into a tree, and emit the tree as
BehaviorTree.CPP XML, JSON, Mermaid or DOT::

    import btc
    project = btc.Project("rules.btrules")
    plan = project.plan()
    tree = project.compile(plan)
    print(tree.to_btcpp_xml())

Bad input raises :class:`BtcError`, whose ``diagnostics`` say what is wrong
and where (code, severity, message, path, line, column, hint).

``btc.btc_runtime`` is btc's py_trees runtime, the one the modules that
``btc compile --emit pytrees --runtime import`` writes import.
"""

from ._agent import (
    Agent,
    AgentReport,
    Attempt,
    FaultOutcome,
    Record,
    Replan,
)
from ._btc import (
    BtcError,
    Diagnostic,
    Plan,
    Project,
    Step,
    Tree,
    __version__,
    plan,
)

__all__ = [
    "Agent",
    "AgentReport",
    "Attempt",
    "BtcError",
    "FaultOutcome",
    "Record",
    "Replan",
    "Diagnostic",
    "Plan",
    "Project",
    "Step",
    "Tree",
    "__version__",
    "plan",
]
