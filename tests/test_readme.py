"""Every Python snippet of the README runs as written, from the repository root."""

import pytest
from examples import ROOT, python_examples, run_python_example

SNIPPETS = python_examples((ROOT / "README.md").read_text())


def test_the_readme_has_python_snippets():
    assert len(SNIPPETS) >= 1  # the front door's one; the others live in docs/ (tests/test_docs.py runs them)


@pytest.mark.parametrize("snippet", SNIPPETS, ids=[f"snippet{i}" for i in range(len(SNIPPETS))])
def test_snippet_runs(snippet):
    printed = run_python_example(snippet, ROOT, "README.md")
    assert printed.strip(), "a README snippet shows its result"


def test_the_readme_links_into_files_that_exist():
    import re

    text = (ROOT / "README.md").read_text()
    links = [link for link in re.findall(r"\]\(([^)#\s]+)[^)]*\)", text) if "://" not in link]
    assert any(link.startswith("docs/") for link in links), "the front door links into the site"
    assert [link for link in links if not (ROOT / link).exists()] == []
