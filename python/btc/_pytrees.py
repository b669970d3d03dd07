"""A compiled tree's py_trees behaviours, built in-process.

The module btc writes for `--emit pytrees --runtime import` is the tree as
data (the world, the plan's steps, the leaf classes, the rule trees, the
root) over btc's py_trees runtime. btc's extension reads that text as
data (each assignment's value is a Python literal), so no generated code
runs. Leaf classes come from the caller's `nodes` where it
names them (a module or a mapping of node id -> class) and are btc's own
otherwise: simulated actions, and conditions that evaluate the formula the
rules define on the knowledge base.
"""

from . import btc_runtime

_BASES = {"Action": btc_runtime.Action, "Condition": btc_runtime.Condition}


class TreeData:
    """What a generated module holds, as values: `world` (the keywords of
    its `World`), `classes` (`(node id, class name)` pairs), `defined`
    (class name -> `(base, attributes)` of the leaf classes it defines)
    and `literals` (`SHAPES`, `STEPS`, `TREES`, `ROOT`, ...). btc's
    extension reads them from the module's text (`btc._btc._module_data`)."""

    def __init__(self, world, classes, defined, literals):
        self.world = world
        self.classes = classes
        self.defined = defined
        self.literals = literals
        self.shapes = literals["SHAPES"]
        self.steps = literals["STEPS"]
        self.trees = literals["TREES"]
        self.root = literals["ROOT"]
        self.step_nodes = literals.get("STEP_NODES", ())
        self.max_ticks = literals.get("MAX_TICKS", 10000)


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
            out.append((ident, _defined_class(cls, base, attrs)))
        else:
            out.append((ident, getattr(btc_runtime, cls)))
    return out


_DEFINED = {}


def _defined_class(name, base, attrs):
    """The class a module defines, made once per content: an agent builds a
    tree per plan from the same rules, and a class made anew each time
    would be a new type to every `isinstance` and `issubclass` cache."""
    key = (name, base, tuple(sorted(attrs.items())))
    try:
        return _DEFINED[key]
    except KeyError:
        cls = _DEFINED[key] = type(name, (_BASES[base],), dict(attrs))
        return cls


def world(data):
    return btc_runtime.World(**data.world)


def plan(data):
    return btc_runtime.Plan(data.shapes, data.steps)


def build(data, nodes=None, the_plan=None):
    """The root behaviour of the tree."""
    return btc_runtime.build_tree(
        data.root,
        data.trees,
        leaf_classes(data, nodes),
        the_plan or plan(data),
        data.step_nodes,
    )
