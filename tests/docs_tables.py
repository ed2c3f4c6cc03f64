"""The README's generated tables, rendered from the committed CPU-scale reports, and the
number check of the README and ``docs/`` (``tests/test_docs.py`` runs both).

* :func:`headline_table` renders the paper's quoted claims (the paper's number, our reading
  with its CI, the verdict) from ``reports/cpu/paper_comparison.md`` and the verdict counts
  from ``reports/cpu/metrics/headline.json``; :func:`oracle_table` the sampling ideas'
  envelopes from ``reports/cpu/sampling_ideas.md``. Each stands in the README between
  ``<!-- begin NAME -->`` and ``<!-- end NAME -->``; :func:`networks_table` the networks'
  test metrics (``docs/results.md``) from ``reports/cpu/metrics`` and ``reports/cpu/seed1``.
* :func:`unsourced_numbers` lists the numbers of a page's prose and tables (code left out)
  that appear in none of the files its section links to.

``python -m tests.docs_tables`` writes the tables into the pages after a new CPU-scale run.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REPORTS = ROOT / "reports" / "cpu"
VERDICTS = ("reproduced", "same_dir", "no_effect", "reversed")
VERDICT_WORDS = {
    "reproduced": "reproduced",
    "same_dir": "same direction",
    "no_effect": "no clear effect",
    "reversed": "reversed",
}


def markdown_table(text: str, heading: str) -> list[dict[str, str]]:
    """The first table under the ``## heading`` of a markdown text, one dict per row keyed by
    the header cells; a missing heading or table raises ``ValueError`` naming it."""
    part = text.split(f"\n## {heading}\n", 1)
    if len(part) != 2:
        raise ValueError(f"no section '## {heading}'")
    body = part[1].split("\n## ", 1)[0].splitlines()
    first = next((i for i, ln in enumerate(body) if ln.startswith("|")), len(body))
    lines = []
    for ln in body[first:]:
        if not ln.startswith("|"):
            break
        lines.append(ln)
    if len(lines) < 3:
        raise ValueError(f"no table under '## {heading}'")
    cells = [[c.strip() for c in ln.strip().strip("|").split(" | ")] for ln in lines]
    return [dict(zip(cells[0], row, strict=True)) for row in cells[2:]]


def headline_table(reports: Path = REPORTS) -> str:
    """The README's table of the paper's claims (module doc), markdown, ending in a newline."""
    text = (reports / "paper_comparison.md").read_text()
    level = re.search(r"Every interval of this table is at ([\d.]+%)", text)
    if level is None:
        raise ValueError("paper_comparison.md states no interval level")
    counts = json.loads((reports / "metrics" / "headline.json").read_text())
    rows = [
        f"| claim (the paper's words) | the paper | ours: time, {level.group(1)} CI | verdict |",
        "| --- | --- | --- | --- |",
    ]
    for row in markdown_table(text, "The paper's quoted claims"):
        ours = row["ours: time, gm ratio of medians [CI]"]
        verdict = row["verdict"]
        if row.get("tests the mask?", "yes").startswith("no"):
            verdict += "; untestable with this network"
        rows.append(f"| {row['claim']} | {row['paper']} | {ours} | {verdict} |")
    head = json.loads((reports / "metrics" / "headline.json").read_text())
    total = ", ".join(f"{VERDICT_WORDS[k]} {counts[k]}" for k in VERDICTS)
    untestable = head.get("untestable", 0)
    if not untestable:
        return "\n".join(rows) + f"\n\nVerdicts: {total}.\n"
    return "\n".join(rows) + (
        f"\n\nVerdicts of the {head['testable']} testable claims: {total}; "
        f"{untestable} untestable with this network (no verdict counted).\n"
    )


def oracle_table(reports: Path = REPORTS) -> str:
    """The README's table of the oracle envelopes in the protocol's cell: iterations saved
    against RRT* per sampling idea and stop, with 95% CIs, from the report's conclusion."""
    text = (reports / "sampling_ideas.md").read_text()
    stops = {
        "within 1% of A*": "to 1% of A*",
        "within 1% of the exact optimum": "to 1% of the exact optimum",
    }
    found: dict[str, dict[str, str]] = {}
    for stop in stops:
        line = re.search(rf"- Envelopes \({re.escape(stop)}, [^)]*\): (.*)\.\n", text)
        if line is None:
            raise ValueError(f"sampling_ideas.md has no envelope line {stop!r}")
        for item in line.group(1).split("; "):
            idea, value = item.split(" ", 1)
            found.setdefault(idea, {})[stop] = value
    rows = ["| sampling near | " + " | ".join(stops.values()) + " |", "| --- | --- | --- |"]
    names = {
        "path": "the path",
        "vertex": "the A* path's vertices",
        "taut_vertex": "the true turning points (exact optimum)",
        "masked_vertex": "the turning points, masked (a perfect M-VNRRT*)",
        "blend": "both (blend)",
        "control": "start and goal only",
    }
    edge = False
    for idea, name in ((i, n) for i, n in names.items() if i in found):
        cells = []
        for s in stops:
            value, flagged, _ = found[idea][s].partition(" (best measured member: ")
            edge |= bool(flagged)
            cells.append(value + (" †" if flagged else ""))
        rows.append(f"| {name} | " + " | ".join(cells) + " |")
    note = (
        "\n† the best measured member of its family: its heatmap-draw probability or blur "
        "is the largest or smallest value the grid tried, so it is no bound of its idea.\n"
    )
    return "\n".join(rows) + "\n" + (note if edge else "")


