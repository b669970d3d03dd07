"""The P3 assembler's own leaf behaviours, plugged into the tree btc
generates (docs/pytrees.md):

    btc compile examples/p3_assembler/rules.btrules \
        --plan examples/p3_assembler/plan.tplan --emit pytrees \
        --runtime import --node-module p3_nodes -o out/p3.py
    cp examples/p3_assembler/pytrees/p3_nodes.py out/
    python3 out/p3.py

Each class is named after the node id it implements (the generated module's
NODE_CLASS_NAMES) and derives from btc_runtime's bases, so the plan step it
runs in still has its precondition checked on the knowledge base before it
starts. Here a small simulated robot stands in for the real drivers: a
navigation takes one tick per metre, the marker detector reads what the
camera sees, the gripper holds one tool.
"""

import py_trees

from btc_runtime import Action

Status = py_trees.common.Status

# Distances between the cell's locations, in metres.
DISTANCE = {
    frozenset(("home", "tool_rack")): 3,
    frozenset(("tool_rack", "assembly_station")): 2,
    frozenset(("home", "assembly_station")): 4,
}


class Robot:
    """The robot the behaviours drive: where it is, what it holds."""

    def __init__(self):
        self.location = "home"
        self.holding = None
        self.log = []


ROBOT = Robot()

# The marker ids the camera sees at each location (rules.btrules' tables).
VISIBLE_MARKERS = {"tool_rack": {11, 21, 31}, "assembly_station": {12, 22, 32}}


class Navigate(Action):
    """Drives to `goal`, one metre per tick."""

    def initialise(self):
        goal = self.ports["goal"]
        self.left = DISTANCE.get(frozenset((ROBOT.location, goal)), 0)

    def update(self):
        if self.left > 0:
            self.left -= 1
            self.feedback_message = "%d m to go" % self.left
            return Status.RUNNING
        ROBOT.location = self.ports["goal"]
        ROBOT.log.append("at " + ROBOT.location)
        return Status.SUCCESS


class DetectMarker(Action):
    """SUCCESS when the camera sees marker `marker` where the robot is."""

    def update(self):
        seen = VISIBLE_MARKERS.get(ROBOT.location, set())
        if int(self.ports["marker"]) in seen:
            return Status.SUCCESS
        self.feedback_message = "marker %s not in view" % self.ports["marker"]
        return Status.FAILURE


class PickTool(Action):
    """Closes the gripper on `tool`."""

    def update(self):
        if ROBOT.holding is not None:
            return Status.FAILURE
        ROBOT.holding = self.ports["tool"]
        ROBOT.log.append("picked " + ROBOT.holding)
        return Status.SUCCESS


class PlaceTool(Action):
    """Opens the gripper at the assembly station."""

    def update(self):
        if ROBOT.holding != self.ports["tool"]:
            return Status.FAILURE
        ROBOT.log.append("placed " + ROBOT.holding)
        ROBOT.holding = None
        return Status.SUCCESS


class Wait(Action):
    """Waits `seconds`, at one tick per second."""

    def initialise(self):
        self.left = int(float(self.ports["seconds"]))

    def update(self):
        if self.left > 0:
            self.left -= 1
            return Status.RUNNING
        return Status.SUCCESS
