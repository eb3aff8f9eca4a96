"""Every test module has a name of its own: pytest's workers import test modules by their
base name (the tests have no __init__.py), and mypy checks tests/ as one tree, so two
`test_protocol.py` in two folders break both, and only under `make test`."""

from __future__ import annotations

from collections import Counter

from support import ROOT


def test_no_two_test_modules_share_a_name() -> None:
    names = Counter(path.name for path in (ROOT / "tests").rglob("test_*.py"))
    assert names, "no test module found under tests/"
    shared = sorted(name for name, count in names.items() if count > 1)
    assert not shared, f"test modules that share a name: {shared}; rename one of each"
