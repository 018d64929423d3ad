"""Generated test traffic: bench-like pulse recordings from a known slip history (:mod:`.bench`)."""
