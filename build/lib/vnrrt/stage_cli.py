"""The command line shared by the DVC stage scripts under ``stages/``."""

from __future__ import annotations

import argparse
import logging
from collections.abc import Callable
from pathlib import Path


def stage_main(
    stage: str,
    fn: Callable,
    doc: str,
    arg: str | None = None,
    arg_type: type = int,
    arg_help: str = "",
) -> object:
    """Parse ``[--<arg> VALUE] [--params params.yaml]``, log at INFO and return
    ``fn(params)`` or ``fn(params, value)``, where ``params`` holds only what ``stage``'s
    entry in ``dvc.yaml`` (of the working directory, where DVC runs stages, else beside the
    parameters file) declares (:func:`vnrrt.config.restrict`)."""
    from vnrrt.config import load_params, restrict, stage_params

    parser = argparse.ArgumentParser(description=doc)
    if arg:
        parser.add_argument(f"--{arg}", type=arg_type, required=True, help=arg_help)
    parser.add_argument("--params", default="params.yaml", help="composed parameters (DVC)")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    params = Path(args.params)
    cfg = load_params(params)
    name = stage if not arg else f"{stage}@{getattr(args, arg)}"
    dvc_yaml = Path("dvc.yaml") if Path("dvc.yaml").is_file() else params.parent / "dvc.yaml"
    view = restrict(cfg, stage_params(name, dvc_yaml))
    if arg:
        return fn(view, getattr(args, arg))
    return fn(view)
