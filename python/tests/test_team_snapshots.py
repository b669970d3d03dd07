"""Snapshot tests of a team's own trees with syrupy, through the `btc`
package: the example docs/testing.md shows, run on the bundled examples.
`pytest --snapshot-update` rewrites `__snapshots__/` after a reviewed
change; a rules change that alters a tree fails here with syrupy's diff."""

import pathlib

import pytest

import btc

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples"
CASES = sorted(
    (folder.name, plan.name)
    for folder in EXAMPLES.iterdir()
    if (folder / "rules.btrules").exists()
    for plan in folder.iterdir()
    if plan.suffix in (".plan", ".tplan") or plan.name == "plan.txt"
)


@pytest.mark.parametrize(("example", "plan"), CASES)
def test_tree(example, plan, snapshot):
    project = btc.Project(EXAMPLES / example / "rules.btrules")
    tree = project.compile(btc.Plan.parse((EXAMPLES / example / plan).read_text()))
    assert tree.to_mermaid() == snapshot(name="mermaid")
    assert tree.to_btcpp_xml() == snapshot(name="btcpp")
