"""Type stubs of btc's native module (re-exported by ``btc``)."""

import os
from typing import Any, Callable, Union

import py_trees

from . import btc_runtime

StrPath = Union[str, "os.PathLike[str]"]

__version__: str

class BtcError(Exception):
    """Bad input: ``diagnostics`` says what and where."""

    diagnostics: list[Diagnostic]

class Diagnostic:
    code: str
    severity: str
    message: str
    path: str
    line: int
    column: int
    end_line: int
    end_column: int
    hint: str | None
    fixes: list[tuple[str, str, int, int, int, int, str]]

class Step:
    action: str
    args: list[str]
    time: float | None
    duration: float | None

class Plan:
    @staticmethod
    def parse(text: str) -> Plan: ...
    @property
    def steps(self) -> list[Step]: ...
    @property
    def cost(self) -> float | None: ...
    def __len__(self) -> int: ...

class Tree:
    def to_btcpp_xml(self) -> str: ...
    def to_json(self) -> str: ...
    def to_mermaid(self) -> str: ...
    def to_dot(self) -> str: ...
    def pytrees_module(self) -> str: ...
    def to_py_trees(self, nodes: object | None = None) -> py_trees.behaviour.Behaviour: ...
    def knowledge_base(
        self, ticks_per_action: int = 1, ms_per_tick: int = 10
    ) -> btc_runtime.KnowledgeBase: ...
    @property
    def steps(self) -> list[str]: ...

class Project:
    def __init__(self, path: StrPath) -> None: ...
    @staticmethod
    def from_texts(*, rules: str, domain: str, problem: str | None = None) -> Project: ...
    def check(self) -> list[Diagnostic]: ...
    def plan(self, problem: StrPath | None = None) -> Plan: ...
    def compile(self, plan: Plan, problem: StrPath | None = None) -> Tree: ...
    def _run_agent(
        self,
        execute: Callable[[dict[str, Any]], dict[str, Any]],
        problem: StrPath | None = None,
        max_replans: int = 5,
        max_ticks: int = 100000,
    ) -> str: ...

def plan(domain: StrPath, problem: StrPath) -> Plan: ...
def _main(args: list[str]) -> int: ...
def _module_data(text: str) -> dict[str, Any]: ...
