"""A seed-style P3 generator: the algorithm of the "P3 assembler" pseudocode
(/work/shared/seeds/000_*.txt, Parts 1 and 2) written anew in Python, as the
peer btc's py_trees compile is measured against (lang/benches/compile_scale.rs).

Usage: python3 p3_seed_generator.py PLAN OUTPUT
"""

import re
import sys

# The knowledge base: operations and their marker ids.
KNOWLEDGE_BASE = {
    "OP1": {"pick_marker": 11, "place_marker": 12},
    "OP2": {"pick_marker": 21, "place_marker": 22},
    "OP3": {"pick_marker": 31, "place_marker": 32},
}
ALL_PREDICATE_PARAMETER_ORDER = {
    "at": ["agent", "location"],
    "holding": ["agent", "tool"],
    "tool_at": ["tool", "location"],
    "hand_free": ["agent"],
}
OPPOSITE_LOCATION = {"home": "tool_rack", "tool_rack": "assembly_station"}
LINE = re.compile(r"^\s*([0-9.]+)\s*:\s*\(([^()\s]+)\s*([^()]*)\)")


def parse_pddl_plan(path):
    actions, tool_to_op = {}, {}
    with open(path) as f:
        for raw in f:
            line = " ".join(raw.split())
            if not line or line.startswith(";"):
                continue
            m = LINE.match(line)
            if not m:
                continue
            time, name, params = m.group(1), m.group(2), m.group(3).split()
            if not params:
                print("warning: no parameters: " + line, file=sys.stderr)
                continue
            key = name + time
            if "MOVE_TO" in name:
                if len(params) != 3:
                    print("error: MOVE_TO needs 3 parameters: " + line, file=sys.stderr)
                    continue
                actions[key] = {
                    "type": "move_to",
                    "agent": params[0],
                    "from": params[1],
                    "to": params[2],
                }
            elif "PICK" in name or "PLACE" in name:
                agent, tool = params[0], params[1]
                op = name.split("_", 1)[1] if "_" in name else None
                if op is None:
                    print("warning: no operation: " + line, file=sys.stderr)
                    continue
                tool_to_op[tool] = op
                location = params[2] if len(params) == 3 else None
                kind = "pick" if "PICK" in name else "place"
                actions[key] = {
                    "type": kind,
                    "agent": agent,
                    "tool": tool,
                    "op": op,
                    "location": location,
                }
            elif "WAIT" in name:
                actions[key] = {"type": "wait", "agent": params[0]}
            else:
                print("warning: unknown action: " + line, file=sys.stderr)
    return actions, tool_to_op


def filter_actions(actions):
    return {
        k: a for k, a in actions.items() if not (a["type"] == "move_to" and a["from"] == a["to"])
    }


def base_op(op):
    return op.split("_")[0]


HEADER = """import py_trees

PREDICATE_PARAMETER_ORDER = %r
KB = set()


def update_kb(predicate, args, value):
    fact = (predicate,) + tuple(args)
    if value:
        KB.add(fact)
    else:
        KB.discard(fact)


class KBUpdateDecorator(py_trees.decorators.Decorator):
    def __init__(self, name, child, updates):
        super().__init__(name=name, child=child)
        self.updates = updates

    def update(self):
        if self.decorated.status == py_trees.common.Status.SUCCESS:
            for predicate, args, value in self.updates:
                update_kb(predicate, args, value)
        return self.decorated.status


def create_behavior_tree():
    root = py_trees.composites.Sequence(name="root", memory=True)
"""


def create_behavior_tree_file(actions, tool_to_op, output):
    used = {p for a in actions.values() for p in ("at", "holding", "tool_at", "hand_free")}
    order = {p: ALL_PREDICATE_PARAMETER_ORDER[p] for p in sorted(used)}
    out = [HEADER % (order,)]
    # Every operation the plan names (the seed collects them from tool_to_op,
    # which keeps one operation per tool: a tool used for two operations
    # would leave one's markers undefined).
    ops = set(tool_to_op.values()) | {a["op"] for a in actions.values() if "op" in a}
    for op in sorted({base_op(o) for o in ops}):
        marks = KNOWLEDGE_BASE.get(op, {})
        out.append("    marker_id_pick_%s = %r\n" % (op, marks.get("pick_marker")))
        out.append("    marker_id_place_%s = %r\n" % (op, marks.get("place_marker")))
    out.append("    decorators = []\n")
    for i, (key, a) in enumerate(actions.items()):
        t = a["type"]
        if t == "move_to":
            out.append(
                "    s = py_trees.composites.Sequence(name=%r, memory=True)\n"
                "    s.add_child(py_trees.behaviours.Success(name='navigate_%d'))\n"
                "    decorators.append(KBUpdateDecorator(%r, s, [('at', [%r, %r], False), "
                "('at', [%r, %r], True)]))\n"
                % (key, i, "kb_" + key, a["agent"], a["from"], a["agent"], a["to"])
            )
        elif t == "wait":
            out.append(
                "    s = py_trees.composites.Sequence(name=%r, memory=True)\n"
                "    s.add_child(py_trees.behaviours.Success(name='wait_%d'))\n"
                "    decorators.append(KBUpdateDecorator(%r, s, []))\n" % (key, i, "kb_" + key)
            )
        else:
            op = base_op(a["op"])
            marker = "marker_id_%s_%s" % (t, op)
            fact = ("holding", [a["agent"], a["tool"]])
            out.append(
                "    s = py_trees.composites.Sequence(name=%r, memory=True)\n"
                "    s.add_child(py_trees.behaviours.Success(name='detect_%%d' %% %s))\n"
                "    s.add_child(py_trees.behaviours.Success(name='%s_%d'))\n"
                "    decorators.append(KBUpdateDecorator(%r, s, [(%r, %r, %r)]))\n"
                % (key, marker, t, i, "kb_" + key, fact[0], fact[1], t == "pick")
            )
    out.append("    root.add_children(decorators)\n    return root\n")
    with open(output, "w") as f:
        f.write("".join(out))


def main():
    plan, output = sys.argv[1], sys.argv[2]
    actions, tool_to_op = parse_pddl_plan(plan)
    filtered = filter_actions(actions)
    create_behavior_tree_file(filtered, tool_to_op, output)
    print("Behavior tree file %s generated successfully." % output)


if __name__ == "__main__":
    main()
