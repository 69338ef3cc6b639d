#!/usr/bin/env python3
"""corpus placeholder node: exits at once (launch plans are compared, never run)."""
