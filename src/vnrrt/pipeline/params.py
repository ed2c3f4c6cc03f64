"""``python -m vnrrt.pipeline.params [--out params.yaml] [overrides...]``: compose ``conf/``
with Hydra overrides exactly as DVC does, validate it (:mod:`vnrrt.pipeline.validate`) and
print it, or write it atomically with ``--out``; a failed composition or validation leaves
``--out`` untouched and exits 2 with one line naming the problem."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from vnrrt.config import ConfigError, compose, dump


def main(argv: list[str] | None = None) -> int:
    """The command line (module doc); returns the exit status."""
    from hydra.errors import HydraException

    from vnrrt.pipeline.validate import validate_config

    parser = argparse.ArgumentParser(prog="python -m vnrrt.pipeline.params", description=__doc__)
    parser.add_argument("--out", type=Path, help="write here (atomically) instead of stdout")
    parser.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. scale=smoke")
    args = parser.parse_args(argv)
    try:
        cfg = compose(args.overrides)
        validate_config(cfg)
    except (HydraException, ConfigError, ValueError) as err:
        print(f"vnrrt.pipeline.params: error: {err}".splitlines()[0], file=sys.stderr)
        return 2
    if args.out is None:
        sys.stdout.write(dump(cfg))
    else:
        from vnrrt.infra.io import write_text

        write_text(args.out, dump(cfg))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
