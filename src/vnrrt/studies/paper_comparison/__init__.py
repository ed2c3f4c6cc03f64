"""The paper comparison (``paper_comparison.md``): the paper's Tables 1-3 and quoted claims
beside this reproduction's trials (stages ``evaluate`` and ``report``)."""
