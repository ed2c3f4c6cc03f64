"""The README and ``docs/`` say what the committed reports say, and their commands work as
written: generated tables equal their rendering from ``reports/cpu``; every number of the
prose and tables is in a file its section links; every shell command names a real make
target, DVC stage, parameter override, module, script option or ``vnrrt`` option.
(``tests/test_readme.py`` runs the Python examples and the ``vnrrt`` lines.)"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
import yaml

from tests.docs_tables import (
    PAGES,
    ROOT,
    TABLES,
    block,
    broken_links,
    generated,
    unsourced_numbers,
)

# docs/architecture.md is written and checked with the code layout (tests of the layout).
CHECKED = [p for p in PAGES if p.name != "architecture.md"]
OTHER_TOOLS = {"dvc", "mlflow", "sbatch", "srun", "sinfo", "grep", "export", "eval", ".", "bash"}


def _ids(pages: list[Path]) -> list[str]:
    return [str(p.relative_to(ROOT)) for p in pages]


def test_the_readme_has_the_generated_answer():
    names = generated((ROOT / "README.md").read_text())
    assert {"headline", "oracle"} <= set(names)


@pytest.mark.parametrize("page", CHECKED, ids=_ids(CHECKED))
def test_generated_tables_equal_their_rendering_from_the_reports(page):
    text = page.read_text()
    for name in generated(text):
        assert block(text, name) == TABLES[name](), (
            f"{page.name}: table '{name}' differs from reports/cpu; "
            "run `python -m tests.docs_tables` after a new CPU-scale run"
        )


@pytest.mark.parametrize("page", CHECKED, ids=_ids(CHECKED))
def test_every_link_names_a_file_here(page):
    assert broken_links(page) == []


@pytest.mark.parametrize("page", CHECKED, ids=_ids(CHECKED))
def test_every_number_is_in_a_file_its_section_links(page):
    assert unsourced_numbers(page) == []


def test_the_number_check_catches_a_changed_number(tmp_path):
    page = ROOT / "docs" / "results.md"
    text = page.read_text()
    assert "8.4x [5.3, 16.3]" in text
    docs = tmp_path / "docs"
    docs.mkdir()
    (tmp_path / "reports").symlink_to(ROOT / "reports")
    changed = docs / "results.md"
    changed.write_text(text.replace("8.4x [5.3, 16.3]", "8.4x [5.3, 163.7]"))
    assert unsourced_numbers(changed) == ["## What a perfect network could give: 163.7"]


def test_a_changed_report_changes_the_headline_rendering(tmp_path):
    reports = tmp_path / "cpu"
    (reports / "metrics").mkdir(parents=True)
    (reports / "metrics" / "headline.json").write_text(
        (ROOT / "reports/cpu/metrics/headline.json").read_text()
    )
    report = (ROOT / "reports/cpu/paper_comparison.md").read_text()
    (reports / "paper_comparison.md").write_text(report.replace("+69.3% [", "+61.3% [", 1))
    assert "+61.3% [" in TABLES["headline"](reports)
    assert TABLES["headline"](reports) != TABLES["headline"]()


def _commands(page: Path) -> list[list[str]]:
    """The page's shell commands (``bash`` blocks, continuation lines joined), as argv."""
    out = []
    for code in re.findall(r"```bash\n(.*?)```", page.read_text(), flags=re.S):
        for line in code.replace("\\\n", " ").splitlines():
            for part in re.split(r"\s&&\s", line):
                argv = shlex.split(part, comments=True)
                if argv:
                    out.append(argv)
    return out


COMMANDS = [(p, argv) for p in CHECKED for argv in _commands(p)]


def _stages() -> set[str]:
    """Every stage name of dvc.yaml, bare and with each foreach key (``train@vertexnet``)."""
    stages = yaml.safe_load((ROOT / "dvc.yaml").read_text())["stages"]
    names = set(stages)
    for name, stage in stages.items():
        keys = stage.get("foreach", [])
        keys = keys if isinstance(keys, list) else []
        names |= {f"{name}@{k}" for k in keys if isinstance(k, str | int)}
    return names


