"""Command line: ``vnrrt <command> ...``. Commands register themselves in :data:`COMMANDS`.

``vnrrt plan`` runs one planner on one instance and draws it::

    vnrrt plan --map FILE [--instance I] [--start X,Y --goal X,Y] --planner vnrrt_star \
        [--heatmap FILE] [--tau 0.5] [--stop optimal] [--set eta=5] --out plan.png

Maps: ``.npy`` occupancy ``(H, W)`` (nonzero = obstacle); ``.png`` floor map (pixel
classes 0 free, 1 obstacle, 2 start, 3 goal when its values are <= 3, else dark pixels
< 128 are obstacles); ``.npz`` dataset shard with ``--instance``. Points are continuous
``(x, y)`` pixels; class-map and shard starts/goals are cell centres. Heatmaps: ``.npy``
``(H, W)`` or a grayscale ``.png`` scaled to [0, 1].
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vnrrt.grid import GridError


def _point(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y (two numbers), got {text!r}") from None
    return x, y


def _read_image(path: Path) -> np.ndarray:
    import cv2

    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise GridError(f"cannot read image {path}")
    return img if img.ndim == 2 else cv2.cvtColor(img[..., :3], cv2.COLOR_BGR2GRAY)


def _first_pixel(img: np.ndarray, value: int):
    ys, xs = np.nonzero(img == value)
    return (float(xs[0]) + 0.5, float(ys[0]) + 0.5) if len(xs) else None


def load_instance(path: Path, instance: int | None) -> dict:
    """Grid ``(H, W)`` uint8 and, where the file holds them, start/goal points and the A*
    length, from a ``.npy``, ``.png`` or shard ``.npz`` file (formats in module doc)."""
    if not path.is_file():
        raise FileNotFoundError(f"map file {path} not found")
    if path.suffix == ".npz":
        from vnrrt.data.reader import Shard

        if instance is None:
            raise ValueError("a shard needs --instance I")
        shard = Shard(path)
        if not 0 <= instance < shard.n_instances:
            raise ValueError(f"--instance {instance} not in [0, {shard.n_instances})")
        inst = shard.instance(instance)
        s, g = inst["start"] + 0.5, inst["goal"] + 0.5
        return {"grid": shard.grid(inst["map_index"]), "start": tuple(s), "goal": tuple(g),
                "astar": inst["length"]}  # fmt: skip
    if path.suffix == ".npy":
        return {"grid": np.load(path)}
    if path.suffix == ".png":
        img = _read_image(path)
        if img.max() <= 3:  # pixel classes of the paper: 0 free, 1 obstacle, 2 start, 3 goal
            return {"grid": (img == 1).astype(np.uint8), "start": _first_pixel(img, 2),
                    "goal": _first_pixel(img, 3)}  # fmt: skip
        return {"grid": (img < 128).astype(np.uint8)}
    raise ValueError(f"unsupported map file {path}: use .npy, .png or a shard .npz")


def load_heatmap(path: Path) -> np.ndarray:
    """Heatmap ``(H, W)`` float64 from ``.npy`` or a grayscale ``.png`` (scaled to [0, 1])."""
    if not path.is_file():
        raise FileNotFoundError(f"heatmap file {path} not found")
    if path.suffix == ".npy":
        return np.load(path).astype(np.float64)
    if path.suffix == ".png":
        img = _read_image(path)
        return img.astype(np.float64) / float(np.iinfo(img.dtype).max)
    raise ValueError(f"unsupported heatmap file {path}: use .npy or .png")


def _overrides(pairs: list[str]) -> dict:
    """``key=value`` strings parsed as YAML scalars (``eta=5`` gives 5, ``gamma=null``)."""
    import yaml

    out = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise ValueError(f"--set expects key=value, got {pair!r}")
        out[key.strip()] = yaml.safe_load(value)
    return out


def _planner_config(path: Path | None, pairs: list[str]):
    from omegaconf import OmegaConf

    from vnrrt.config import CONF_DIR, section
    from vnrrt.planners import PlannerConfig

    path = path or CONF_DIR / "planner" / "default.yaml"
    cfg = section({"planner": OmegaConf.load(path)}, "planner", PlannerConfig)
    return cfg.replace(**_overrides(pairs))


def add_plan_command(sub: argparse._SubParsersAction) -> None:
    """Register ``vnrrt plan``."""
    from vnrrt.planners import PLANNERS

    p = sub.add_parser("plan", help="run one planner on one instance and draw it")
    p.add_argument("--map", type=Path, required=True, help=".npy, .png or shard .npz")
    p.add_argument("--instance", type=int, help="instance index inside a shard")
    p.add_argument("--start", type=_point, help="start point X,Y in pixels")
    p.add_argument("--goal", type=_point, help="goal point X,Y in pixels")
    p.add_argument("--planner", choices=PLANNERS, default="rrt_star")
    p.add_argument("--heatmap", type=Path, help="sampling heatmap .npy or .png")
    p.add_argument("--tau", type=float, help="mask threshold of m_vnrrt_star")
    p.add_argument("--stop", choices=("initial", "optimal"), default="initial")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--config", type=Path, help="planner YAML (default conf/planner/default.yaml)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a planner setting, e.g. --set eta=5 (repeatable)")  # fmt: skip
    p.add_argument("--out", type=Path, help="write a PNG of map, heatmap, tree and path")
    p.set_defaults(func=run_plan)


def run_plan(args: argparse.Namespace) -> int:
    """``vnrrt plan``: print the result (and both reference lengths); 0 on success."""
    from vnrrt.planners import any_angle_length, astar_length, plan

    cfg = _planner_config(args.config, args.set)
    inst = load_instance(args.map, args.instance)
    start = args.start or inst.get("start")
    goal = args.goal or inst.get("goal")
    if start is None or goal is None:
        raise ValueError("give --start X,Y and --goal X,Y (the map file does not hold them)")
    heatmap = load_heatmap(args.heatmap) if args.heatmap else None
    ref = inst.get("astar") if cfg.reference == "astar" else None
    result = plan(inst["grid"], start, goal, args.planner, heatmap=heatmap, tau=args.tau,
                  stop=args.stop, reference_length=ref, seed=args.seed, config=cfg,
                  keep_tree=args.out is not None)  # fmt: skip
    print(result.summary())
    try:
        a, t = astar_length(inst["grid"], start, goal), any_angle_length(inst["grid"], start, goal)
        print(
            f"reference lengths: A* {a:.2f} px, any-angle {t:.2f} px; cost/A* {result.cost / a:.4f}"
        )
    except ValueError as err:  # start and goal not connected
        print(f"reference lengths: none ({err})")
    print(f"path: {len(result.path)} points; fallback_uniform={result.fallback_uniform}")
    if args.out:
        from vnrrt.viz.planners import save_plan

        save_plan(args.out, inst["grid"], result, start, goal, heatmap)
        print(f"figure: {args.out}")
    return 0 if result.success else 1


COMMANDS: list[Callable[[argparse._SubParsersAction], None]] = [add_plan_command]


def build_parser() -> argparse.ArgumentParser:
    """The ``vnrrt`` parser with one sub-command per entry of :data:`COMMANDS`."""
    parser = argparse.ArgumentParser(prog="vnrrt", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for add in COMMANDS:
        add(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``vnrrt`` console script; returns the exit status.

    0: success; 1: the planner stopped on a budget; 2: bad input (message on stderr).
    """
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (GridError, ValueError, FileNotFoundError) as err:
        print(f"vnrrt {args.command}: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
