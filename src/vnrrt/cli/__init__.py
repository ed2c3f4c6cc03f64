"""Command lines: ``vnrrt plan``, ``vnrrt predict`` (:mod:`.main`, inputs read by
:mod:`.inputs`) and the runner of every stage script (:mod:`.stage`: arguments, exit codes,
error reports)."""
