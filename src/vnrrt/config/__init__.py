"""Configuration: Hydra composition of ``conf/`` and typed, validated sections.

``conf/`` is the single source of truth. DVC composes it into ``params.yaml`` on
``dvc exp run`` (``hydra.enabled``); :func:`compose` does the same composition here (used
by ``make params`` and by the test that keeps the committed ``params.yaml`` in sync).
Stages read ``params.yaml`` with :func:`load_params`, see only the keys their ``dvc.yaml``
entry declares (:func:`restrict`) and validate the sections they use against typed
dataclasses (:func:`section`), so an unknown key or a wrong type fails with a message that
names the key. :mod:`vnrrt.pipeline.validate` checks the whole composition before any stage runs.
"""

from __future__ import annotations

import dataclasses
import inspect
import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

# omegaconf is imported inside the functions that use it: `check`, `ConfigError` and `asdict`
# (which the data code imports) then work where it is not installed (scripts/gpu/).
if TYPE_CHECKING:
    from omegaconf import DictConfig

REPO_ROOT = Path(__file__).resolve().parents[3]
# conf/ of the repository; in an installed wheel its copy (package data: src/vnrrt/conf links
# to it); VNRRT_CONF_DIR names another
_PACKAGED = Path(__file__).resolve().parents[1] / "conf"
CONF_DIR = Path(
    os.environ.get("VNRRT_CONF_DIR")
    or (REPO_ROOT / "conf" if (REPO_ROOT / "conf").is_dir() else _PACKAGED)
)

T = TypeVar("T")


class ConfigError(ValueError):
    """A configuration value or key is invalid; the message names it."""


def conf_file(group: str, option: str = "default", node: str | None = None) -> dict:
    """The settings of ``conf/<group>/<option>.yaml`` as plain Python values (YAML's ``.inf``
    is ``math.inf``, ``null`` is None), composed as Hydra composes a group option: the
    options its ``defaults`` list names first, then its own keys (``_self_``, last when not
    listed). With ``node``, the mapping under that top-level key (``scale`` in a ``# @package
    _global_`` file), not composed. :class:`ConfigError` names a missing or malformed file."""
    from vnrrt.infra.io import read_yaml

    path = CONF_DIR / group / f"{option}.yaml"
    doc = read_yaml(path, "config file", ConfigError)
    if node is not None:
        doc = doc.get(node) if isinstance(doc, dict) else None
    if not isinstance(doc, dict):
        raise ConfigError(f"config file {path} has no mapping{f' under {node!r}' if node else ''}")
    if node is not None:
        return doc
    bases = doc.pop("defaults", [])
    if not all(isinstance(b, str) for b in bases):
        raise ConfigError(f"config file {path}: its defaults name other groups' options")
    merged: dict = {}
    for base in bases if "_self_" in bases else [*bases, "_self_"]:
        merged.update(doc if base == "_self_" else conf_file(group, base))
    return merged


def conf_defaults(group: str, option: str = "default", node: str | None = None, *,
                  exact: bool = False, error: type[Exception] = ConfigError):  # fmt: skip
    """Class decorator, applied below ``@dataclass``: the defaults of the class's own fields
    are the values of ``conf/<group>/<option>.yaml`` (:func:`conf_file`), so the library's
    defaults and the pipeline's are one source. Every own field must be in the file; with
    ``exact``, the file holds no other key (else it may: a section's subset). ``error``
    (:class:`ConfigError` by default) names the file and the keys otherwise."""

    def wrap(cls: type[T]) -> type[T]:
        values = conf_file(group, option, node)
        names = list(inspect.get_annotations(cls))
        missing = [n for n in names if n not in values]
        if missing:
            raise error(f"conf/{group}/{option}.yaml lacks {missing} ({cls.__name__})")
        extra = sorted(set(values) - set(names)) if exact else []
        if extra:
            raise error(f"conf/{group}/{option}.yaml and {cls.__name__} differ: {extra}")
        for name in names:
            value = values[name]
            if isinstance(value, list | dict):
                default = dataclasses.field(default_factory=_copier(value))
            else:
                default = value
            setattr(cls, name, default)
        return cls

    return wrap


def _copier(value):
    """A default factory returning a fresh deep copy of ``value``."""
    import copy

    return lambda: copy.deepcopy(value)


def check_parts(parts, key: str) -> list[int]:
    """``parts`` (the ids of a stage's parts, e.g. ``eval.parts``) as a list of ints;
    :class:`ConfigError` naming ``key`` unless it is ``[0, 1, ..., K-1]`` with K >= 1."""
    try:
        ids = None if isinstance(parts, str) else [int(p) for p in parts]
    except (TypeError, ValueError):
        ids = None
    check(bool(ids) and ids == list(range(len(ids))), key, parts, "must be [0, 1, ..., K-1]")
    return ids


