"""Where work runs: in this process, a local process pool, or Dask.

Low in the tree, below the studies and the mesher, which both hand their work
units to :func:`~cospherical.execution.backends.completed`: ``backends`` chooses
and checks the backend (``--jobs``, ``--scheduler``, ``--dask-workers``),
``pool`` makes local process pools whose workers never outlive the command.
"""

__all__: list[str] = []  # the modules are the API: backends and pool
