"""Unit tests of btc_runtime (`python3 -m unittest discover emit/python`).

The differential test in lang/tests/pytrees_diff.rs proves whole trees
against btc's engine; these pin the pieces: the type hierarchy, derived
predicates, numbers, effects and each control node's tick semantics.
"""

import unittest

import py_trees

import btc_runtime as rt

Status = py_trees.common.Status


def world(**kw):
    base = {
        "types": (("vehicle", ()), ("truck", ("vehicle",)), ("place", ())),
        "objects": (("t1", ("truck",)), ("v1", ("vehicle",)), ("p1", ("place",)), ("x", ())),
        "predicates": ("at", "busy", "free", "reach"),
    }
    base.update(kw)
    return rt.World(**base)


class TypesTest(unittest.TestCase):
    def test_quantifiers_range_over_subtypes(self):
        w = world()
        self.assertEqual(w.objects_of(("vehicle",)), ("t1", "v1"))
        self.assertEqual(w.objects_of(("truck",)), ("t1",))
        self.assertEqual(w.objects_of(()), ("t1", "v1", "p1", "x"))
        self.assertEqual(w.objects_of(("truck", "place")), ("t1", "p1"))
        kb = rt.KnowledgeBase(world(init=(("at", "t1", "p1"), ("at", "v1", "p1"))))
        every = (":forall", (("?v", ("vehicle",)),), ("at", "?v", "p1"))
        self.assertTrue(kb.holds(every))
        kb.apply((":del", ("at", "v1", "p1")))
        self.assertFalse(kb.holds(every))


class DerivedTest(unittest.TestCase):
    def test_strata_close_before_negation(self):
        # reach is the transitive closure of at; free negates reach.
        derived = (
            ("reach", (("?a", ()), ("?b", ())), ("at", "?a", "?b")),
            (
                "reach",
                (("?a", ()), ("?b", ())),
                (":exists", (("?c", ()),), (":and", ("at", "?a", "?c"), ("reach", "?c", "?b"))),
            ),
            ("free", (("?a", ()),), (":not", ("reach", "?a", "p1"))),
        )
        w = world(derived=derived, init=(("at", "t1", "v1"), ("at", "v1", "p1")))
        self.assertEqual([len(s) for s in w.strata], [2, 1])
        kb = rt.KnowledgeBase(w)
        self.assertTrue(kb.holds(("reach", "t1", "p1")))
        self.assertFalse(kb.holds(("free", "t1")))
        self.assertTrue(kb.holds(("free", "p1")))
        kb.apply((":del", ("at", "v1", "p1")))
        self.assertFalse(kb.holds(("reach", "t1", "p1")))
        self.assertTrue(kb.holds(("free", "t1")))
        # Derived atoms are not facts: a snapshot shows what was set.
        self.assertEqual(kb.snapshot(), ["(at t1 v1)"])


class NumbersTest(unittest.TestCase):
    def test_fluents_start_at_their_values_and_undefined_ones_fail(self):
        w = world(functions=("fuel",), values=((("fuel", "t1"), 10.0),))
        kb = rt.KnowledgeBase(w)
        self.assertTrue(kb.holds((":cmp", ">=", (":f", "fuel", "t1"), 10.0)))
        self.assertFalse(kb.holds((":cmp", "<", (":f", "fuel", "v1"), 1.0)))
        self.assertFalse(kb.holds((":cmp", ">=", (":f", "fuel", "v1"), 1.0)))
        kb.apply((":num", "decrease", ("fuel", "t1"), (":bin", "*", 2.0, 1.5)))
        kb.apply((":num", "increase", ("fuel", "v1"), 1.0))  # undefined: no change
        kb.apply((":num", "assign", ("fuel", "p1"), (":duration",)), {"?duration": 4.0})
        self.assertEqual(kb.snapshot(), ["(= (fuel p1) 4.0)", "(= (fuel t1) 7.0)"])

    def test_floats_print_as_btc_prints_them(self):
        self.assertEqual(rt.format_float(1.0), "1.0")
        self.assertEqual(rt.format_float(0.25), "0.25")
        self.assertEqual(rt.format_float(1e-05), "0.00001")
        self.assertEqual(rt.format_float(-3.0), "-3.0")


