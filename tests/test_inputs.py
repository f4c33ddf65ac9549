"""Every input of the mesher and the table readers bounded and checked before the work.

Hostile files through the real CLI: one line on stderr, exit 2, no traceback.  The
heavy ones run in a child process under a 1 GiB address-space limit and a time
limit, so a reader that inflates what it is given fails the test instead of the
machine.  Hypothesis fuzzes the leaf-list and refine grammars (exit 0 or 2, never
a traceback) and compares the exact cell tests with a brute force in Fractions.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from strategies import BOXES, shapes

from cospherical.cli import main
from cospherical.mesh import octree

ROOT = Path(__file__).resolve().parents[1]
PATTERNS = ROOT / "patterns"
GiB = 1 << 30
QUICK = ("--no-delaunay", "--no-uniform")


def run(*argv) -> tuple[int, str, str]:
    """The CLI in-process: (exit status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main([str(a) for a in argv])
    return status, out.getvalue(), err.getvalue()


def one_line(status: int, err: str, *needles: str) -> str:
    assert status == 2, (status, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle.lower() in lines[0].lower(), lines[0]
    return lines[0]


def _limits(seconds: int):
    def apply():
        resource.setrlimit(resource.RLIMIT_AS, (GiB, GiB))
        resource.setrlimit(resource.RLIMIT_CPU, (seconds, seconds))
    return apply


def bounded(*argv, seconds: int = 60) -> tuple[subprocess.CompletedProcess, float]:
    """The CLI as a child under 1 GiB of address space and ``seconds`` of CPU: (result, wall seconds)."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "cospherical", *map(str, argv)], capture_output=True, text=True,
                            timeout=3 * seconds, preexec_fn=_limits(seconds), env=env)
    return result, time.perf_counter() - start


# ---------------------------------------------------------------------------
# Leaf lists


@pytest.mark.parametrize("name, text, needle", [
    ("double-minus.txt", "--0 0 0 0\n", "line 1"),
    ("long.txt", "0 0 0 " + "1" * 5000 + "\n", "12 digits"),
    ("long.json", '{"leaves": [[0, 0, 0, ' + "1" * 5000 + "]]}", "5,000 digits"),
    ("repeated.json", '{"leaves": [[1, 0, 0, 0]], "leaves": [[0, 0, 0, 0]]}', "repeated key 'leaves'"),
    ("float.json", '{"leaves": [[0, 0, 0, 0.0]]}', "leaf 0"),
    ("bool.json", '{"leaves": [[0, 0, 0, true]]}', "leaf 0"),
    ("unicode.txt", "0 0 0 \u0661\n", "line 1"),
])
def test_hostile_leaf_lists_are_refused_in_one_line(tmp_path, name, text, needle):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    one_line(*run("mesh", "--domain", 1, 1, 1, "--leaves", path, *QUICK)[::2], needle)


def test_leaf_count_is_bounded_before_the_leaves_are_read(tmp_path):
    # Lines (text) and brackets (JSON) bound the leaves: refused from that count, in the
    # time it takes to read the file, with the bound in the line.
    text = tmp_path / "many.txt"
    text.write_text("0 0 0 0\n" * 200_000)
    listed = tmp_path / "many.json"
    listed.write_text(json.dumps({"leaves": [[0, 0, 0, 0]] * 200_000}))
    for path in (text, listed):
        result, seconds = bounded("mesh", "--domain", 1, 1, 1, "--leaves", path, "--max-leaves", 100_000, seconds=30)
        one_line(result.returncode, result.stderr, "200,000 leaves", "bound of 100,000")
        assert seconds < 20
        one_line(*run("mesh", "--domain", 1, 1, 1, "--leaves", path, "--max-leaves", 1000)[::2],
                 "more than a list of 1,000 leaves")
    # the default bound is what the machine holds; a tree within it passes
    assert octree.leaf_bound() > 100_000
    status, out, err = run("mesh", "--domain", 1, 1, 1, "--leaves", _write(tmp_path, "one.txt", "0 0 0 0\n"),
                           "--max-leaves", 1, *QUICK)
    assert status == 0 and "leaves: 1\n" in out, err


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


LEAF_LINES = st.lists(st.one_of(
    st.tuples(*[st.integers(-3, 9)] * 4).map(lambda t: " ".join(map(str, t))),
    st.text(alphabet="0123456789- #\t1e.+", max_size=16),
    st.sampled_from(["# note", "", "0 0 0 0", "1 0 0 0", "1 1 1 1", "99999999999999 0 0 0"]),
), max_size=10)


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(lines=LEAF_LINES, as_json=st.booleans())
def test_fuzz_leaf_lists_never_traceback(tmp_path_factory, lines, as_json):
    folder = tmp_path_factory.mktemp("leaves")
    if as_json:
        rows = [line.split() for line in lines]
        text = json.dumps({"leaves": [[int(x) if x.lstrip("-").isdigit() else x for x in row] for row in rows]})
    else:
        text = "\n".join(lines)
    status, out, err = run("mesh", "--domain", 1, 1, 1, "--leaves", _write(folder, "l.txt", text), *QUICK)
    assert status in (0, 2) and "Traceback" not in err
    if status == 2:
        one_line(status, err)


# ---------------------------------------------------------------------------
# Refinement shapes and the tree's size


@pytest.mark.parametrize("domain, shape", [
    ((1, 1, 1), "point:0.1234567891,0.5,0.5"),
    ((1, 1, 1), "point:1e-10,0.5,0.5"),
    (("3e9", 1, 1), "point:1,0.5,0.5"),
    (("3e9", 1, 1), "box:0,0,0,1e9,1,1"),
    (("3e9", 1, 1), "sphere:1e9,0.5,0.5,3"),
    (("sqrt(2)", "1e-12", 1), "box:0.1234567891,0,0,0.2,1e-13,0.5"),
])
def test_refine_numbers_beyond_int64_are_decided_exactly(domain, shape):
    # the leaves' own tessellations: what the octree decides is the subject here, not the global subdivision
    status, out, err = run("mesh", "--domain", *domain, "--refine", shape, "--levels", 3, "--delaunay", "leaf", *QUICK)
    assert status == 0, err
    assert "volume_ok: true" in out


def test_tree_size_is_estimated_and_refused_at_once():
    for argv in (("--levels", 16, "--refine", "box:0,0,0,1,1,1"), ("--levels", 11, "--refine", "plane:1,1,1,1.5")):
        result, seconds = bounded("mesh", "--domain", 1, 1, 1, *argv, seconds=30)
        line = one_line(result.returncode, result.stderr, "an estimated", "bound of", "--max-leaves")
        assert seconds < 15, (seconds, line)
    one_line(*run("mesh", "--domain", 1, 1, 1, "--refine", "point:0.3,0.3,0.3", "--levels", 4,
                  "--max-leaves", 10)[::2], "bound of 10")
    one_line(*run("mesh", "--domain", 1, 1, 1, "--refine", "point:0.3,0.3,0.3", "--levels", 4,
                  "--max-leaves", "-5")[::2], "--max-leaves")


REFINE_TEXT = st.one_of(shapes(), st.text(alphabet="pointboxsphereplane:,.0123456789-e/+()sqrt ", max_size=30))


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(text=REFINE_TEXT, texts=BOXES, levels=st.sampled_from(["0", "1", "2", "x", "-1", "17"]))
def test_fuzz_refine_never_tracebacks(text, texts, levels):
    status, out, err = run("mesh", "--domain", *texts, "--refine", text, "--levels", levels, *QUICK)
    assert status in (0, 2) and "Traceback" not in err, err
    if status == 2:
        one_line(status, err)


# ---------------------------------------------------------------------------
# Element node lists: one validation for check and mesh, before any geometry


def _table(folder: Path, name: str, nodes, type_id: str) -> Path:
    source = (PATTERNS / "leaves-1x1x1.yaml").read_text()
    header = source[:source.index("configurations:\n") + len("configurations:\n")]
    entry = {"fvm_adequate": True, "optimal": [{"type": type_id, "nodes": nodes, "circumcenter": [0.5, 0.5, 0.5]}],
             "internal_faces": "optimal", "internal_edges_and_faces": "optimal"}
    return _write(folder, name, header + "  '000000000000+f': " + json.dumps(entry) + "\n")


@pytest.mark.parametrize("nodes, type_id, needle", [
    ([0] * 300, "v8f6-c3cb81", "27 items"),
    ([0, 1, 2, 3, 4, 5, 6, 6], "v8f6-c3cb81", "unique"),
    ([0, 1, 2, 3, 4], "v4f4-8f0284", "5 nodes for a type of 4 vertices"),
    ([0, 1, 2, 3, 4, 5, 6, 7, 8], "v8f6-c3cb81", "9 nodes for a type of 8 vertices"),
])
def test_bad_node_lists_are_refused_by_check_and_mesh_alike(tmp_path, nodes, type_id, needle):
    path = _table(tmp_path, "bad.yaml", nodes, type_id)
    one_line(*run("check", path)[::2], needle)
    result, seconds = bounded("mesh", "--domain", 1, 1, 1, "--refine", "point:0.5,0.5,0.5", "--levels", 0,
                              "--patterns", path, "--out", tmp_path / "out", *QUICK, seconds=60)
    one_line(result.returncode, result.stderr, needle)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_a_table_of_another_element_is_refused_naming_both():
    line = one_line(*run("mesh", "--domain", 1, 1, 1, "--refine", "point:0.5,0.5,0.5", "--levels", 1,
                         "--patterns", PATTERNS / "bisection-prism-1x1x1.yaml", *QUICK)[::2], "prism", "cuboid")
    assert "1 x 1 x 1" in line


# ---------------------------------------------------------------------------
# Stores, YAML and shape files: sizes bounded before they are read


def _store(folder: Path) -> Path:
    from cospherical.formats.patterns import load
    from cospherical.formats.sqlite_store import dictionary_of, pack, write_store

    table = load(PATTERNS / "leaves-1x1x1.yaml")
    codes = sorted(table.configurations)[:20]
    texts = [table.configurations.text(code) for code in codes]
    dictionary = dictionary_of(texts)
    path = folder / "t.sqlite"
    write_store(path, table.header, dictionary, [(c, pack(t, dictionary)) for c, t in zip(codes, texts)])
    return path


def test_a_store_entry_is_bounded_by_its_stored_size_and_its_header_by_its_keys(tmp_path):
    import sqlite3

    path = _store(tmp_path)
    assert run("check", path)[0] == 0
    from cospherical.formats.sqlite_store import MAX_ENTRY

    connection = sqlite3.connect(path)
    code = connection.execute("SELECT code FROM entries ORDER BY code LIMIT 1").fetchone()[0]
    connection.execute("UPDATE entries SET entry = zeroblob(?) WHERE code = ?", (4 * MAX_ENTRY, code))
    connection.commit()
    connection.close()
    result, seconds = bounded("check", path, seconds=30)
    one_line(result.returncode, result.stderr, f"stored in over {MAX_ENTRY} bytes")
    from cospherical.errors import FormatError
    from cospherical.formats.patterns import load
    from cospherical.formats.sqlite_store import open_store

    # refused when opened, before any lookup: a lookup by code reads every b-tree cell it compares
    # with whole (a 900 MB entry: 935 MB for 'mesh --patterns' to refuse it), whatever the query bounds
    with pytest.raises(FormatError, match="stored in over"):
        open_store(path)
    result, seconds = bounded("mesh", "--domain", 1, 1, 1, "--refine", "point:0.5,0.5,0.5", "--levels", 0,
                              "--patterns", path, *QUICK, seconds=30)
    one_line(result.returncode, result.stderr, f"stored in over {MAX_ENTRY} bytes")
    (tmp_path / "c").mkdir()
    with pytest.raises(KeyError):  # the store's contract is the YAML table's
        load(_store(tmp_path / "c")).elements(["x"])

    (tmp_path / "b").mkdir()
    again = _store(tmp_path / "b")
    connection = sqlite3.connect(again)
    header = connection.execute("SELECT value FROM meta WHERE key = 'header'").fetchone()[0]
    connection.execute("UPDATE meta SET value = ? WHERE key = 'header'",
                       ('{"study": "x", ' + header[1:],))
    connection.commit()
    connection.close()
    one_line(*run("check", again)[::2], "repeated key 'study'")


def test_block_style_yaml_beyond_the_parser_bound_is_refused_at_once(tmp_path):
    from cospherical.files.yamlio import MAX_YAML_PARSE

    path = tmp_path / "block.yaml"
    row = "  - type: v8f6-c3cb81\n    nodes:\n    - 0\n    - 1\n"
    path.write_text("schema_version: 1\nconfigurations:\n  '000000000000':\n    optimal:\n"
                    + row * (MAX_YAML_PARSE // len(row) + 1))
    result, seconds = bounded("check", path, seconds=30)
    one_line(result.returncode, result.stderr, f"at most {MAX_YAML_PARSE:,}")
    assert seconds < 15


@pytest.mark.parametrize("count, needle", [(2000, "4 to 64 corners"), (60, "coplanar")])
def test_shape_corners_are_bounded_and_coplanarity_is_one_pass(tmp_path, count, needle):
    # every corner on the parabola y = x**2 in z = 0: no three on a line, all on one plane
    shape = {"corners": [[str(i), str(i * i), "0"] for i in range(count)],
             "edges": [[i, (i + 1) % count] for i in range(count)],
             "faces": [list(range(count)), list(range(count))[::-1]]}
    path = _write(tmp_path, "flat.json", json.dumps(shape))
    start = time.perf_counter()
    one_line(*run("tessellate", "--shape", path, "--box", 1, 1, 1)[::2], needle)
    assert time.perf_counter() - start < 5


# ---------------------------------------------------------------------------
# Checkpoints of the intersection study: a checksum each, bounds on every value


def _with_checksum(payload: bytes) -> bytes:
    from cospherical.studies.intersection.run import _checkpoint_bytes

    return _checkpoint_bytes(payload)  # what an attacker who knows the format writes: the sum holds


def _payload(path: Path) -> bytes:
    return path.read_bytes().split(b"\n", 1)[1]


def _cells_with(path: Path, **changes) -> bytes:
    from cospherical.studies.intersection.run import CELL_NAMES

    with np.load(io.BytesIO(_payload(path))) as data:
        arrays = {name: data[name] for name in CELL_NAMES}
    arrays.update({k: v(arrays[k]) for k, v in changes.items()})
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


def _deflated(path: Path) -> bytes:
    import zipfile

    buffer = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(_payload(path))) as source, \
            zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as target:
        for info in source.infolist():
            target.writestr(info.filename, source.read(info))
    return buffer.getvalue()


def _elements_with(path: Path, change) -> bytes:
    entries, types = json.loads(_payload(path))
    return json.dumps(change(entries, types)).encode()


def _claiming(path: Path) -> bytes:
    """A stage-1 archive whose first array's header claims 500 M int64 (4 GB) it does not hold."""
    import zipfile

    buffer = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(_payload(path))) as source, zipfile.ZipFile(buffer, "w") as target:
        for n, info in enumerate(source.infolist()):
            data = source.read(info)
            if n == 0:
                header = np.lib.format.header_data_from_array_1_0(np.zeros(1, dtype=np.int64))
                header["shape"] = (500_000_000,)
                head = io.BytesIO()
                np.lib.format.write_array_header_1_0(head, header)
                data = head.getvalue() + data[-64:]
            target.writestr(info.filename, data)
    return buffer.getvalue()


DAMAGE = {
    "garbage": ("cells", lambda p: b"\x00garbage"),
    "one mask everywhere, sum not renewed": ("cells", lambda p: p.read_bytes().split(b"\n", 1)[0] + b"\n" + _cells_with(
        p, poly_mask=lambda a: np.full_like(a, a[0]))),
    "tetrahedra 10**15": ("cells", lambda p: _with_checksum(_cells_with(p, tets=lambda a: a + 10**15))),
    "closed stored as 7": ("cells", lambda p: _with_checksum(_cells_with(p, closed=lambda a: np.full(len(a), 7)))),
    "a deflated array": ("cells", lambda p: _with_checksum(_deflated(p))),
    "an array claiming 500 M int64": ("cells", lambda p: _with_checksum(_claiming(p))),
    "nested 100,000 deep": ("elements", lambda p: _with_checksum(b"[" * 100_000 + b"]" * 100_000)),
    "a type not among its chunk's": ("elements", lambda p: _with_checksum(_elements_with(
        p, lambda e, t: [[{**e[0], "type": "v9f9-000000"}, *e[1:]], t]))),
    "fewer entries than elements": ("elements", lambda p: _with_checksum(_elements_with(p, lambda e, t: [e[:-1], t]))),
    # each value in range, the sum renewed: only stage 2, which finds the names are not cells of their
    # configurations, can tell (it was a ValueError traceback; a mask that is a cell elsewhere counted wrongly)
    "one mask everywhere, sum renewed": ("cells", lambda p: _with_checksum(_cells_with(
        p, poly_mask=lambda a: np.full_like(a, a[0])))),
}


@pytest.fixture(scope="module")
def intersection_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    args = ["study", "intersection", "--resolution", 2, "--jobs", 1, "--out", out, "--resume", "--chunk-size", 20,
            "--format", "json"]
    status, summary, err = run(*args)
    assert status == 0, err
    return out, args, json.loads(summary)


@pytest.mark.parametrize("damage", sorted(DAMAGE))
def test_a_damaged_checkpoint_is_computed_again_never_counted(intersection_run, damage):
    out, args, full = intersection_run
    stage, write = DAMAGE[damage]
    path = sorted((out / "checkpoints").glob(f"*-{stage}-*"))[0]
    original = path.read_bytes()
    path.write_bytes(write(path))
    status, summary, err = run(*args)
    assert status == 0 and "Traceback" not in err, err
    notes = [line for line in err.splitlines() if "damaged checkpoint" in line]
    assert len(notes) == 1 and path.name in notes[0] and "computed again" in notes[0], err
    assert json.loads(summary) == full
    assert path.read_bytes() == original  # rewritten whole, the same bytes


@pytest.mark.parametrize("stage", ["cells", "elements"])
def test_a_fifo_in_a_checkpoints_place_is_noted_not_waited_on(intersection_run, stage):
    """open() and read() of a FIFO block until a writer comes: --resume hung for ever. Now it is noted as
    damaged, and the checkpoint is not written over a special file the user put there (one line, exit 2)."""
    out, args, _ = intersection_run
    path = sorted((out / "checkpoints").glob(f"*-{stage}-*"))[0]
    original = path.read_bytes()
    path.unlink()
    os.mkfifo(path)
    try:
        status, _, err = run(*args)
    finally:
        path.unlink()
        path.write_bytes(original)
    assert status == 2 and "Traceback" not in err, err
    assert f"damaged checkpoint {path.name} (not a regular file)" in err, err
    assert err.strip().splitlines()[-1].endswith("not a regular file: not replacing it"), err


def test_a_store_with_a_long_code_is_refused_without_reading_it(tmp_path):
    """length() of a text reads it whole: a 150 MB code took as much memory to refuse as it is long."""
    import sqlite3

    path = _store(tmp_path)
    connection = sqlite3.connect(path)
    connection.execute("INSERT INTO entries VALUES (?, zeroblob(10))", ("0" * 150_000_000,))
    connection.commit()
    connection.close()
    program = ("import re, sys\n"
               "from cospherical.errors import FormatError\n"
               "from cospherical.formats.sqlite_store import open_store\n"
               "try:\n    open_store(sys.argv[1])\nexcept FormatError as error:\n    print(error)\n"
               # this process's peak (ru_maxrss would be the parent's, kept across exec)
               "print(re.search(r'VmHWM:\\s*(\\d+)', open('/proc/self/status').read()).group(1))")
    result = subprocess.run([sys.executable, "-c", program, str(path)], capture_output=True, text=True, timeout=120)
    line, peak_kb = result.stdout.splitlines()
    assert "store damaged: an entry is stored in over" in line, result
    assert int(peak_kb) < 100_000, peak_kb  # 150 MB and more before


def test_a_store_entry_with_a_bad_node_list_is_refused_like_a_yaml_one(tmp_path):
    import sqlite3

    from cospherical.formats.sqlite_store import pack

    path = _store(tmp_path)
    connection = sqlite3.connect(path)
    (dictionary,) = connection.execute("SELECT data FROM dictionary").fetchone()
    code = connection.execute("SELECT code FROM entries ORDER BY code LIMIT 1").fetchone()[0]
    entry = {"fvm_adequate": True, "optimal": [{"type": "v4f4-8f0284", "nodes": [0] * 300,
                                                "circumcenter": [0.5, 0.5, 0.5]}],
             "internal_faces": "optimal", "internal_edges_and_faces": "optimal"}
    connection.execute("UPDATE entries SET entry = ? WHERE code = ?", (pack(json.dumps(entry), dictionary), code))
    connection.commit()
    connection.close()
    one_line(*run("check", path)[::2], "27 items")
    from cospherical.formats.patterns import load

    with pytest.raises(Exception, match="27 items"):
        load(path).elements(code)
