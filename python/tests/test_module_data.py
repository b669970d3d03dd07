"""btc's reader of the py_trees modules it writes (`to_py_trees` builds
from what it reads) against Python's own parser: on every example's module
and on a fixture of the forms that need care, the same values; on text it
does not expect, a `ValueError` naming the line, never a crash."""

import ast
import pathlib

import pytest

import btc
from btc import _btc

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIXTURE = pathlib.Path(__file__).parent / "fixtures" / "generated_module.txt"
EXAMPLES = ["ariac", "nist_kitting", "p3_assembler", "two_robots"]
LITERALS = ("SHAPES", "STEPS", "TREES", "ROOT", "STEP_NODES", "MAX_TICKS", "NODE_CLASS_NAMES")


class _Floats(ast.NodeTransformer):
    """`float("inf")`, the one call the emitter writes in a value (a float
    that is not finite has no literal), as the constant it makes."""

    def visit_Call(self, node):
        if getattr(node.func, "id", None) == "float" and len(node.args) == 1:
            return ast.Constant(float(ast.literal_eval(node.args[0])))
        return self.generic_visit(node)


def by_python(text):
    """The module's data as Python's `ast` reads it: the reference."""
    world, classes, defined, literals = {}, [], {}, {}
    for node in _Floats().visit(ast.parse(text)).body:
        if isinstance(node, ast.ClassDef):
            attrs = {
                s.targets[0].id: ast.literal_eval(s.value)
                for s in node.body
                if isinstance(s, ast.Assign)
            }
            defined[node.name] = (node.bases[0].id, attrs)
        elif isinstance(node, ast.Assign):
            name = node.targets[0].id
            if name == "WORLD":
                world = {k.arg: ast.literal_eval(k.value) for k in node.value.keywords}
            elif name == "CLASSES":
                classes = [(ast.literal_eval(p.elts[0]), p.elts[1].id) for p in node.value.elts]
            elif name in LITERALS:
                literals[name] = ast.literal_eval(node.value)
    return {"world": world, "classes": classes, "defined": defined, "literals": literals}


def same(a, b):
    """Equal, with NaN equal to itself and types kept (a tuple is not a
    list, 1 is not 1.0 nor True)."""
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True
    if type(a) is not type(b):
        return False
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return a == b


@pytest.mark.parametrize("example", EXAMPLES)
def test_every_examples_module_reads_as_python_reads_it(example):
    project = btc.Project(ROOT / "examples" / example / "rules.btrules")
    text = project.compile(project.plan()).pytrees_module()
    assert same(_btc._module_data(text), by_python(text))


def test_the_forms_that_need_care_read_as_python_reads_them():
    text = FIXTURE.read_text()
    ours = _btc._module_data(text)
    assert same(ours, by_python(text))
    # The fixture has each form: the comparison cannot pass on nothing.
    assert ours["world"]["values"][2][1] == float("inf")
    assert "\U0001f916" in [o[0] for o in ours["world"]["objects"]]
    assert ours["defined"]["Grasp"][1]["FORMULA"][0] == ":or"
    assert ours["classes"][2] == ("Place", "Action")
    assert ours["literals"]["MAX_TICKS"] == 250
    assert ours["literals"]["STEP_NODES"] == (("C", 0, ("r1",)),)


@pytest.mark.parametrize(
    "text",
    [
        "ROOT = (",
        "ROOT = (\"L\", 0, None, (('robot', 1), ))",
        'SHAPES = ("unterminated)',
        'STEPS = ("\\q",)',
        'STEPS = ("\\x4",)',
        "TREES = {1: 2",
        "MAX_TICKS = 12abc",
        "WORLD = World(types=(), =1)",
        "CLASSES = ((1, Grasp),)",
        "class Grasp(Action):\n    NODE_ID\n",
        'class Grasp(Action):\n    """never closed\n',
        "ROOT = open('/etc/passwd')",
    ],
)
def test_text_it_does_not_expect_is_refused_with_its_line(text):
    with pytest.raises(ValueError, match="line"):
        _btc._module_data(text)
