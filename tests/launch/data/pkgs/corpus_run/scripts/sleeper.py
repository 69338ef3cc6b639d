#!/usr/bin/env python3
"""Prints its name, then sleeps until SIGINT/SIGTERM (like a well-behaved node)."""

import signal
import sys

name = next((a.split(":=", 1)[1] for a in sys.argv if a.startswith("__name:=")), "sleeper")
print(f"{name} ready", flush=True)
try:
    signal.pause()
except KeyboardInterrupt:
    sys.exit(0)
