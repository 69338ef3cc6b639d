"""Bash completion for every ninjemys command: ``ninjemys.bash`` (see ninjemys.tools.complete)."""