def check(ok: bool, key: str, value: Any, why: str) -> None:
    """Raise :class:`ConfigError` ``invalid config value key=value: why`` unless ``ok``."""
    if not ok:
        raise ConfigError(f"invalid config value {key}={value!r}: {why}")


def section(cfg: DictConfig | dict, key: str, schema: type[T]) -> T:
    """Return ``cfg[key]`` as a validated ``schema`` instance.

    Unknown or missing keys, missing sections and wrong types raise :class:`ConfigError`
    naming the offending ``key.subkey`` (the dataclasses' defaults, read from ``conf/`` by
    :func:`conf_defaults`, serve library callers; a composed config must give every key).
    """
    from omegaconf import DictConfig, OmegaConf
    from omegaconf.errors import OmegaConfBaseException

    node = cfg.get(key) if isinstance(cfg, Mapping) else None
    if node is None:
        raise ConfigError(f"config section {key!r} is missing")
    names = [f.name for f in dataclasses.fields(schema)]
    unknown = [str(k) for k in node if k not in names]
    if unknown:
        raise ConfigError(
            f"unknown config key(s) {[f'{key}.{k}' for k in unknown]}; known: {names}"
        )
    missing = [n for n in names if n not in node]
    if missing:
        raise ConfigError(f"config section {key!r} lacks {missing} (conf/ gives every key)")
    try:  # interpolations resolved against the whole config first (``${scale.name}``)
        if isinstance(node, DictConfig):
            node = OmegaConf.to_container(node, resolve=True)
        merged = OmegaConf.merge(OmegaConf.structured(schema), node)
        for name, value in node.items():  # a given mapping replaces the default's, whole
            if isinstance(value, Mapping):
                merged[name] = value
        obj = OmegaConf.to_object(merged)
    except OmegaConfBaseException as err:
        where = f"{key}.{err.full_key}" if getattr(err, "full_key", None) else key
        raise ConfigError(f"bad config at {where!r}: {err.msg}") from None
    try:
        obj.validate()
    except ConfigError:
        raise
    except ValueError as err:  # a library's own settings error (e.g. PlannerConfigError)
        raise ConfigError(f"{key}: {err}") from None
    return obj


def sections(cfg: DictConfig | dict, **schemas: type) -> dict[str, Any]:
    """``{name: section(cfg, name, schema)}`` for every ``name=schema``: a stage's typed
    sections in one call."""
    return {name: section(cfg, name, schema) for name, schema in schemas.items()}


def load_params(path: str | Path = "params.yaml", optional: tuple[str, ...] = ()) -> DictConfig:
    """Load the composed parameters file (``params.yaml``) written by DVC or ``make params``;
    every section of the composition must be there but those named ``optional`` (sections
    newer than a kept file, which its reader does not read)."""
    from omegaconf import DictConfig, OmegaConf

    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"parameters file {path} not found (run `make params`)")
    try:
        cfg = OmegaConf.load(path)
    except Exception as err:  # YAML errors of several kinds
        raise ConfigError(f"parameters file {path} is not valid YAML: {err}") from None
    if not isinstance(cfg, DictConfig) or not cfg:
        raise ConfigError(f"parameters file {path} is empty or not a mapping (run `make params`)")
    missing = [k for k in sections_of_composition() if k not in cfg and k not in optional]
    if missing:
        raise ConfigError(f"parameters file {path} lacks the sections {missing}: cut short or "
                          "not a composition of conf/ (run `make params`)")  # fmt: skip
    return cfg


def sections_of_composition() -> list[str]:
    """The top-level keys every composition of ``conf/config.yaml`` has: its own keys and one
    section per config group of its defaults list (``hydra`` aside)."""
    from vnrrt.infra.io import read_yaml

    root = read_yaml(CONF_DIR / "config.yaml", "config file", ConfigError)
    groups = [next(iter(d)) for d in root.get("defaults", []) if isinstance(d, dict)]
    own = [k for k in root if k != "defaults"]
    return [k for k in dict.fromkeys(own + groups) if k != "hydra"]


# Sections every stage receives without listing them as DVC params: where files go
# (DVC tracks them as deps and outs), where runs are logged and how many processes to use
# (neither changes an output).
ALWAYS = ("paths", "logger", "workers")


