"""The command line shared by the DVC stage scripts under ``stages/``, and the exit statuses
of every vnrrt command (stage scripts and the ``vnrrt`` CLI; :data:`EXIT_HELP`, shown by
their ``--help``).
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import traceback
import zipfile
from collections.abc import Callable
from pathlib import Path

EXIT_OK, EXIT_BUDGET, EXIT_INPUT, EXIT_INTERNAL = 0, 1, 2, 3
EXIT_HELP = """\
Exit status: 0 success; 1 the planner stopped on a budget (vnrrt plan only); 2 bad
configuration, input or service (a missing or malformed file, a wrong value, an unreachable
tracking store): one line on stderr naming it; 3 an internal error (a bug): the traceback,
then one line saying so. Ctrl-C or SIGTERM ends the command as Python does (130 in a shell).
VNRRT_TRACEBACK=1 also prints the traceback of a status-2 error."""
# Exceptions that mean bad configuration or input, not a bug: every vnrrt error type is a
# ValueError; files that are missing, unreadable or not archives; MLflow's errors (below).
INPUT_ERRORS = (ValueError, FileNotFoundError, IsADirectoryError, NotADirectoryError,
                PermissionError, zipfile.BadZipFile)  # fmt: skip


def is_input_error(err: BaseException) -> bool:
    """Whether ``err`` is bad configuration, input or service (:data:`INPUT_ERRORS`, or an
    ``MlflowException`` of the tracking store) rather than an internal error."""
    mlflow_errors = sys.modules.get("mlflow.exceptions")  # never imported: no MLflow error
    mlflow_error = mlflow_errors is not None and isinstance(err, mlflow_errors.MlflowException)
    return isinstance(err, INPUT_ERRORS) or mlflow_error


def first_line(err: BaseException) -> str:
    """The first line of ``err``'s message (its type name when it has none)."""
    text = str(err).strip()
    return text.splitlines()[0] if text else type(err).__name__


def run_reporting(prog: str, fn: Callable[[], int]) -> int:
    """``fn()``'s exit status, or that of the exception it raised (:data:`EXIT_INPUT` or
    :data:`EXIT_INTERNAL`), reported on stderr as :data:`EXIT_HELP` says; interrupts
    propagate."""
    try:
        return fn()
    except Exception as err:
        if is_input_error(err):
            if os.environ.get("VNRRT_TRACEBACK") == "1":
                traceback.print_exc()
            print(f"{prog}: error: {first_line(err)}", file=sys.stderr)
            return EXIT_INPUT
        traceback.print_exc()
        print(f"{prog}: internal error ({type(err).__name__}: {first_line(err)}); this is a "
              "bug, please report it with the traceback above", file=sys.stderr)  # fmt: skip
        return EXIT_INTERNAL


def stage_main(
    stage: str,
    fn: Callable,
    doc: str,
    arg: str | None = None,
    arg_type: type = int,
    arg_help: str = "",
    more: tuple[tuple[str, type, str], ...] = (),
) -> None:
    """Parse ``[--<arg> VALUE] [--params params.yaml]``, log at INFO, run ``fn(params)`` or
    ``fn(params, value)`` and exit with its status (:data:`EXIT_HELP`). ``more``: further
    ``(name, type, help)`` arguments after ``arg`` (a ``matrix`` stage, named
    ``stage@<value>-<value>``), passed to ``fn`` in order. ``params`` holds only what
    ``stage``'s entry in ``dvc.yaml`` (of the working directory, where DVC runs stages, else
    beside the parameters file) declares (:func:`vnrrt.config.restrict`)."""
    raw = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(description=doc, epilog=EXIT_HELP, formatter_class=raw)
    options = ([(arg, arg_type, arg_help)] if arg else []) + list(more)
    for option, kind, text in options:
        parser.add_argument(f"--{option}", type=kind, required=True, help=text)
    parser.add_argument("--params", default="params.yaml", help="composed parameters (DVC)")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    values = [getattr(args, option) for option, _, _ in options]
    name = f"{stage}@{'-'.join(str(v) for v in values)}" if values else stage

    def run() -> int:
        from vnrrt.config import (
            check_unchanged_since_validate,
            load_params,
            restrict,
            stage_params,
        )

        params = Path(args.params)
        if os.environ.get("DVC_STAGE") and stage != "validate":  # run by dvc repro / exp run
            check_unchanged_since_validate(params, params.parent / "dvc.lock")
        cfg = load_params(params)
        dvc_yaml = Path("dvc.yaml") if Path("dvc.yaml").is_file() else params.parent / "dvc.yaml"
        view = restrict(cfg, stage_params(name, dvc_yaml))
        fn(view, *values)
        return EXIT_OK

    sys.exit(run_reporting(f"stage {name}", run))
