"""``make fuzz``: every target of :mod:`targets` for N mutated inputs (default 100,000 each).

Each target runs in its own process under a 1 GiB address-space limit (a parser that allocates what
a lying length field asks for dies with MemoryError and is reported) and a per-input time limit of
2 s (a hang is reported with the input's index). Exit status 1 when anything unexpected escaped.
Reproduce a finding with ``--target NAME --only INDEX`` (same seed, same input).

Run: ``.venv/bin/python tests/fuzz/run_fuzz.py [--count N] [--seed S] [--target NAME ...]``.
"""

from __future__ import annotations

import argparse
import collections
import multiprocessing
import resource
import signal
import sys
import time
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

PER_INPUT_SECONDS = 2
MEMORY_LIMIT = 1 << 30


class Hang(Exception):
    pass


def _alarm(_signum: int, _frame: object) -> None:
    raise Hang(f"no result within {PER_INPUT_SECONDS} s")


def run_target(name: str, count: int, seed: int, only: int | None, out: multiprocessing.Queue) -> None:
    import logging

    from targets import Mutator, check, targets

    logging.disable(logging.CRITICAL)  # parsers log what they work around; the counts are what matter
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    signal.signal(signal.SIGALRM, _alarm)
    target = next(t for t in targets() if t.name == name)
    mutator = Mutator(target.seeds, seed=seed)
    findings: collections.Counter = collections.Counter()
    examples: dict = {}
    start = time.monotonic()
    for i in range(count):
        data = mutator.next()
        if only is not None and i != only:
            continue
        signal.alarm(PER_INPUT_SECONDS)
        try:
            exc = check(target, data)
        except Hang as hang:
            exc = hang
        finally:
            signal.alarm(0)
        if exc is not None:
            last = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
            where = f"{last.filename.split('/src/')[-1]}:{last.lineno}" if last else "?"
            key = f"{type(exc).__name__} at {where}"
            findings[key] += 1
            examples.setdefault(key, (i, str(exc)[:160]))
    out.put((name, count, time.monotonic() - start, dict(findings), examples))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--target", action="append", default=[])
    parser.add_argument("--only", type=int, default=None, help="run just this input index (reproduce)")
    opts = parser.parse_args(argv)
    from targets import targets

    names = opts.target or [t.name for t in targets()]
    bad = 0
    for name in names:
        queue: multiprocessing.Queue = multiprocessing.Queue()
        proc = multiprocessing.Process(
            target=run_target, args=(name, opts.count, opts.seed, opts.only, queue)
        )
        proc.start()
        proc.join()
        if queue.empty():
            print(f"{name:15s} the fuzzing process died (exit {proc.exitcode})")
            bad += 1
            continue
        name, count, seconds, findings, examples = queue.get()
        total = sum(findings.values())
        print(f"{name:15s} {count:8d} inputs in {seconds:7.1f} s: {total} unexpected")
        for key, n in sorted(findings.items(), key=lambda kv: -kv[1]):
            index, text = examples[key]
            print(f"    {n:6d} x {key}  (first: input {index}: {text})")
        bad += bool(total)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
