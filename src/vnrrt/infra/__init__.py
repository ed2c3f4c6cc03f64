"""Infrastructure without domain knowledge: atomic file writes and hashes (:mod:`.io`), process
pools (:mod:`.parallel`)."""