def _options(source: Path) -> set[str]:
    """The ``--options`` and subcommand names a script's argparse code defines."""
    text = source.read_text()
    return set(re.findall(r"[\"'](--[\w-]+)[\"']", text)) | set(
        re.findall(r"add_parser\(\s*[\"']([\w-]+)[\"']", text)
    )


def _module_file(name: str) -> Path:
    for base in (ROOT / "src" / Path(*name.split(".")), ROOT / Path(*name.split("."))):
        for path in (base.with_suffix(".py"), base / "__main__.py"):
            if path.is_file():
                return path
    raise AssertionError(f"no module {name} in src/ or the repository")


def _check_python(argv: list[str]) -> None:
    if argv[1] == "-m":
        source, args = _module_file(argv[2]), argv[3:]
    else:
        source, args = ROOT / argv[1], argv[2:]
        assert source.is_file(), f"no script {argv[1]}"
    options = _options(source)
    for arg in args:
        opt = arg.split("=", 1)[0]
        if opt.startswith("--"):
            assert opt in options, f"{source.name} has no option {opt}"


def _check_dvc(argv: list[str], capsys) -> None:
    from vnrrt.pipeline.params import main as compose

    words = [a for a in argv[2:] if not a.startswith("-")]
    if argv[1:3] == ["exp", "run"]:
        overrides = [argv[i + 1] for i, a in enumerate(argv) if a == "-S"]
        targets = [a for i, a in enumerate(argv[3:], 3) if not a.startswith("-")
                   and argv[i - 1] != "-S"]  # fmt: skip
        fixed = [o for o in overrides if "," not in o or "[" in o]
        sweeps = [o for o in overrides if o not in fixed] or ["="]
        for sweep in sweeps:  # a sweep 'k=a,b' composes each value with the fixed ones
            key, _, values = sweep.partition("=")
            for value in values.split(","):
                run = fixed + ([f"{key}={value}"] if key else [])
                assert compose(run) == 0, f"-S {' -S '.join(run)} does not compose"
        capsys.readouterr()
        assert set(targets) <= _stages(), f"unknown stage in {targets}"
    elif argv[1] in {"repro", "status", "commit"}:
        assert set(words) <= _stages(), f"unknown stage in {words}"
    elif argv[1:3] == ["metrics", "show"]:
        assert all((ROOT / w).is_file() for w in words[1:]), f"no file in {words}"


@pytest.mark.parametrize(("page", "argv"), COMMANDS, ids=[" ".join(a[:4]) for _, a in COMMANDS])
def test_every_command_names_what_exists(page, argv, capsys):
    program = argv[0].removeprefix(".venv/bin/")
    if program == "make":
        targets = re.findall(r"^([a-z0-9-]+):", (ROOT / "Makefile").read_text(), flags=re.M)
        assert set(argv[1:]) <= set(targets), f"{page.name}: no make target {argv[1:]}"
    elif program == "python":
        _check_python(argv)
    elif program == "vnrrt":
        from vnrrt.cli.main import build_parser

        assert callable(build_parser().parse_args(argv[1:]).func)
    elif program == "dvc":
        _check_dvc(["dvc", *argv[1:]], capsys)
    elif "/" in program:
        assert (ROOT / program).is_file(), f"{page.name}: no script {program}"
    else:
        assert program in OTHER_TOOLS | {"cp", "mkdir", "export"}, f"unchecked command {argv}"


def test_the_link_check_catches_missing_files_and_headings(tmp_path):
    (tmp_path / "other.md").write_text("# Title\n\n## The paper's claims\n")
    page = tmp_path / "page.md"
    page.write_text(
        "[a](other.md#the-papers-claims) [b](other.md#gone) [c](missing.md) [d](#here)\n"
        "## Here\n[e](https://example.org/x) `[f](in-code.md)`\n"
    )
    assert broken_links(page) == ["other.md#gone", "missing.md"]
