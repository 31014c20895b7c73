"""Tolerance analysis: the yield of a design when every dimension is a little off and every
pin a little loose (Monte Carlo over samples solved together), which dimensions matter, and
each output's structural error. ``mechc tolerance`` (``mechc/cli/tolerance.py``) runs it."""
