"""The member table of ``dual.npz``: what the writer writes, kind and shape; the bounds on exact texts."""

from __future__ import annotations

import io
import zipfile

import numpy as np

from cospherical.formats.dual import members


def test_every_member_written_is_of_its_kind_and_shape_and_no_other_is(dual_run):
    with zipfile.ZipFile(dual_run / "a" / "dual.npz") as archive:
        arrays = {info.filename[:-4]: np.lib.format.read_array(io.BytesIO(archive.read(info)))
                  for info in archive.infolist()}
    assert set(arrays) == {"manifest", *members._MEMBERS}  # a one-box mesh: version 3
    counts = {"n": len(arrays["grid_vertices"]), "m": len(arrays["edges"]), "e": len(arrays["element_sizes"])}
    for name, (kinds, columns, count) in members._MEMBERS.items():
        array = arrays[name]
        assert array.dtype.kind in kinds and array.shape[0] == counts[count], name
        if columns == "w":
            assert array.ndim == 2 and 4 <= array.shape[1] <= members._MAX_ELEMENT_NODES, name
        else:
            assert array.shape[1:] == (() if columns is None else (columns,)), name


def test_exact_texts_are_bounded_in_digits():
    most = members._MAX_TEXT_DIGITS
    assert members._INTEGER.fullmatch("-" + "9" * most) and not members._INTEGER.fullmatch("9" * (most + 1))
    assert members._POSITIVE.fullmatch("1" + "0" * (most - 1)) and not members._POSITIVE.fullmatch("0")
    assert members._POSITIVE_FRACTION.fullmatch("3/4") and not members._POSITIVE_FRACTION.fullmatch("3/0")
    assert not members._FRACTION.fullmatch("1e999999999") and not members._INTEGER.fullmatch("--5")
