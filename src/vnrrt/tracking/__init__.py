"""MLflow: the store, tags, experiments and the typed ``logger`` section (:mod:`.store`),
lineage of files and runs (:mod:`.lineage`), reports logged with their figures
(:mod:`.report_artifacts`)."""
