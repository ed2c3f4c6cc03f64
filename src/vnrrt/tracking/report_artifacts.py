"""A markdown report as MLflow artifacts that read in the UI's artifact viewer.

MLflow's markdown viewer (3.17) shows an image whose path is relative as the text
``[alt](path)``, and resolves a relative link against the UI's page rather than the artifact.
So a report ``<name>.md`` is logged (:func:`log_report`) as:

* ``<name>.md``: the report's text, each figure it shows logged beside it under the path it
  uses (a downloaded artifact folder reads as the repository's file does), and its links to
  other reports replaced by the UI links given (``links``: target -> link);
* ``<name>.html``: the same text rendered, figures inline (data URIs), which the viewer shows
  in a frame: the report with its figures in the browser.
"""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

IMAGE = re.compile(r"!\[([^\]]*)\]\(([^)\s]+)\)")  # ![alt](path)
LINK = re.compile(r"(?<!!)\[([^\]]*)\]\(([^)\s]+)\)")  # [text](target), not an image
MIME = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml"}
STYLE = """body{font:14px/1.5 -apple-system,'Segoe UI',Helvetica,Arial,sans-serif;margin:16px;
color:#1f2328;max-width:1100px}table{border-collapse:collapse;margin:8px 0}th,td{border:1px
solid #d0d7de;padding:3px 8px}th{background:#f6f8fa}img{max-width:100%}code{background:#f6f8fa;
padding:0 3px}"""


def figure_paths(text: str) -> list[str]:
    """The local files a markdown ``text`` shows as images (relative paths, in order, each
    once; URLs left out)."""
    found = [m.group(2) for m in IMAGE.finditer(text)]
    return list(dict.fromkeys(p for p in found if "://" not in p and not p.startswith("data:")))


def with_links(text: str, links: dict[str, str]) -> str:
    """``text`` with every link whose target is a key of ``links`` pointing at its value."""

    def swap(m: re.Match) -> str:
        target = links.get(m.group(2))
        return m.group(0) if target is None else f"[{m.group(1)}]({target})"

    return LINK.sub(swap, text)


def to_html(text: str, folder: Path, title: str) -> str:
    """The markdown ``text`` as one HTML page, its local figures (relative to ``folder``)
    inlined as data URIs."""
    from markdown_it import MarkdownIt

    def inline(m: re.Match) -> str:
        path = folder / m.group(2)
        if m.group(2) not in figure_paths(m.group(0)) or not path.is_file():
            return m.group(0)
        data = base64.b64encode(path.read_bytes()).decode()
        mime = MIME.get(path.suffix.lower(), "application/octet-stream")
        return f"![{m.group(1)}](data:{mime};base64,{data})"

    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(IMAGE.sub(inline, text))
    return (
        f'<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>{html.escape(title)}'
        f"</title><style>{STYLE}</style></head><body>\n{body}</body></html>\n"
    )


def log_report(client, run_id: str, path: Path, links: dict[str, str] | None = None) -> list[str]:
    """Log the report ``path`` to run ``run_id`` (module doc); returns the artifact paths
    written. A figure the report shows that is missing is a ``FileNotFoundError``."""
    path = Path(path)
    text = with_links(path.read_text(), links or {})
    written = []
    for rel in figure_paths(text):
        figure = path.parent / rel
        if ".." in Path(rel).parts or Path(rel).is_absolute():
            raise ValueError(f"{path} shows {rel}: a figure outside the report's folder")
        if not figure.is_file():
            raise FileNotFoundError(f"{path} shows {rel}, which is not a file at {figure}")
        folder = str(Path(rel).parent)
        client.log_artifact(run_id, str(figure), None if folder == "." else folder)
        written.append(rel)
    client.log_text(run_id, text, path.name)
    client.log_text(run_id, to_html(text, path.parent, path.stem), path.stem + ".html")
    return [*written, path.name, path.stem + ".html"]
