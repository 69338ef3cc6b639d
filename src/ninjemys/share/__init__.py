"""Data files ninjemys installs for the shell (bash completion); a package only so they ship as package data."""
