"""cospherical: Delaunay tessellations of 1-irregular cuboids with co-spherical elements.

>>> from cospherical import Configuration, tessellate
>>> tess = tessellate(Configuration.from_code("888888888888"))
>>> len(tess.elements), tess.elements[0].type.name
(8, 'cuboid')
"""

from .configuration import Box, Configuration
from .element_types import ElementType
from .exact import InputError, Length
from .tessellation import Element, Tessellation, tessellate

__version__ = "0.1.0"

__all__ = [
    "Box",
    "Configuration",
    "Element",
    "ElementType",
    "InputError",
    "Length",
    "Tessellation",
    "tessellate",
    "__version__",
]
