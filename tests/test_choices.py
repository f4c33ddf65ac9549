"""The closed sets of names: each tuple is its Literal's values, and every command offers a set whole."""

from __future__ import annotations

import argparse
import typing

import cospherical.choices as choices
from cospherical.cli import build_parser

# Each tuple of names beside the Literal type it lists.
SETS = {name: getattr(choices, name) for name in choices.__all__ if isinstance(getattr(choices, name), tuple)}
TYPES = {name: getattr(choices, name) for name in choices.__all__ if typing.get_origin(getattr(choices, name)) is typing.Literal}


def test_each_tuple_lists_one_literal_in_its_order():
    listed = {values: name for name, values in SETS.items()}
    assert len(SETS) == len(TYPES) == 11
    for name, literal in TYPES.items():
        values = typing.get_args(literal)
        assert values in listed, f"{name}: no tuple lists its values"
        assert len(set(values)) == len(values) > 1 and all(isinstance(v, str) and v == v.strip() for v in values)


def test_the_sets_that_refine_others_are_their_subsets():
    assert choices.SPLIT_CRITERIA == tuple(c for c in choices.CRITERIA if c != "optimal")
    assert set(choices.POINT_POLICIES) < set(choices.FACE_POINT_SOURCES)
    assert set(choices.DELAUNAY_BACKENDS) - {"python"} == set(choices.KEY_BACKENDS) - {"numpy"} == {"compiled"}


def _options(parser: argparse.ArgumentParser, command: str = ""):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _options(sub, f"{command} {name}".strip())
        elif action.choices is not None:
            yield command, action.option_strings[0] if action.option_strings else action.dest, tuple(action.choices)


def test_every_option_offers_a_set_whole_and_in_order():
    # An option whose choices share a name with a set offers that set, not a hand-typed part of it
    # that a new name would miss.
    offered = list(_options(build_parser()))
    matched = 0
    for command, option, values in offered:
        sharing = [names for names in SETS.values() if set(values) & set(names)]
        if sharing:
            assert values in sharing, f"{command} {option}: {values} is none of {sharing}"
            matched += 1
    assert matched >= 6, offered  # criterion, face points (several commands), balance, delaunay, order
