"""A robot agent in its own process: btc plans, builds the tree with this
agent's behaviours, ticks it under py_trees, and replans when a behaviour
reports a fault.

`Grasp` stands in for a ROS 2 action client: it sends a goal when it
starts, polls the goal's state every tick (RUNNING while the server
works), cancels the goal when the tree halts it, and when the server
aborts because the gripper's camera found the part faulty, reports the
ARIAC fault to btc. Here the server is simulated in-process
(`GripperServer`); under ROS 2 it would be an `rclpy.action.ActionClient`.
The first part is faulty: btc discards it, the agent replans with the
spare part of the same kind (problem_spare.pddl) and reaches the goal.

Run from the repository's root:  python examples/embed/python/agent.py
"""

import pathlib
import sys

import py_trees

import btc
from btc import btc_runtime

HERE = pathlib.Path(__file__).resolve().parent
ARIAC = HERE.parents[1] / "ariac"


class GripperServer:
    """An action server: a goal takes `ticks` polls; the first `faults`
    goals abort (the part is faulty)."""

    def __init__(self, ticks=2, faults=1):
        self.ticks = ticks
        self.faults = faults
        self.goals = []

    def send_goal(self, part):
        goal = {"part": part, "left": self.ticks, "state": "ACTIVE"}
        self.goals.append(goal)
        return goal

    def poll(self, goal):
        if goal["state"] != "ACTIVE":
            return goal["state"]
        goal["left"] -= 1
        if goal["left"] > 0:
            return "ACTIVE"
        if self.faults > 0:
            self.faults -= 1
            goal["state"] = "ABORTED"
        else:
            goal["state"] = "SUCCEEDED"
        return goal["state"]

    def cancel(self, goal):
        if goal["state"] == "ACTIVE":
            goal["state"] = "CANCELED"


SERVER = GripperServer()


class Grasp(btc_runtime.Action):
    """The action client: goal on start, poll while running, cancel on halt."""

    def initialise(self):
        super().initialise()
        self.goal = SERVER.send_goal(self.ports["part"])

    def update(self):
        state = SERVER.poll(self.goal)
        if state == "ACTIVE":
            return py_trees.common.Status.RUNNING
        if state == "SUCCEEDED":
            return py_trees.common.Status.SUCCESS
        return self.report_fault(
            "faulty_part",
            part=self.ports["part"],
            reason="the gripper's camera found %s faulty" % self.ports["part"],
        )

    def terminate(self, new_status):
        if new_status == py_trees.common.Status.INVALID:
            SERVER.cancel(self.goal)


def main():
    project = btc.Project(ARIAC / "rules.btrules")
    errors = [d for d in project.check() if d.severity == "error"]
    if errors:
        for d in errors:
            print(d, file=sys.stderr)
        return 2
    agent = btc.Agent(project, ARIAC / "problem_spare.pddl", nodes={"Grasp": Grasp})
    report = agent.run(max_replans=3)
    for a in report.attempts:
        print("attempt %d: %s, %d of %d steps" % (a.attempt, a.status, a.steps_done, a.steps_total))
        for step in a.plan:
            print("  " + step)
    for r in report.replans:
        print("replanned after attempt %d: %s" % (r.after_attempt, r.why))
    for f in report.faults:
        print("fault %s: %s" % (f.fault, f.ended))
    print("goal %s: %s" % (report.goal, "reached" if report.goal_reached else "not reached"))
    print("goals sent to the gripper: %d" % len(SERVER.goals))
    return 0 if report.goal_reached else 1


if __name__ == "__main__":
    sys.exit(main())
