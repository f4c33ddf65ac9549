"""Hand-offs to other libraries: a mesh given to a simulator or a viewer in memory.

Above the formats (an adapter may read a mesh folder) and below the command line.
Each adapter imports its library inside its functions: the library is an optional
extra (``pip install cospherical[devsim]``), and a missing one is one clear error line.
"""

__all__: list[str] = []  # nothing re-exported: the public names are each module's __all__
