"""The element catalogue (a :class:`Catalogue`): names of the known types, and the paper's criteria (kept sets, splits)."""

from .build import build_catalogue, intersection_examples
from .criteria import (
                       Choice,
                       apply_catalogue_criterion,
                       choose,
                       choose_kept,
                       element_options,
                       kept_split,
                       minimal_kept_sets,
                       option_types,
                       split_options,
                       split_positions,
                       split_tessellation,
)
from .model import Catalogue, CatalogueType, Example, ReferenceFace, SplitPiece
from .names import (SCHEMA_VERSION, catalogue_from_text, catalogue_path, known_name, load_catalogue,
                    shipped_catalogue, type_name, type_names)

__all__ = ["SCHEMA_VERSION", "Catalogue", "CatalogueType", "Choice", "Example", "ReferenceFace", "SplitPiece",
           "apply_catalogue_criterion", "build_catalogue",
           "catalogue_from_text", "intersection_examples",
           "catalogue_path",
           "choose", "choose_kept", "element_options", "kept_split", "known_name", "load_catalogue", "minimal_kept_sets",
           "option_types", "shipped_catalogue", "split_options", "split_positions", "split_tessellation", "type_name",
           "type_names"]
