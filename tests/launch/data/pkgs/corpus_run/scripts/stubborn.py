#!/usr/bin/env python3
"""Ignores SIGINT (a node that hangs at shutdown): only SIGTERM/SIGKILL stop it."""

import signal

signal.signal(signal.SIGINT, signal.SIG_IGN)
print("stubborn ready", flush=True)
while True:
    signal.pause()
