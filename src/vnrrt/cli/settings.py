"""The planner settings of ``vnrrt plan``: ``--config`` (a name in ``conf/planner/`` or a
planner YAML file) and ``--set KEY=VALUE`` overrides, and how the output names them."""

from __future__ import annotations

from pathlib import Path

from vnrrt.cli.inputs import UsageError


def _overrides(pairs: list[str]) -> dict:
    """``key=value`` strings parsed as YAML scalars (``eta=5`` gives 5, ``gamma=null``)."""
    import yaml

    out = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise UsageError(f"--set expects key=value, got {pair!r}")
        try:
            out[key.strip()] = yaml.safe_load(value)
        except yaml.YAMLError:
            raise UsageError(f"--set {pair!r}: the value is not a number or word") from None
    return out


RULES = {"max_iterations": "iterations_per_free_cell", "max_seconds": "seconds_per_free_cell"}


def planner_config(config: str | None, pairs: list[str]):
    """The planner settings and how to name them: ``--config`` a name of ``conf/planner/``
    (``user``, the default when none is given; ``fastest``; ``default``, the paper's
    protocol) or a planner YAML file, then the ``--set`` overrides. A budget set
    (``max_iterations``, ``max_seconds``) is the budget: the budget rule's constant for it
    is turned off unless set too."""
    from vnrrt.config import CONF_DIR
    from vnrrt.planners import PlannerConfig

    name = config or "user"
    if (CONF_DIR / "planner" / f"{name}.yaml").is_file() and "/" not in name and "." not in name:
        cfg, label = PlannerConfig.named(name), f"{name} (conf/planner/{name}.yaml)"
    else:
        cfg, label = _config_file(Path(name)), name
    changes = _overrides(pairs)
    for budget, rule in RULES.items():
        if budget in changes and rule not in changes:
            changes[rule] = None
    return cfg.replace(**changes), label + "".join(f" --set {a}" for a in pairs)


def _config_file(path: Path):
    """The planner settings of a YAML file (every key of ``conf/planner/default.yaml``)."""
    import yaml
    from omegaconf import OmegaConf

    from vnrrt.config import section
    from vnrrt.planners import PlannerConfig

    if not path.is_file():
        raise UsageError(f"--config {path} not found (nor a name in conf/planner/)")
    try:
        node = OmegaConf.create(yaml.safe_load(path.read_text()) or {})
    except yaml.YAMLError as err:
        first = str(err).splitlines()[0]
        raise UsageError(f"--config {path} is not valid YAML: {first}") from None
    return section({"planner": node}, "planner", PlannerConfig)
