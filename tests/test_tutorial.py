"""docs/tutorial.md, run as a new user would: its spec saved as printed, every ``$ mechc``
command of its console blocks run in a fresh directory, each shown output line found in the
real output (in order; times in seconds may differ, ``...`` skips lines), and the pictures it
shows equal to the files its draw commands write."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "tutorial.md"


def _blocks(kind: str) -> list[str]:
    return re.findall(rf"```{kind}\n(.*?)```", DOC.read_text(), re.S)


def _steps() -> list[tuple[list[str], list[str]]]:
    """(command words, output lines shown) for every '$ mechc' line of the console blocks."""
    steps = []
    for block in _blocks("console"):
        for line in block.splitlines():
            if line.startswith("$ "):
                steps.append((shlex.split(line[2:]), []))
            else:
                steps[-1][1].append(line)
    return steps


def _norm(line: str) -> str:
    """Seconds vary from run to run: '0.22 s' and '9.129 s' both read 'T s'; a file's size in
    KB follows every change of the drawing and reads 'N KB'."""
    line = re.sub(r"\d+(\.\d+)? s\b", "T s", line.rstrip())
    return re.sub(r"\d+ KB\b", "N KB", line)


def _shown_in(shown: list[str], got: str) -> None:
    lines = [_norm(x) for x in got.splitlines()]
    at = 0
    for want in shown:
        if want == "...":
            continue
        want = _norm(want)
        assert want in lines[at:], f"tutorial shows {want!r}; the command printed:\n{got}"
        at = lines.index(want, at) + 1


def test_the_tutorial_runs_as_printed(cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = _blocks("bool")
    assert len(spec) == 1
    Path("alarm.bool").write_text(spec[0])
    # the misspelt copy the tutorial describes: 'armed' as 'armd' on line 5
    lines = spec[0].splitlines(keepends=True)
    assert lines[4].endswith("& armed\n")
    lines[4] = lines[4].replace("& armed\n", "& armd\n")
    Path("typo.bool").write_text("".join(lines))
    steps = _steps()
    assert [s[0][:2] for s in steps] == [["mechc", "compile"]] * 3 + [
        ["mechc", "simulate"], ["mechc", "draw"], ["mechc", "draw"]]
    for words, shown in steps:
        code, out, err = cli(*words[1:])
        expect_error = any("error:" in s for s in shown)
        assert code == (2 if expect_error else 0), err
        _shown_in(shown, err if expect_error else out)
        if expect_error:
            assert not Path("typo.json").exists()  # nothing written for a bad spec
    # the pictures in the doc are the files the commands wrote, byte for byte
    pictures = re.findall(r"!\[[^\]]*\]\((tutorial/[\w.-]+\.svg)\)", DOC.read_text())
    assert pictures == ["tutorial/alarm.svg", "tutorial/alarm-on.svg"]
    for pic in pictures:
        assert (DOC.parent / pic).read_bytes() == (tmp_path / Path(pic).name).read_bytes(), (
            f"docs/{pic} is not what the tutorial's command draws: redraw it")