def restrict(cfg: DictConfig, keys: list[str], always: tuple[str, ...] = ALWAYS) -> DictConfig:
    """A copy of ``cfg`` holding only the dotted ``keys`` (and ``always``); reading any other
    key fails, so a stage can only use the parameters its ``dvc.yaml`` entry declares."""
    from omegaconf import OmegaConf

    out = OmegaConf.create({})
    for key in [*always, *keys]:
        value = OmegaConf.select(cfg, key, default=_MISSING)
        if value is _MISSING:
            raise ConfigError(f"parameter {key!r} is declared but missing from the parameters")
        OmegaConf.update(out, key, value, merge=False, force_add=True)
    OmegaConf.set_struct(out, True)
    return out


_MISSING = object()


def stage_params(stage: str, dvc_yaml: str | Path = "dvc.yaml") -> list[str]:
    """The dotted ``params`` keys of stage ``stage`` (``name`` or ``name@item``; ``${item}``
    in a key becomes ``item``; of a ``matrix`` stage ``name@a-b``, ``${item.<k>}`` becomes
    the value of its k-th matrix key) in ``dvc_yaml``; :class:`ConfigError` if it is not
    there."""
    from vnrrt.infra.io import read_yaml

    path = Path(dvc_yaml)
    if not path.is_file():
        raise ConfigError(f"{path} not found: run stages from the repository root")
    stages = (read_yaml(path, "pipeline file", ConfigError) or {}).get("stages", {})
    name, _, item = stage.partition("@")
    if name not in stages:
        raise ConfigError(f"stage {name!r} is not in {path}")
    entry = stages[name].get("do", stages[name])
    keys = [k for k in entry.get("params", []) if isinstance(k, str)]
    names = {"${item}": item}
    if "matrix" in stages[name]:
        axes = list(stages[name]["matrix"])
        values = item.split("-", len(axes) - 1)
        if len(values) != len(axes):
            raise ConfigError(f"stage {stage!r}: expected {name}@<{'>-<'.join(axes)}>")
        names = {f"${{item.{a}}}": v for a, v in zip(axes, values, strict=True)}
    for placeholder, value in names.items():
        keys = [k.replace(placeholder, value) for k in keys]
    return keys


def _leaves(doc: Any, prefix: str = "") -> dict[str, Any]:
    """``{dotted key: value}`` of the leaves of a nested mapping (lists are leaves)."""
    if not isinstance(doc, Mapping):
        return {prefix: doc}
    out: dict[str, Any] = {}
    for k, v in doc.items():
        out.update(_leaves(v, f"{prefix}.{k}" if prefix else str(k)))
    return out


def check_unchanged_since_validate(params: str | Path, dvc_lock: str | Path) -> None:
    """Refuse to go on when ``params`` no longer holds the values the ``validate`` stage of
    this run recorded in ``dvc_lock`` (DVC writes a stage's entry as soon as it finishes).

    That happens when a second ``dvc exp run -S ...`` in the same workspace rewrites
    ``params.yaml`` while a first one is running: without this check the first run's later
    stages would use the second run's values (issue #28). :class:`ConfigError` names every
    changed key with both values. Nothing is checked when the lock or its ``validate``
    entry is absent (a first run, a stage script run by hand)."""
    from vnrrt.infra.io import read_yaml

    lock = Path(dvc_lock)
    if not lock.is_file():
        return
    entry = ((read_yaml(lock, "DVC lock file", ConfigError) or {}).get("stages") or {}).get(
        "validate"
    )
    recorded = ((entry or {}).get("params") or {}).get(Path(params).name)
    if not recorded:
        return
    now = read_yaml(params, "parameters file", ConfigError) or {}
    before = _leaves(recorded)
    after = _leaves({k: now.get(k) for k in recorded})
    changed = [
        f"{k}: {before.get(k)!r} -> {after.get(k)!r}"
        for k in sorted(set(before) | set(after))
        if before.get(k) != after.get(k)
    ]
    if changed:
        raise ConfigError(
            f"{params} changed since this run's validate stage ({'; '.join(changed)}): "
            "another `dvc exp run` in this workspace? Queue parallel experiments instead "
            "(`dvc exp run --queue -S ...`, then `dvc queue start`), or re-run `dvc repro`"
        )


def compose(overrides: list[str] | tuple[str, ...] = ()) -> DictConfig:
    """Compose ``conf/config.yaml`` with Hydra overrides and resolve it, exactly as DVC does."""
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir
    from omegaconf import OmegaConf

    with initialize_config_dir(str(CONF_DIR), version_base=None):
        cfg = hydra_compose(config_name="config", overrides=list(overrides))
    OmegaConf.resolve(cfg)
    return cfg


def dump(cfg: DictConfig) -> str:
    """YAML text of a composed config, in the format DVC writes ``params.yaml``."""
    from omegaconf import OmegaConf

    return OmegaConf.to_yaml(cfg)


def asdict(obj: Any) -> dict:
    """Plain dict of a config dataclass (for hashing and metadata)."""
    return dataclasses.asdict(obj)
