"""The test tree itself: pytest (prepend import mode) cannot collect two test modules with the same
basename in one run, so a duplicate would silently break the full suite on some runs."""

from __future__ import annotations

from collections import Counter
from pathlib import Path


def test_test_module_basenames_are_unique():
    root = Path(__file__).parent
    names = Counter(p.name for p in root.rglob("test_*.py") if "data" not in p.relative_to(root).parts)
    assert [name for name, count in names.items() if count > 1] == []
