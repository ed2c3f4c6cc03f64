"""The README's and docs/library.md's examples work as written: each page's Python blocks run
in order (a block that reads pipeline outputs runs when `make repro` has made them), and every
`vnrrt ...` line parses with the real command line; where its input files exist, it runs
and exits 0."""

import re
import shlex
from pathlib import Path

import pytest

from vnrrt.cli.main import build_parser, main
from vnrrt.search import any_angle_path

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", ROOT / "docs" / "library.md"]
PIPELINE_FILE = re.compile(r"(?:data|models)/[\w./-]+\.(?:npz|ckpt|map|scen)")


def _blocks(page: Path, lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", page.read_text(), flags=re.S)


def _missing(text: str) -> list[str]:
    return [p for p in PIPELINE_FILE.findall(text) if not (ROOT / p).is_file()]


def _commands() -> list[list[str]]:
    lines = [ln for page in PAGES for block in _blocks(page, "bash") for ln in block.splitlines()]
    return [shlex.split(line, comments=True) for line in lines if line.startswith("vnrrt ")]


def _run(page: Path) -> dict:
    """Run the page's Python blocks in order in one namespace; returns it."""
    blocks = _blocks(page, "python")
    assert blocks, f"{page.name} has no Python example"
    namespace: dict = {}
    for block in blocks:
        if not _missing(block):  # else it needs `make repro` first
            exec(compile(block, page.name, "exec"), namespace)
    return namespace


def test_the_readme_quick_start_reaches_the_exact_optimum(monkeypatch):
    monkeypatch.chdir(ROOT)
    ns = _run(ROOT / "README.md")
    _, exact = any_angle_path(ns["grid"], ns["start"], ns["goal"])  # independent reference
    result, fastest = ns["result"], ns["fastest"]
    assert isinstance(result, ns["PlanResult"]) and result.planner == "vnrrt_star"
    assert result.success and exact - 1e-9 <= result.cost <= 1.01 * exact + 1e-9
    assert fastest.success and fastest.cost >= exact - 1e-9


def test_the_library_examples_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    ns = _run(ROOT / "docs" / "library.md")  # the blocks assert their own results
    assert ns["first"].success and ns["first"].cost >= ns["exact"] - 1e-9


@pytest.mark.parametrize("argv", _commands(), ids=lambda a: " ".join(a[1:4]))
def test_the_command_lines_parse_and_run_where_their_inputs_exist(argv, monkeypatch, tmp_path):
    args = build_parser().parse_args(argv[1:])  # an unknown option or choice fails here
    assert callable(args.func)
    if _missing(" ".join(argv)):
        pytest.skip("reads pipeline outputs: run `make repro` first")
    monkeypatch.chdir(tmp_path)  # outputs (--out) land here; inputs are read from the repo
    absolute = [str(ROOT / a) if PIPELINE_FILE.fullmatch(a) else a for a in argv[1:]]
    assert main(absolute) == 0
