"""Imported first by every stage script: the stage runs with the repository's virtual
environment even where ``python`` on the PATH is another interpreter (``.venv/bin/dvc exp
run`` without activating ``.venv``: DVC runs ``python stages/<stage>.py`` with the PATH's
``python``, which lacks vnrrt). Such a stage is run again, once, with ``.venv/bin/python``,
saying so in one line; without a ``.venv`` it ends with status 2 and one line saying what to
do. Standard library only: it runs before vnrrt can be imported."""

import importlib.util
import os
import sys
from pathlib import Path

VENV = Path(__file__).resolve().parents[1] / ".venv"
MARK = "VNRRT_STAGE_REEXEC"  # set for the run again: never a second time

if importlib.util.find_spec("vnrrt") is None:
    stage = f"stage {Path(sys.argv[0]).stem}"
    venv_python = VENV / "bin" / "python"
    if venv_python.is_file() and not os.environ.get(MARK):
        print(f"{stage}: {sys.executable} cannot import vnrrt; running with {venv_python} "
              "(activate .venv, or use `make repro`, to skip this)", file=sys.stderr)  # fmt: skip
        os.environ[MARK] = "1"
        os.execv(str(venv_python), [str(venv_python), *sys.argv])
    fix = "activate the virtual environment (`source .venv/bin/activate`) or use `make repro`"
    print(f"{stage}: error: {sys.executable} cannot import vnrrt: {fix}", file=sys.stderr)
    sys.exit(2)
