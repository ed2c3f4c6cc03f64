"""An HTML template for ``dvc plots show`` that renders without network access.

DVC's default page loads Vega, Vega-Lite and Vega-Embed from a CDN, so on an offline machine
(a cluster node) it shows nothing. This template carries the three libraries inline (the
bundle that ``vl-convert-python`` ships, ~0.9 MB) and keeps DVC's placeholders, so DVC fills
in the plots as usual. ``make setup`` writes it to ``.dvc/tmp/plots_offline.html``, which
``.dvc/config`` names as ``plots.html_template``; ``python -m vnrrt.viz.plots_page`` writes it
again.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from vnrrt.infra.io import write_text

DEFAULT_OUT = Path(".dvc/tmp/plots_offline.html")
PAGE = """<!DOCTYPE html>
<html>
<head>
    {refresh_tag}
    <meta charset="utf-8">
    <title>vnrrt: DVC plots</title>
    <script>
%s
    </script>
    <style>
        table {
            border-spacing: 15px;
        }
    </style>
</head>
<body>
    {plot_divs}
</body>
</html>
"""
PLACEHOLDERS = ("{plot_divs}", "{refresh_tag}", "{scripts}")


def offline_page() -> str:
    """The template (module doc): DVC's page with the libraries inline and no ``{scripts}``
    placeholder (the one DVC fills with CDN links)."""
    import vl_convert

    bundle = vl_convert.javascript_bundle()
    if "</script" in bundle.lower() or any(p in bundle for p in PLACEHOLDERS):
        raise ValueError("the Vega bundle cannot be inlined: it holds '</script' or a placeholder")
    return PAGE % bundle


def write_offline_page(out: str | Path = DEFAULT_OUT) -> Path:
    """Write :func:`offline_page` to ``out`` (atomically); returns the path."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, offline_page())
    return out


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help="template file to write")
    write_offline_page(p.parse_args(argv).out)


if __name__ == "__main__":
    main()
