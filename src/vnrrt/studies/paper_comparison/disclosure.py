"""The report's disclosure sections: every planner and protocol setting beside the paper's
(``data/paper/settings.yaml``, our values from the run's config), the networks of this
scale beside the paper's, and what each masked configuration's sampler actually samples."""

from __future__ import annotations

import math

from vnrrt.evaluation.keys import ConfigKey, label, sort_texts

STATUS = {
    "as_paper": "as the paper",
    "silent": "ours, the paper is silent",
    "differs": "ours, differs",
    "inferred": "ours, inferred from the paper's source",
}


def _value(v) -> str:
    if isinstance(v, list | tuple):
        return ", ".join(_value(x) for x in v)
    if isinstance(v, float):
        return f"{v:g}"
    return "null" if v is None else str(v)


def setting_status(entry: dict, ours) -> str:
    """A setting's status: computed from ``paper_value`` when it has one (equal: as the
    paper), else the entry's ``status``."""
    if "paper_value" in entry:
        same = _value(ours) == _value(entry["paper_value"])
        return STATUS["as_paper" if same else "differs"]
    return STATUS[entry["status"]]


def settings_table(settings: dict, values: dict) -> str:
    """The settings table: ``settings`` as ``settings.yaml`` holds it, ``values`` the run's
    value of every ``key`` it names."""
    lines = ["| setting | this run | the paper | status |", "| --- | --- | --- | --- |"]
    for entry in settings["settings"]:
        key = entry.get("key")
        if key:
            ours = f"{_value(values[key])} (`{key}`)"
            ours += f"; {entry['ours_note']}" if entry.get("ours_note") else ""
            status = setting_status(entry, values[key])
        else:
            ours, status = entry["ours"], STATUS[entry["status"]]
        lines.append(f"| {entry['name']} | {ours} | {entry['paper']} | {status} |")
    return "\n".join(lines)


def networks_scale_table(trainings: dict[str, dict], scale: str, paper_network: str) -> str:
    """The networks of this scale (``trainings``: network -> its training metrics file;
    ``where`` in one, as for the GPU-trained networks, replaces ``scale``) beside the paper's
    network."""
    lines = [
        "| network | architecture | parameters | initialisation | steps x batch | images seen | "
        "training wall time |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for name, t in trainings.items():
        net = t.get("network", {})
        target = t.get("target", {}).get("kind", "?")
        arch = (
            f"{net.get('encoder', '?')} U-Net (encoder width {net.get('encoder_width', '?')}, "
            f"decoder width {net.get('decoder_width', '?')}), target {target}"
        )
        init = "ImageNet weights" if net.get("weights", "none") != "none" else "from scratch"
        params = f"{net['params_total']:,}" if "params_total" in net else "?"
        batch = t.get("batch_size", "?")
        minutes = t.get("fit_seconds", math.nan) / 60
        lines.append(
            f"| {name} ({t.get('where', scale)}) | {arch} | {params} | {init} "
            f"| {t.get('steps', '?')} x {batch} "
            f"| {t.get('train_images', 0):,} | {minutes:.0f} min |"
        )
    lines.append(f"| the paper's | {paper_network} | | | | | |")
    return "\n".join(lines)


def mask_section(summary: dict, stop: str = "optimal", map_set: str = "random") -> list[str]:
    """Where each heatmap sampler's mass lies after its mask (``summary["mask_shares"]``), on
    ``map_set`` at stop rule ``stop``, with the uniform-fallback rate."""
    cells = summary.get("mask_shares", {}).get(stop, {})
    keys = [k for k in sort_texts(cells) if map_set in cells[k] and not ConfigKey.parse(k).informed]
    if not keys:
        return []
    lines = [
        "| configuration | start/goal disks | near interior vertices | near the rest of the path "
        "| elsewhere | falls back to uniform |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for k in keys:
        c = cells[k][map_set]
        shares = [c["mass_endpoints"], c["mass_interior"], c["mass_path"]]
        known = [s for s in shares if s is not None]
        rest = 1 - sum(known) if len(known) == 3 else None
        vals = [_pct(s) for s in [*shares, rest]]
        lines.append(f"| {label(k)} | " + " | ".join(vals) + f" | {c['fallback_rate']:.0%} |")
    return lines


def _pct(v) -> str:
    return "—" if v is None else f"{v:.1%}"
