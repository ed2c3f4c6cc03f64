"""Every figure of the project (matplotlib, Agg backend). Nothing else imports matplotlib.

One module per consumer, so that a stage depends only on the figures it draws:
:mod:`.common` (saving, floor maps, heatmaps), :mod:`.maps` (Fig. 4), :mod:`.planners`
(a planner run), :mod:`.training` (the per-epoch validation figure), :mod:`.evaluation`
(Fig. 3, Fig. 5, convergence, the oracle and regime studies).

Coordinates as in :mod:`vnrrt.grid`: images are drawn with ``extent=(0, W, H, 0)`` so a
continuous point (x, y) is plotted at x right, y down, and a cell (x, y) at its centre
(x + 0.5, y + 0.5). Obstacles are black everywhere, the start a green star, the goal a red
cross (the paper's Fig. 4 style).
"""
