"""The stubs of qrm._qrm name what the module has, with the same parameters."""

import ast
import inspect
from pathlib import Path

import qrm
from qrm import _qrm

STUB = Path(qrm.__file__).with_name("_qrm.pyi")


def stub_functions():
    tree = ast.parse(STUB.read_text())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            yield node.name, None, node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and not item.name.startswith("__"):
                    yield item.name, node.name, item


def test_every_stub_matches_the_module():
    checked = 0
    for name, owner, node in stub_functions():
        target = getattr(getattr(_qrm, owner), name) if owner else getattr(_qrm, name)
        if isinstance(target, property) or not callable(target):
            continue
        stubbed = [a.arg for a in node.args.args if a.arg not in ("self", "cls")]
        actual = [
            p for p in inspect.signature(target).parameters if p not in ("self", "cls", "$self")
        ]
        assert stubbed == actual, f"{owner or ''}.{name}: stub {stubbed}, module {actual}"
        checked += 1
    assert checked >= 20


def test_the_module_has_nothing_unstubbed():
    stubbed = {name for name, owner, _ in stub_functions() if owner is None}
    public = {n for n in dir(_qrm) if not n.startswith("_") and callable(getattr(_qrm, n))}
    assert public - stubbed == {"Map", "QrmError", "ContradictionError"}
