#!/usr/bin/env python3
"""Deliberately not executable: rosrun/roslaunch must say chmod +x."""
