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


# ---- a real browser for the viewer's tests (tests/test_viewer.py) ------------------------------

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--no-first-run", "--disable-sync"]


def _install_chromium() -> str | None:
    """Install Debian's ``chromium`` once (root with apt-get, as on CI); None when installed,
    else why it cannot be. A lock file keeps parallel test workers from running apt twice."""
    import fcntl
    import os
    import shutil
    import subprocess

    if os.path.exists(CHROMIUM):
        return None
    if shutil.which("apt-get") is None or os.geteuid() != 0:
        return (f"{CHROMIUM} is missing and cannot be installed here (needs root and apt-get): "
                "apt-get install chromium")
    with open("/tmp/mechc-chromium-install.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # the first worker installs, the others wait
        if os.path.exists(CHROMIUM):
            return None
        env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
        for cmd in (["apt-get", "update", "-qq"],
                    ["apt-get", "install", "-y", "-qq", "--no-install-recommends", "chromium"]):
            r = subprocess.run(cmd, env=env, capture_output=True, text=True)
            if r.returncode != 0:
                return f"{' '.join(cmd)} failed: {(r.stderr or r.stdout).strip()[-300:]}"
    return None if os.path.exists(CHROMIUM) else f"apt-get installed no {CHROMIUM}"


@pytest.fixture(scope="session")
def browser():
    """Headless Chromium (the Debian package) driven by playwright, installed if missing."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:  # only outside `make install` (the test extra has it): say how
        pytest.skip("playwright is not installed (pip install -e '.[test]')")
    why = _install_chromium()
    if why:  # only where Chromium is missing and cannot be installed (not root, no apt)
        pytest.skip(why)
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()
