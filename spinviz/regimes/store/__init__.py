"""The atlas store: ``dataset`` (the xarray / Zarr store: creation, identity, chunk writes,
reading, refinement levels), ``integrity`` (a checksum record per chunk, verified before a
resume) and ``verify`` (``--verify``'s report)."""
