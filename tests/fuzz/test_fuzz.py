"""The short form of ``make fuzz``: every parser of untrusted input takes 2,000 mutated inputs (fixed
seed) and raises nothing but its documented error, within a time limit per input. The long form
(``make fuzz``, 100,000 inputs per parser, under a memory limit) is tests/fuzz/run_fuzz.py."""

from __future__ import annotations

import logging
import signal
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from targets import Mutator, Target, check, targets  # noqa: E402

COUNT = 2000
ALL = targets()


class _Hang(Exception):
    pass


def _alarm(_signum: int, _frame: object) -> None:
    raise _Hang("no result within 10 s")


@pytest.mark.parametrize("target", ALL, ids=[t.name for t in ALL])
def test_parser_takes_mutated_input_without_an_unexpected_exception(target: Target, caplog) -> None:  # noqa: ANN001
    caplog.set_level(logging.CRITICAL)
    mutator = Mutator(target.seeds, seed=7)
    previous = signal.signal(signal.SIGALRM, _alarm)
    findings = []
    try:
        for i in range(COUNT):
            data = mutator.next()
            signal.alarm(10)  # a hang never ends; a loaded CI machine can be slow
            try:
                exc = check(target, data)
            except _Hang as hang:
                exc = hang
            finally:
                signal.alarm(0)
            if exc is not None:
                findings.append(f"input {i}: {type(exc).__name__}: {exc}")
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert not findings, f"{len(findings)} of {COUNT} inputs escaped: {findings[:3]}"


def test_the_mutator_is_deterministic_and_reaches_far() -> None:
    seeds = [b"<launch><arg name='a' default='1'/></launch>"]
    a, b = Mutator(seeds, seed=3), Mutator(seeds, seed=3)
    first = [a.next() for _ in range(200)]
    assert first == [b.next() for _ in range(200)]
    assert len(set(first)) > 150  # mostly distinct inputs
    assert any(len(x) < len(seeds[0]) // 2 for x in first) and any(len(x) > len(seeds[0]) for x in first)
