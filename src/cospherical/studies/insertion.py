"""The insertion orders of the intersection study's midpoint scheme (explained in
:mod:`cospherical.studies.intersection.family`).

Apart from the study, which loads numpy, so that the command line can offer them
without loading it.
"""

__all__ = ["INSERTION_ORDERS"]

INSERTION_ORDERS = ("edge", "rank", "reverse")
