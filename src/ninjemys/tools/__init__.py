"""Command-line tools: one module per command, each exposing ``main(argv) -> int``.

Shared plumbing (error reporting, exit codes) lives in :mod:`ninjemys.tools.cli`.
"""
