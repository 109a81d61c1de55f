"""Analysis of finished runs: ``compare`` (the two models' predictions side by side) and
``info`` (a body's derived quantities beside the figures the paper prints)."""
