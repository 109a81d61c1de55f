"""Where work runs: the services every long command shares.

* ``processes``: the cores this process may use (``usable_cores``) and a pool of worker
  processes that map a function over items in order and stop clean (``ProcessMapper``);
  standard library only, so the schema can ask how many cores there are.
* ``cluster``: a Dask cluster -- the embedded ``LocalCluster`` or an existing one by its
  address -- with the waits, signals and shutdown a command needs (``Cluster``, ``polled``);
  it loads Dask when imported, so only the commands that run on Dask import it.

The atlas (``regimes``), ``decide`` (``spinviz.experiment``) and rendering use them; none of
them keeps an executor of its own.
"""
