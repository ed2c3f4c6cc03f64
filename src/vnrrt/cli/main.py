"""The vnrrt command line: plan with RRT*, NRRT*, VNRRT* or M-VNRRT*, and predict heatmaps
with a trained network.

  vnrrt plan --map FILE [--instance NAME|I] [--start X,Y --goal X,Y] [--planner P]
             [--heatmap FILE | --checkpoint CKPT [--pad]] [--tau T] [--stop initial|optimal]
             [--config NAME|FILE] [--set KEY=VALUE ...] [--out plan.png]
  vnrrt plan --map M.map --scen M.map.scen [--scen-rows 0,5,10-19] [--longest N]
             [--limit N] [--planner P --checkpoint CKPT] ...  (a batch: one row per query)
  vnrrt predict --checkpoint CKPT --map FILE [--instance NAME|I | --start X,Y --goal X,Y]
             [--pad] --out heatmap.npy|heatmap.png

Planner settings: --config user (the default: conf/planner/user.yaml, our fastest settings
with budgets scaled with the map's free cells), fastest, default (the paper's protocol) or a
planner YAML file; the output names the configuration and the budget it used.

Maps: .npy occupancy (H, W), nonzero = obstacle; .npz: a dataset shard or the pipeline's
named maps (with --instance, an index or a named map's name, e.g. u_trap); .png, read the
same at any bit depth (8 or 16 bits, gray, RGB or palette): an opaque image whose values are
all 0-3 is a class map (0 free, 1 obstacle, 2 start, 3 goal; a 0/1 occupancy image is one),
any other a picture whose dark pixels (gray level below half of white, transparent pixels
counting as white) are obstacles; .map, a MovingAI map (., G, S passable; @, O, T, W not),
with --scen its .scen queries (their cells' centres). Points are continuous (x, y) pixels;
the cells of class maps and shards give their centres. --pad runs a network on the map
padded with obstacles to multiples of its stride (32) and crops the heatmap back.
Heatmaps: .npy (H, W), a grayscale .png scaled to [0, 1], or a pipeline heatmap file (.npz,
with --instance and --network: it must be the heatmap of the --map instance and its own
start and goal cells). A network (--checkpoint, or --network of a pipeline file) must have
the target the planner samples: vertex for vnrrt_star and m_vnrrt_star, path for nrrt_star.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vnrrt import __version__
from vnrrt.cli.inputs import (
    UsageError,
    check_out,
    check_planner_target,
    load_heatmap,
    load_instance,
)
from vnrrt.cli.scen import add_scen_arguments, run_scen
from vnrrt.cli.settings import planner_config
from vnrrt.cli.stage import EXIT_BUDGET, EXIT_HELP, EXIT_OK, run_reporting

__all__ = ["UsageError", "build_parser", "load_heatmap", "load_instance", "main"]


def _point(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y (two numbers), got {text!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise argparse.ArgumentTypeError(f"expected finite X,Y, got {text!r}")
    return x, y


def _endpoints(args, inst: dict) -> tuple[tuple, tuple]:
    start = args.start or inst.get("start")
    goal = args.goal or inst.get("goal")
    if start is None or goal is None:
        raise UsageError("give --start X,Y and --goal X,Y (the map file does not hold them)")
    return start, goal


def _reference(inst: dict, start, goal, cfg):
    """The stored A* length when start and goal are the instance's own; else None, so that
    the planner computes the reference for these endpoints."""
    same = inst.get("start") == tuple(start) and inst.get("goal") == tuple(goal)
    return inst.get("astar") if same and cfg.reference == "astar" else None


def add_plan_command(sub: argparse._SubParsersAction) -> None:
    """Register ``vnrrt plan``."""
    from vnrrt.planners import PLANNERS

    p = sub.add_parser(
        "plan",
        help="run one planner on one instance and draw it",
        description="Run one planner on one instance (see `vnrrt --help`).",
    )
    p.add_argument("--map", type=Path, required=True,
                   help=".npy, .png, MovingAI .map or shard/named-maps .npz")  # fmt: skip
    p.add_argument("--instance", help="instance index or named map (u_trap) of an .npz")
    p.add_argument("--start", type=_point, help="start point X,Y in pixels")
    p.add_argument("--goal", type=_point, help="goal point X,Y in pixels")
    add_scen_arguments(p)
    p.add_argument("--planner", choices=PLANNERS, default="rrt_star")
    p.add_argument("--heatmap", type=Path, help="sampling heatmap .npy, .png or pipeline .npz")
    p.add_argument("--network", help="network of a pipeline heatmap .npz (vertexnet, nrrtnet)")
    p.add_argument("--row", type=int, help="row of a pipeline .npz heatmap (default: --instance's)")
    p.add_argument("--checkpoint", help="predict the heatmap with this network checkpoint")
    p.add_argument("--pad", action="store_true", help="pad the map to the network's stride")
    p.add_argument("--tau", type=float, help="mask threshold of m_vnrrt_star, in (0, 1]")
    p.add_argument("--stop", choices=("initial", "optimal"), default="initial")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--config", help="a planner YAML file, or a name in conf/planner/: user "
                   "(the default: our fastest settings, budgets scaled with the map's free "
                   "cells), fastest, default (the paper's protocol)")  # fmt: skip
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a planner setting, e.g. --set eta=5 (repeatable); "
                   "--set max_iterations=N or max_seconds=S fixes that budget")  # fmt: skip
    p.add_argument("--out", type=Path, help="write a PNG of map, heatmap, tree and path")
    p.set_defaults(func=run_plan)


def _heatmap(args, inst: dict, start, goal) -> np.ndarray | None:
    """The heatmap of ``--checkpoint`` or ``--heatmap`` for these endpoints, or None."""
    from vnrrt.grid import point_to_cell

    if args.heatmap and args.checkpoint:
        raise UsageError("give --heatmap or --checkpoint, not both")
    cells = point_to_cell(np.array([start, goal]))
    if args.checkpoint:
        from vnrrt.predict import heatmap, load_model

        model = load_model(args.checkpoint)
        check_planner_target(model.record, args.planner, args.checkpoint)
        return heatmap(model, inst["grid"], tuple(cells[0]), tuple(cells[1]), pad=args.pad)
    if not args.heatmap:
        return None
    if args.heatmap.suffix == ".npz" and "key" in inst:
        own = point_to_cell(np.array([inst["start"], inst["goal"]]))
        if not np.array_equal(cells, own):
            raise UsageError(f"--heatmap {args.heatmap} holds instance {inst['key']}'s heatmap "
                             f"for start cell {tuple(own[0])} and goal cell {tuple(own[1])}; "
                             "--start/--goal move them: predict one with --checkpoint")  # fmt: skip
    return load_heatmap(args.heatmap, inst.get("key"), args.network, args.row, args.planner)


def run_plan(args: argparse.Namespace) -> int:
    """``vnrrt plan``: print the result and both reference lengths; 0 on success."""
    from vnrrt.planners import any_angle_length, astar_length, plan

    if args.tau is not None and not 0.0 < args.tau <= 1.0:
        raise UsageError(f"--tau {args.tau}: must be in (0, 1] (heatmaps are probabilities)")
    cfg, label = planner_config(args.config, args.set)
    if args.scen is not None:
        return run_scen(args, cfg if args.tau is None else cfg.replace(tau=args.tau), label)
    for flag in ("scen_rows", "longest", "limit"):
        if getattr(args, flag) is not None:
            raise UsageError(f"--{flag.replace('_', '-')} needs --scen")
    inst = load_instance(args.map, args.instance)
    start, goal = _endpoints(args, inst)
    heatmap = _heatmap(args, inst, start, goal)
    if heatmap is None and args.planner != "rrt_star":
        raise UsageError(f"--planner {args.planner} samples a heatmap: give --heatmap FILE "
                         "or --checkpoint CKPT (e.g. models/quick/vertexnet.ckpt)")  # fmt: skip
    if args.out is not None:
        check_out(args.out, (".png",))
    result = plan(inst["grid"], start, goal, args.planner, heatmap=heatmap,
                  stop=args.stop, reference_length=_reference(inst, start, goal, cfg),
                  seed=args.seed, config=cfg if args.tau is None else cfg.replace(tau=args.tau),
                  keep_tree=args.out is not None)  # fmt: skip
    print(result.summary())
    print(f"config: {label}")
    try:
        a, t = astar_length(inst["grid"], start, goal), any_angle_length(inst["grid"], start, goal)
        ratio = f"{result.cost / a:.4f}" if a > 0 else "n/a (start and goal coincide)"
        print(f"reference lengths: A* {a:.2f} px, exact {t:.2f} px; cost/A* {ratio}")
    except ValueError as err:  # start and goal not connected
        print(f"reference lengths: none ({err})")
    print(f"path: {len(result.path)} points; fallback_uniform={result.fallback_uniform}")
    if args.out:
        from vnrrt.viz.planners import save_plan

        save_plan(args.out, inst["grid"], result, start, goal, heatmap)
        print(f"figure: {args.out}")
    return EXIT_OK if result.success else EXIT_BUDGET


def add_predict_command(sub: argparse._SubParsersAction) -> None:
    """Register ``vnrrt predict``."""
    p = sub.add_parser("predict", help="a trained network's heatmap for one instance",
                       description="Predict a heatmap (see `vnrrt --help`).")  # fmt: skip
    p.add_argument("--checkpoint", required=True, help="checkpoint .ckpt or MLflow model URI")
    p.add_argument("--map", type=Path, required=True,
                   help=".npy, .png, MovingAI .map or shard/named-maps .npz")  # fmt: skip
    p.add_argument("--instance", help="instance index or named map (u_trap) of an .npz")
    p.add_argument("--start", type=_point, help="start point X,Y in pixels")
    p.add_argument("--goal", type=_point, help="goal point X,Y in pixels")
    p.add_argument("--pad", action="store_true", help="pad the map to the network's stride")
    p.add_argument("--device", default="cpu", help="torch device (default cpu)")
    p.add_argument("--out", type=Path, required=True, help="heatmap .npy (float32) or .png")
    p.set_defaults(func=run_predict)


def run_predict(args: argparse.Namespace) -> int:
    """``vnrrt predict``: write the heatmap; 0 on success."""
    from vnrrt.grid import point_to_cell
    from vnrrt.predict import heatmap

    inst = load_instance(args.map, args.instance)
    start, goal = _endpoints(args, inst)
    check_out(args.out, (".npy", ".png"))
    cells = point_to_cell(np.array([start, goal]))
    heat = heatmap(args.checkpoint, inst["grid"], tuple(cells[0]), tuple(cells[1]), args.device,
                   pad=args.pad)  # fmt: skip
    from vnrrt.infra.io import atomic_write_bytes

    if args.out.suffix.lower() == ".npy":
        atomic_write_bytes(args.out, lambda f: np.save(f, heat))
    else:
        import cv2

        _, png = cv2.imencode(".png", np.round(heat * 65535).astype(np.uint16))
        atomic_write_bytes(args.out, lambda f: f.write(png.tobytes()))
    print(f"heatmap {heat.shape[1]}x{heat.shape[0]}, max {heat.max():.3f}: {args.out}")
    return 0


COMMANDS: list[Callable[[argparse._SubParsersAction], None]] = [
    add_plan_command,
    add_predict_command,
]


def build_parser() -> argparse.ArgumentParser:
    """The ``vnrrt`` parser with one sub-command per entry of :data:`COMMANDS`."""
    parser = argparse.ArgumentParser(
        prog="vnrrt",
        description=__doc__,
        epilog=EXIT_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"vnrrt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for add in COMMANDS:
        add(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``vnrrt`` console script and ``python -m vnrrt``; returns the exit
    status (:data:`vnrrt.cli.stage.EXIT_HELP`: 0 success, 1 budget, 2 bad input, 3 bug)."""
    args = build_parser().parse_args(argv)
    return run_reporting(f"vnrrt {args.command}", lambda: args.func(args))


if __name__ == "__main__":
    sys.exit(main())
