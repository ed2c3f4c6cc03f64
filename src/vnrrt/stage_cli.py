"""The command line shared by the DVC stage scripts under ``stages/``."""

from __future__ import annotations

import argparse
import logging
from collections.abc import Callable


def stage_main(fn: Callable, doc: str, arg: str | None = None, arg_type: type = int,
               arg_help: str = "") -> object:  # fmt: skip
    """Parse ``[--<arg> VALUE] [--params params.yaml]``, log at INFO and return
    ``fn(params)`` or ``fn(params, value)`` (``params``: the composed parameters)."""
    from vnrrt.config import load_params

    parser = argparse.ArgumentParser(description=doc)
    if arg:
        parser.add_argument(f"--{arg}", type=arg_type, required=True, help=arg_help)
    parser.add_argument("--params", default="params.yaml", help="composed parameters (DVC)")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    cfg = load_params(args.params)
    if arg:
        return fn(cfg, getattr(args, arg))
    return fn(cfg)
