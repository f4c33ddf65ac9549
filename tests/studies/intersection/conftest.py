"""The intersection study's runs that several test modules read: made once per test process."""

from __future__ import annotations

import pytest

from cospherical.studies.intersection import run_intersection


@pytest.fixture(scope="session")
def r4_study():
    """The R = 4 study, run in this process (the pool and Dask are held to one process in test_run.py), and
    an example of every type it met (``run_intersection``'s ``examples``: type id -> node mask, code, ...)."""
    examples: dict = {}
    return run_intersection(4, examples=examples), examples


@pytest.fixture(scope="session")
def r4_run(r4_study):
    """The R = 4 study's summary."""
    return r4_study[0]


@pytest.fixture(scope="session")
def r4_table(r4_study, full, tmp_path_factory):
    """The R = 4 pattern table, as YAML and as an indexed store, made in this process.

    By default its entries are those of a sample of the representatives: every one that holds an example of
    a type the study met (so every type of the whole table is in it) and a seeded 1 in 16 of the others
    (1 in 8 until the suite's budget asked for 2 CPU-s more); with ``--full`` all 32,077 (the sample's table
    costs about 1 CPU-s, the whole one 9). One process:
    the table's pool path, and that it writes the same bytes as one process, is
    formats/test_intersection_table.py's test_pattern_table_of_the_representatives."""
    import numpy as np

    from cospherical.catalogue import shipped_catalogue
    from cospherical.formats.intersection_table import write_pattern_table
    from cospherical.studies.intersection.table import TableRun

    summary, examples = r4_study
    run = TableRun(summary, jobs=1)
    if not full:
        holders = np.isin(run.reps, [example[1] for example in examples.values()])
        run.reps = run.reps[holders | (np.random.default_rng(4).random(len(run.reps)) < 1 / 16)]
    folder = tmp_path_factory.mktemp("r4")
    write_pattern_table(run, shipped_catalogue().version, yaml_path=folder / "r4.yaml", store=folder / "r4.sqlite")
    return folder / "r4.yaml", folder / "r4.sqlite"
