"""The ``mechc`` command line: argument parsing and one call per command."""

from mechc.cli.main import main

__all__ = ["main"]
