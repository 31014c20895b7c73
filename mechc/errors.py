"""Errors a user can cause, each with an exit status and a one-line message.

The CLI catches :class:`MechcError` and prints ``str(err)``; anything else is a bug in mechc and
is reported as such (still without dumping a traceback unless ``MECHC_DEBUG`` is set).
"""

from __future__ import annotations

from pathlib import Path

EXIT_OK = 0
EXIT_FAILED = 1  # a proof or design check failed
EXIT_USAGE = 2  # bad input: spec syntax, unknown file, inconsistent options
EXIT_INTERNAL = 3


class MechcError(Exception):
    exit_code = EXIT_USAGE


class SpecError(MechcError):
    """A problem in an input file, located by file, line and column (1-based)."""

    def __init__(self, path: str, line: int, col: int, message: str):
        self.path, self.line, self.col, self.message = path, line, col, message
        super().__init__(f"{path}:{line}:{col}: error: {message}")


class UsageError(MechcError):
    """Bad command-line use or an unreadable/invalid file that has no line to point at."""


class DesignError(MechcError):
    """The design cannot be built as asked (e.g. a failed design check)."""

    exit_code = EXIT_FAILED


def read_input(path: str | Path, expected: str, what: str = "file") -> bytes:
    """The bytes of a file the user named; a file that cannot be read has no line or column to
    point at, so each I/O problem is a one-line UsageError naming the file."""
    try:
        return Path(path).read_bytes()
    except FileNotFoundError:
        raise UsageError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise UsageError(f"{path}: is a directory, expected {expected}") from None
    except OSError as e:
        raise UsageError(f"{path}: cannot read {what}: {e.strerror or e}") from None
