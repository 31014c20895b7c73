"""Fixtures shared by the tests (helpers live in tests/helpers.py)."""

from __future__ import annotations

import pytest

from mechc.cli.main import main


@pytest.fixture
def cli(capsys):
    """Run ``mechc ARGS`` in-process; returns (exit status, stdout, stderr)."""

    def run(*args: str):
        code = main([str(a) for a in args])
        out, err = capsys.readouterr()
        return code, out, err

    return run
