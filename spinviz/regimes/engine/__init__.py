"""The atlas's engine: ``runs`` (batches of Euler-only runs through the one driver, each
classified where it ran), ``classify`` (label, confidence, evidence) and ``refine`` (which
cells of a level are cut in four for the next)."""
