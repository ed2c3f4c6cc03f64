"""The README's library and command-line examples work as written: its Python blocks run in
order (a block that reads pipeline outputs runs when `make repro` has made them), and every
`vnrrt ...` line parses with the real command line; where its input files exist, it runs
and exits 0."""

import re
import shlex
from pathlib import Path

import pytest

from vnrrt.cli.main import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
PIPELINE_FILE = re.compile(r"(?:data|models)/[\w./-]+\.(?:npz|ckpt)")


def _blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", README, flags=re.S)


def _missing(text: str) -> list[str]:
    return [p for p in PIPELINE_FILE.findall(text) if not (ROOT / p).is_file()]


def _commands() -> list[list[str]]:
    lines = [line for block in _blocks("bash") for line in block.splitlines()]
    return [shlex.split(line, comments=True) for line in lines if line.startswith("vnrrt ")]


def test_the_python_examples_run(monkeypatch, tmp_path):
    monkeypatch.chdir(ROOT)
    blocks = _blocks("python")
    assert blocks, "the README has no Python example"
    namespace: dict = {}
    ran = 0
    for block in blocks:
        if _missing(block):  # needs `make repro` first
            continue
        exec(compile(block, "README.md", "exec"), namespace)
        ran += 1
    assert ran >= 1
    result = namespace["result"]  # the first example plans to the exact optimum
    assert result.success and result.cost <= 1.01 * namespace["exact"] + 1e-9


@pytest.mark.parametrize("argv", _commands(), ids=lambda a: " ".join(a[1:4]))
def test_the_command_lines_parse_and_run_where_their_inputs_exist(argv, monkeypatch, tmp_path):
    args = build_parser().parse_args(argv[1:])  # an unknown option or choice fails here
    assert callable(args.func)
    if _missing(" ".join(argv)):
        pytest.skip("reads pipeline outputs: run `make repro` first")
    monkeypatch.chdir(tmp_path)  # outputs (--out) land here; inputs are read from the repo
    absolute = [str(ROOT / a) if PIPELINE_FILE.fullmatch(a) else a for a in argv[1:]]
    assert main(absolute) == 0