def networks_table(reports: Path = REPORTS) -> str:
    """The networks' test-split metrics per training seed (seed 0 in ``metrics/``, seed 1 in
    ``seed1/``), masses also as multiples of a uniform map's."""
    rows = [
        "| network, seed | interior-vertex AP | interior recall | mass near interior vertices "
        "(x uniform) | path AP | mass near the path (x uniform) | mass on start/goal |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for name, label in (("vertexnet", "VertexNet"), ("nrrtnet", "NRRT* network")):
        for seed, folder in ((0, "metrics"), (1, "seed1")):
            d = json.loads((reports / folder / f"train_{name}.json").read_text())
            t = {k.removeprefix("test/"): v for k, v in d.items() if k.startswith("test/")}
            inner = t["mass_near_interior"] / t["mass_near_interior_uniform"]
            path = t["mass_near_path"] / t["mass_near_path_uniform"]
            rows.append(
                f"| {label}, {seed} | {t['interior_ap']:.3f} | {t['interior_recall']:.3f} | "
                f"{t['mass_near_interior']:.3f} ({inner:.1f}x) | {t['path_ap']:.3f} | "
                f"{t['mass_near_path']:.3f} ({path:.1f}x) | {t['mass_on_endpoints']:.3f} |"
            )
    return "\n".join(rows) + "\n"


TABLES = {"headline": headline_table, "oracle": oracle_table, "networks": networks_table}
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def block(text: str, name: str) -> str:
    """The text between ``<!-- begin name -->`` and ``<!-- end name -->`` (without the
    markers' lines); ``ValueError`` when the markers are missing."""
    m = re.search(rf"<!-- begin {name} -->\n(.*?)<!-- end {name} -->", text, flags=re.S)
    if m is None:
        raise ValueError(f"no '<!-- begin {name} -->' ... '<!-- end {name} -->' block")
    return m.group(1)


def generated(text: str) -> list[str]:
    """The names of the generated blocks in ``text``, in order."""
    return re.findall(r"<!-- begin (\w+) -->", text)


def write() -> None:
    """Replace every generated block of the README and ``docs/`` by a fresh rendering."""
    for page in PAGES:
        text = page.read_text()
        for name in generated(text):
            text = text.replace(block(text, name), TABLES[name]())
        page.write_text(text)


NUMBER = re.compile(r"(?<![\w.])(?<![A-Za-z]-)[-+]?\d[\d,]*(?:\.\d+)?")
CODE = re.compile(r"```.*?```|`[^`\n]*`", flags=re.S)
LINK_TARGET = re.compile(r"\]\(([^)\s]+)\)")
# The paper's own figure, table, algorithm and map numbers, and the generated blocks.
NAMED = re.compile(r"\b(?:Fig\.|Figs\.|Tables?|Algorithms?|Maps?|seeds?)\s+\d+(?:[-,]\s*\d+)*")
LIST_ITEM = re.compile(r"^\s*\d+\.\s", flags=re.M)  # an ordered list's "1. "
GENERATED = re.compile(r"<!-- begin (\w+) -->.*?<!-- end \1 -->", flags=re.S)


def numbers(text: str) -> list[str]:
    """The number tokens of ``text`` without thousands separators (``115,200`` -> ``115200``)."""
    out = []
    for token in NUMBER.findall(text):
        token = token.lstrip("+-").rstrip(",")
        if re.fullmatch(r"\d{1,3}(,\d{3})+(\.\d+)?", token):
            token = token.replace(",", "")
        out.extend(t for t in token.split(",") if t)
    return out


def _matches(token: str, source: set[str], values: list[float]) -> bool:
    """``token`` stands in ``source`` as written, or is a source value rounded to its digits."""
    if token in source:
        return True
    if "." not in token:  # an integer stands as written (or as a source's ``200.0``)
        return float(token) in values and any(float(s) == float(token) for s in source)
    digits = len(token.split(".")[1])
    want = float(token)
    return any(round(v, digits) == want for v in values)


def sections(text: str) -> list[tuple[str, str]]:
    """(heading, body) of each ``##`` section (the text before the first one as '')."""
    parts = re.split(r"^(## .*)$", text, flags=re.M)
    return [("", parts[0]), *zip(parts[1::2], parts[2::2], strict=True)]


def anchors(page: Path) -> set[str]:
    """The heading anchors of a markdown page, as GitHub makes them."""
    text = re.sub(r"```.*?```", " ", page.read_text(), flags=re.S)
    heads = re.findall(r"^#+ (.*)$", text, flags=re.M)
    return {re.sub(r"[^\w\- ]", "", h.lower()).replace(" ", "-") for h in heads}


def broken_links(page: Path) -> list[str]:
    """The relative link targets of ``page`` that name no file or folder, or no heading of
    the markdown page they name (``file.md#heading``, ``#heading``)."""
    broken = []
    for target in LINK_TARGET.findall(CODE.sub(" ", page.read_text())):
        if "://" in target:
            continue
        path, _, anchor = target.partition("#")
        file = page.parent / path if path else page
        if not file.exists() or (anchor and file.suffix == ".md" and anchor not in anchors(file)):
            broken.append(target)
    return broken


def unsourced_numbers(page: Path) -> list[str]:
    """'section: number' for each number of ``page`` (code spans, code blocks, link targets,
    the paper's figure/table/map numbers and generated blocks left out) that no file linked
    from its section contains, as written or rounded (``3.2`` for a source's ``3.151``)."""
    missing = []
    for heading, body in sections(page.read_text()):
        prose = GENERATED.sub(" ", CODE.sub(" ", body))
        links = [t for t in LINK_TARGET.findall(prose) if "://" not in t]
        prose = LIST_ITEM.sub(" ", NAMED.sub(" ", LINK_TARGET.sub("]", prose)))
        source_text = ""
        for target in links:
            path = (page.parent / target.split("#")[0]).resolve()
            if path.is_file() and path.suffix in {".md", ".json", ".yaml", ".txt", ".cff", ""}:
                source_text += path.read_text() + "\n"
        source = set(numbers(source_text))
        values = [float(t) for t in source]
        missing += [
            f"{heading or 'top'}: {t}" for t in numbers(prose) if not _matches(t, source, values)
        ]
    return missing


if __name__ == "__main__":
    write()
