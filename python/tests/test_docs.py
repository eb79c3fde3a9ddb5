"""The Python examples of the README and of docs/python.md run as printed, and print what the page
shows of scx's own lines (the scene's and the analysis's)."""

from __future__ import annotations

import contextlib
import io
import re

import pytest
from conftest import REPO


def python_blocks(text: str) -> list:
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def run(code: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "<example>", "exec"), {"__name__": "__example__"})
    return out.getvalue()


def test_the_readmes_example_runs(tmp_path, monkeypatch):
    pytest.importorskip("pandas")
    pytest.importorskip("scipy")
    readme = (REPO / "README.md").read_text()
    tour = readme.split("<!-- BEGIN python tour")[1].split("<!-- END python tour")[0]
    (code,) = python_blocks(tour)
    monkeypatch.chdir(tmp_path)
    out = run(code)
    assert "continuous_mutual_information" in out


def test_the_worked_example_of_docs_python_runs_and_prints_what_the_page_shows(tmp_path, monkeypatch):
    for module in ("pandas", "scipy", "trimesh"):
        pytest.importorskip(module)
    page = (REPO / "docs" / "python.md").read_text()
    blocks = python_blocks(page)
    assert blocks, "docs/python.md has no python example"
    monkeypatch.chdir(tmp_path)
    out = "".join(run(code) for code in blocks)
    shown = page.split("```text\n", 1)[1].split("```", 1)[0]
    for line in shown.splitlines():
        if line.startswith("<scx."):
            assert line in out.splitlines(), (line, out)
    assert (tmp_path / "room.png").exists()
