#!/usr/bin/env python3
"""Writes two lines to stdout and one to stderr, then exits 0 (for the output pass-through tests)."""

import sys

sys.stdout.write("out line 1\nout line 2\n")
sys.stdout.flush()
sys.stderr.write("err line 1\n")
sys.stderr.flush()
