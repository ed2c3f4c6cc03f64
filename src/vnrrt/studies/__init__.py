"""The studies built on the evaluation engine (:mod:`vnrrt.evaluation`), one subpackage each,
named after its report: :mod:`.paper_comparison`, :mod:`.sampling_ideas`,
:mod:`.training_budget`; :mod:`.paper_tables` reads the paper's published numbers."""
