#!/usr/bin/env python3
"""Exits with code 3 after the number of seconds given as first argument (default 0)."""

import sys
import time

delay = float(sys.argv[1]) if len(sys.argv) > 1 and ":=" not in sys.argv[1] else 0.0
print("crasher running", flush=True)
time.sleep(delay)
sys.exit(3)
