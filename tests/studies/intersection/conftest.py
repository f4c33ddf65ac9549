"""The intersection study's runs that several test modules read: made once per test process."""

from __future__ import annotations

import pytest

from cospherical.studies.intersection import run_intersection


@pytest.fixture(scope="session")
def r4_run():
    """The R = 4 study, run in this process (the pool and Dask are held to one process in test_run.py)."""
    return run_intersection(4)


@pytest.fixture(scope="session")
def r4_table(r4_run, tmp_path_factory):
    """The R = 4 pattern table, as YAML and as an indexed store, made in this process.

    One process: a pool of two adds its workers' start-up (about 11 CPU-s against 9 at load 5). The
    table's pool path, and that it writes the same bytes as one process, is
    formats/test_intersection_table.py's test_pattern_table_of_the_representatives."""
    from cospherical.catalogue import shipped_catalogue
    from cospherical.formats.intersection_table import write_pattern_table
    from cospherical.studies.intersection.table import TableRun

    folder = tmp_path_factory.mktemp("r4")
    write_pattern_table(TableRun(r4_run, jobs=1), shipped_catalogue().version, yaml_path=folder / "r4.yaml",
                        store=folder / "r4.sqlite")
    return folder / "r4.yaml", folder / "r4.sqlite"
