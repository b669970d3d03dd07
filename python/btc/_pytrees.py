"""A compiled tree's py_trees behaviours, built in-process.

The module btc writes for `--emit pytrees --runtime import` is the tree as
data (the world, the plan's steps, the leaf classes, the rule trees, the
root) over btc's py_trees runtime. Here that text is read as data: each
assignment's value is a Python literal, read with `ast.literal_eval`, so no
generated code runs. Leaf classes come from the caller's `nodes` where it
names them (a module or a mapping of node id -> class) and are btc's own
otherwise: simulated actions, and conditions that evaluate the formula the
rules define on the knowledge base.
"""

import ast

from . import btc_runtime

_BASES = {"Action": btc_runtime.Action, "Condition": btc_runtime.Condition}


class TreeData:
    """What a generated module holds, as values."""

    def __init__(self, text):
        self.world = {}
        self.literals = {}
        self.classes = []
        self.defined = {}
        for node in ast.parse(text).body:
            if isinstance(node, ast.ClassDef):
                self.defined[node.name] = _class_of(node)
            elif isinstance(node, ast.Assign) and len(node.targets) == 1:
                name = getattr(node.targets[0], "id", None)
                self._assign(name, node.value)
        self.shapes = self.literals["SHAPES"]
        self.steps = self.literals["STEPS"]
        self.trees = self.literals["TREES"]
        self.root = self.literals["ROOT"]
        self.max_ticks = self.literals.get("MAX_TICKS", 10000)

    def _assign(self, name, value):
        if name == "WORLD" and isinstance(value, ast.Call):
            self.world = {k.arg: ast.literal_eval(k.value) for k in value.keywords}
        elif name == "CLASSES" and isinstance(value, ast.Tuple):
            # ((node id, class name), ...): the class is a name, not a literal.
            for pair in value.elts:
                ident, cls = pair.elts
                self.classes.append((ast.literal_eval(ident), cls.id))
        elif name in ("SHAPES", "STEPS", "TREES", "ROOT", "MAX_TICKS", "NODE_CLASS_NAMES"):
            self.literals[name] = ast.literal_eval(value)


def _class_of(node):
    """A generated leaf class: its base and its `NODE_ID` and `FORMULA`."""
    base = node.bases[0].id
    attrs = {}
    for stmt in node.body:
        if isinstance(stmt, ast.Assign) and len(stmt.targets) == 1:
            attrs[stmt.targets[0].id] = ast.literal_eval(stmt.value)
    return base, attrs


def _user_class(nodes, ident, name):
    """The caller's class for a node id, if it gives one."""
    if nodes is None:
        return None
    if isinstance(nodes, dict):
        return nodes.get(ident)
    return getattr(nodes, name, None) or getattr(nodes, ident, None)


def leaf_classes(data, nodes=None):
    """`(node id, class)` pairs in the order the tree refers to them."""
    names = data.literals.get("NODE_CLASS_NAMES", {})
    out = []
    for ident, cls in data.classes:
        user = _user_class(nodes, ident, names.get(ident, cls))
        if user is not None:
            out.append((ident, user))
        elif cls in data.defined:
            base, attrs = data.defined[cls]
            out.append((ident, type(cls, (_BASES[base],), dict(attrs))))
        else:
            out.append((ident, getattr(btc_runtime, cls)))
    return out


def world(data):
    return btc_runtime.World(**data.world)


def plan(data):
    return btc_runtime.Plan(data.shapes, data.steps)


def build(data, nodes=None, the_plan=None):
    """The root behaviour of the tree."""
    return btc_runtime.build_tree(
        data.root, data.trees, leaf_classes(data, nodes), the_plan or plan(data)
    )