class EffectsTest(unittest.TestCase):
    def test_parts_see_the_state_before_and_deletes_come_first(self):
        kb = rt.KnowledgeBase(world(init=(("at", "t1", "p1"),)))
        kb.apply(
            (
                ":and",
                (":del", ("at", "t1", "p1")),
                ("at", "t1", "p1"),
                (":when", ("at", "t1", "p1"), ("busy", "t1")),
                (":forall", (("?v", ("vehicle",)),), ("free", "?v")),
            )
        )
        self.assertEqual(kb.snapshot(), ["(at t1 p1)", "(busy t1)", "(free t1)", "(free v1)"])


class Script(py_trees.behaviour.Behaviour):
    """A leaf that returns its statuses in turn (the last one repeats)."""

    def __init__(self, name, statuses):
        super().__init__(name=name)
        self.statuses = list(statuses)
        self.ticks = 0

    def update(self):
        s = self.statuses[min(self.ticks, len(self.statuses) - 1)]
        self.ticks += 1
        return s


def tick(root, kb=None, times=1):
    kb = kb or rt.KnowledgeBase(world())
    rt.put_kb(kb)
    for _ in range(times):
        kb.tick += 1
        for _node in root.tick():
            pass
    return root.status


class ControlTest(unittest.TestCase):
    def test_retry_tries_again_in_the_same_tick(self):
        leaf = Script("a", [Status.FAILURE, Status.FAILURE, Status.SUCCESS])
        self.assertEqual(tick(rt.Retry("r", leaf, 3)), Status.SUCCESS)
        self.assertEqual(leaf.ticks, 3)
        leaf = Script("a", [Status.FAILURE])
        self.assertEqual(tick(rt.Retry("r", leaf, 2)), Status.FAILURE)
        self.assertEqual(leaf.ticks, 2)

    def test_repeat_counts_successes(self):
        leaf = Script("a", [Status.SUCCESS])
        self.assertEqual(tick(rt.Repeat("r", leaf, 4)), Status.SUCCESS)
        self.assertEqual(leaf.ticks, 4)

    def test_timeout_reads_the_simulated_clock(self):
        leaf = Script("a", [Status.RUNNING])
        root = rt.Timeout("t", leaf, 25)
        kb = rt.KnowledgeBase(world(), ms_per_tick=10)
        self.assertEqual(tick(root, kb, 3), Status.RUNNING)
        self.assertEqual(tick(root, kb, 1), Status.FAILURE)
        self.assertEqual(leaf.status, Status.INVALID)

    def test_parallel_thresholds(self):
        kids = [
            Script("a", [Status.SUCCESS]),
            Script("b", [Status.RUNNING]),
            Script("c", [Status.FAILURE]),
        ]
        self.assertEqual(tick(rt.Parallel("p", 1, 1, children=kids)), Status.SUCCESS)
        kids = [Script("a", [Status.RUNNING, Status.SUCCESS]), Script("c", [Status.FAILURE])]
        self.assertEqual(tick(rt.Parallel("p", 2, 2, children=kids)), Status.FAILURE)

    def test_reactive_sequence_halts_the_others(self):
        cond = Script("c", [Status.SUCCESS, Status.SUCCESS, Status.FAILURE])
        act = Script("a", [Status.RUNNING])
        root = rt.ReactiveSequence(name="r", children=[cond, act])
        kb = rt.KnowledgeBase(world())
        self.assertEqual(tick(root, kb, 2), Status.RUNNING)
        self.assertEqual(tick(root, kb, 1), Status.FAILURE)
        self.assertEqual(act.status, Status.INVALID)


# A move from `?#1` to `?#2`: its start wants the first, its end makes it the
# second.
MOVE = (
    "move",
    ("at", "?#0", "?#1"),
    None,
    None,
    None,
    (":and", (":del", ("at", "?#0", "?#1")), ("at", "?#0", "?#2")),
)


