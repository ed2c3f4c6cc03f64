"""The offline template of `make plots`: DVC's placeholders kept, the libraries inline, no
CDN (the page itself is drawn in a browser by the slow test in tests/test_pipeline.py)."""

import re

from vnrrt.viz.plots_page import offline_page, write_offline_page


def test_the_template_carries_vega_inline_and_keeps_dvcs_placeholders(tmp_path):
    page = offline_page()
    assert "{plot_divs}" in page and "{refresh_tag}" in page and "{scripts}" not in page
    assert not re.search(r"<script[^>]+src=", page) and "http" not in page.split("<script>")[0]
    assert "window.vegaEmbed=" in page and len(page) > 500_000
    out = write_offline_page(tmp_path / "sub" / "t.html")
    assert out.read_text() == page
