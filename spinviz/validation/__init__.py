"""Validation and measurement tools: ``checks`` (the paper's closed forms), ``stress`` (stiff
and extreme cases), ``bench`` (work-precision), ``render_bench`` (frames per second) and
``report`` (regenerates docs/accuracy.md).  The core never imports them."""