class StepTest(unittest.TestCase):
    def test_a_step_applies_its_effects_once_and_records_its_events(self):
        shape = MOVE
        plan = rt.Plan((shape,), ((0, ("t1", "p1", "v1")),))
        w = world(init=(("at", "t1", "p1"),), goal=("at", "t1", "v1"))
        kb = rt.KnowledgeBase(w, plan)

        class Move(rt.Action):
            NODE_ID = "Move"

        root = rt.build_tree(("S", 0, ("L", 0, None, ())), (), (("Move", Move),), plan)
        result = rt.run(root, kb, 10)
        self.assertEqual(result.status, Status.SUCCESS)
        self.assertTrue(result.goal_reached)
        self.assertEqual(result.events, [(1, "start", 1), (2, "end", 1)])
        self.assertEqual(result.kb, ["(at t1 v1)"])

    def test_steps_that_name_a_shared_node_each_build_their_own(self):
        shape = MOVE
        plan = rt.Plan((shape,), ((0, ("t1", "p1", "v1")), (0, ("t1", "v1", "p1"))))
        w = world(init=(("at", "t1", "p1"),), goal=("at", "t1", "p1"))
        kb = rt.KnowledgeBase(w, plan)

        class Move(rt.Action):
            NODE_ID = "Move"

        spec = ("Q", None, (("S", 0, 0), ("S", 1, 0)))
        root = rt.build_tree(spec, (), (("Move", Move),), plan, (("L", 0, None, ()),))
        first, second = (s.children[0] for s in root.children)
        self.assertIsNot(first, second)
        self.assertEqual((first.step, second.step), (0, 1))
        result = rt.run(root, kb, 10)
        self.assertEqual(result.status, Status.SUCCESS)
        self.assertTrue(result.goal_reached)
        self.assertEqual(
            result.events, [(1, "start", 1), (2, "end", 1), (2, "start", 2), (3, "end", 2)]
        )

    def test_an_action_fails_when_its_step_cannot_start(self):
        shape = ("move", ("at", "?#0", "?#1"), None, None, None, None)
        plan = rt.Plan((shape,), ((0, ("t1", "v1")),))
        kb = rt.KnowledgeBase(world(), plan)

        class Move(rt.Action):
            NODE_ID = "Move"

        root = rt.build_tree(("S", 0, ("L", 0, None, ())), (), (("Move", Move),), plan)
        self.assertEqual(rt.run(root, kb, 10).status, Status.FAILURE)


if __name__ == "__main__":
    unittest.main()


class BlackboardClientsTest(unittest.TestCase):
    """A long-running agent builds a tree per plan: a tree's blackboard
    clients go when it is shut down or collected, and a run leaves none of
    its own."""

    def tree(self):
        step = rt.Plan(((("a",), None, None, None, None, None),), ((0, ()),))
        leaf = rt.Action("act", step=0)
        root = rt.PlanStep("step 1", rt.Timeout("limit", leaf, 1000), 0)
        return root, rt.KnowledgeBase(world(), step)

    def clients(self):
        return len(py_trees.blackboard.Blackboard.clients)

    def test_a_run_then_shutdown_leaves_no_client(self):
        before = self.clients()
        root, kb = self.tree()
        self.assertEqual(self.clients(), before + 3)
        result = rt.run(root, kb, 10)
        self.assertEqual(result.status, Status.SUCCESS)
        self.assertEqual(self.clients(), before + 3)
        py_trees.trees.BehaviourTree(root).shutdown()
        self.assertEqual(self.clients(), before)
        # Shutting down twice is harmless.
        py_trees.trees.BehaviourTree(root).shutdown()
        self.assertEqual(self.clients(), before)

    def built(self):
        """A tree as `build_tree` builds it: a step over a retry of a
        condition and an action, under a timeout."""
        shapes = (("a", None, None, None, None, None),)
        plan = rt.Plan(shapes, ((0, ()),))
        leaf = ("L", 0, None, ())
        cond = ("L", 1, None, ())
        root = ("S", 0, ("D", "timeout", 1000, None, ("Q", None, (cond, leaf))))
        classes = (("act", rt.Action), ("ok", rt.Condition))
        return rt.build_tree(root, (), classes, plan), rt.KnowledgeBase(world(), plan)

    def test_a_built_tree_shares_one_client(self):
        import gc

        before = self.clients()
        root, kb = self.built()
        self.assertEqual(self.clients(), before + 1)
        result = rt.run(root, kb, 10)
        self.assertEqual(result.status, Status.SUCCESS)
        py_trees.trees.BehaviourTree(root).shutdown()
        self.assertEqual(self.clients(), before)
        for _ in range(50):
            root, kb = self.built()
            rt.run(root, kb, 10)
        self.assertLessEqual(self.clients(), before + 50)
        del root, kb
        gc.collect()
        self.assertEqual(self.clients(), before)

    def test_a_dropped_tree_releases_its_clients(self):
        import gc

        before = self.clients()
        for _ in range(50):
            root, kb = self.tree()
            rt.run(root, kb, 10)
        del root, kb
        gc.collect()
        self.assertEqual(self.clients(), before)
