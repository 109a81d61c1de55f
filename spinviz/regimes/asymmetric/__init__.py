"""The boxes one crystal can grow as: where each one's spin ends as tau -> oo (``shape``: the
averaged flow's shape, a flow on one line), over a plane of two edge ratios (``atlas``)."""
