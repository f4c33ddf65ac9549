"""The documentation site: it builds with warnings as errors, its examples run, it renders.

The site is built once per test session into a temporary folder (``mkdocs build
--strict``: a broken link, a missing anchor or reference, a snippet that is not there
fails the build), shared by the xdist workers. Its shell and Python examples run as the
README's do, through ``examples.py``; a line that is also a README example runs there,
once. Every page is then opened from disk in Debian's Chromium, headless, driven by
selenium through Debian's chromedriver (one browser for all pages), at 1280 px: no page
scrolls sideways, no table is wider than the text column, every formula is typeset, every
picture loads, and the console stays silent.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest
from examples import (ROOT, heavy_lines_without_figures, make_scratch, python_examples, run_python_example,
                      run_shell_example, shell_examples, smaller)

DOCS = ROOT / "docs"
PAGES = {path.relative_to(DOCS).as_posix(): path.read_text() for path in sorted(DOCS.rglob("*.md"))}
README_LINES = set(shell_examples((ROOT / "README.md").read_text()))
# Not run here, and why: the set-up made this environment; the site build and the compiled
# store reader are run by the tests below (test_site_builds_strict, test_c_reader_...); the leaf
# study of the 1 x 2 x 4 box, the same command, by cli/test_study.py (test_study_leaves_json_and_tables),
# which checks its output; the bisection study of the 1 x 2 x 4 box as JSON into a folder by
# cli/test_study.py (test_study_cli_json_shape: the same command with --compare-paper), which checks its output.
NOT_RUN = ("scripts/setup.sh", "mkdocs ", "out/lookup out/", "cospherical study leaves --box 1 2 4 --format json --out ",
           "cospherical study bisection --box 1 2 4 --format json --out ")
MKDOCS = Path(sys.executable).parent / "mkdocs"


@pytest.fixture(scope="session")
def site(tmp_path_factory, worker_id):
    """The built site, once per session: xdist's workers share one build (a lock in their common folder)."""
    import fcntl

    shared = tmp_path_factory.getbasetemp() if worker_id == "master" else tmp_path_factory.getbasetemp().parent
    folder, built = shared / "site", shared / "site.built"
    with open(shared / "site.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not built.exists():
            env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
            result = subprocess.run([str(MKDOCS), "build", "--strict", "--site-dir", str(folder)], cwd=ROOT, env=env,
                                    capture_output=True, text=True, timeout=300)
            assert result.returncode == 0, result.stderr[-3000:]
            built.touch()
    return folder


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    return make_scratch(tmp_path_factory.mktemp("docs") / "repo")


def _text(html: str) -> str:
    return re.sub(r"<[^>]+>", "", html)


def test_site_builds_strict_with_every_page_in_the_navigation(site):
    for page in PAGES:
        assert (site / page.replace(".md", ".html")).is_file(), page


def test_getting_started_lists_every_debian_package_the_set_up_installs(site):
    # the package section of setup.sh run with every "already there?" test failing: a bare machine's list
    script = (ROOT / "scripts" / "setup.sh").read_text()
    section = script[script.index("packages=()"):script.index("if [ ${#packages[@]}")]
    stubs = "command() { return 1; }; ldconfig() { :; }; python3() { return 1; }; function [ { return 1; }; "
    installed = subprocess.run(["bash", "-c", stubs + section + 'echo "${packages[@]}"'], capture_output=True,
                               text=True, check=True, timeout=30).stdout.split()
    assert {"qhull-bin", "chromium", "chromium-driver", "python3-venv"} <= set(installed)
    page = _text((site / "getting-started.html").read_text())
    assert [name for name in installed if name not in page] == []


def test_cli_reference_lists_every_command_and_option_of_the_parser(site):
    import argparse

    from cospherical.cli import build_parser

    page = _text((site / "reference" / "cli.html").read_text())

    def walk(parser):
        yield parser
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for child in action.choices.values():
                    yield from walk(child)

    parsers = list(walk(build_parser()))
    assert len(parsers) > 10
    for parser in parsers:
        assert parser.prog in page, parser.prog
        for action in parser._actions:
            if action.help != argparse.SUPPRESS:
                for flag in action.option_strings:
                    assert flag in page, (parser.prog, flag)


def test_results_pages_show_what_results_holds(site):
    gallery = (site / "results" / "gallery.html").read_text()
    pictures = sorted(path.name for path in (ROOT / "results" / "elements").glob("*.png"))
    assert sorted(set(re.findall(r'figures/elements/([\w-]+\.png)', gallery))) == pictures
    for name in pictures:
        assert (site / "figures" / "elements" / name).read_bytes() == (ROOT / "results" / "elements" / name).read_bytes()
    paper = _text((site / "results" / "paper.html").read_text())
    summary = json.loads((ROOT / "results" / "bisection-1x2x4.json").read_text())
    assert f"{summary['criteria']['optimal']['total']:,}" in paper
    assert f"{summary['fvm_adequate']:,} / {summary['fvm_adequate_open']:,}" in paper
    formats = (site / "reference" / "formats.html").read_text()
    for schema in (ROOT / "src" / "cospherical" / "data" / "schemas").glob("*.json"):
        assert f"schemas/{schema.name}" in formats
        assert json.loads((site / "schemas" / schema.name).read_text()) == json.loads(schema.read_text())
        for field in json.loads(schema.read_text())["properties"]:
            assert f"<code>{field}</code>" in formats, (schema.name, field)


def test_every_example_file_a_page_names_ships():
    named = {name for text in PAGES.values() for name in re.findall(r"examples/[\w./-]+\w", text)}
    assert named, "the pages name the shipped examples"
    for name in named:
        assert (ROOT / name).is_file() or (ROOT / name).is_dir(), name


def test_heavy_examples_say_their_time_and_size():
    assert [(page, line) for page, text in PAGES.items() for line in heavy_lines_without_figures(text)] == []


def test_every_benchmark_example_runs_at_a_small_size():
    # a benchmark's default size is the figure it records (minutes of CPU, GBs): its example line must
    # have a SMALLER rule, or the test below runs it at that size
    from examples import SMALLER

    lines = {line for text in [*PAGES.values(), (ROOT / "README.md").read_text()] for line in shell_examples(text)}
    benchmarks = [line for line in lines if line.startswith("python benchmarks/")]
    assert benchmarks, "the pages show the benchmarks"
    assert [line for line in benchmarks if not any(pattern.search(line) for pattern, _ in SMALLER)] == []


def _docs_lines() -> list[str]:
    """The lines to run: each command once as it runs (two lines that differ only in a size the ``SMALLER``
    rules shrink, such as the intersection study's tables at R = 8 and R = 16, are one run)."""
    lines = dict.fromkeys(line for text in PAGES.values() for line in shell_examples(text))
    readme = {smaller(line) for line in README_LINES}
    run = {}
    for line in lines:
        if smaller(line) not in readme and not any(skip in line for skip in NOT_RUN):
            run.setdefault(smaller(line), line)
    return list(run.values())


@pytest.mark.parametrize("line", _docs_lines())
def test_docs_shell_example_runs(scratch, line):
    run_shell_example(line, scratch, in_process=True)


SNIPPETS = [(page, snippet) for page, text in PAGES.items() for snippet in python_examples(text)]


@pytest.mark.parametrize("page, snippet", SNIPPETS, ids=[f"{page}-{i}" for i, (page, _) in enumerate(SNIPPETS)])
def test_docs_python_example_runs(scratch, page, snippet):
    assert run_python_example(snippet, scratch, page).strip(), "an example shows its result"


def test_an_example_that_leaves_a_file_in_the_checkout_fails(tmp_path):
    checkout = tmp_path / "clone"
    subprocess.run(["git", "init", "-q", str(checkout)], check=True)
    (checkout / ".gitignore").write_text("out/\n")
    subprocess.run(["git", "add", ".gitignore"], cwd=checkout, check=True)
    subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "ignore out/"],
                   cwd=checkout, check=True)
    run_shell_example("mkdir -p out && echo kept > out/result.txt", checkout)  # out/ is where examples write
    run_shell_example("echo 'out/' > .gitignore", checkout)  # a committed file rewritten: what regenerating is
    with pytest.raises(AssertionError, match=r"left files in the checkout: \['stray\.txt'\]"):
        run_shell_example("echo stray > stray.txt", checkout)
    # a line run in-process is held to the same outcome: a refusal (exit 2) fails it, a stray file too
    with pytest.raises(AssertionError, match="80000000000Z"):
        run_shell_example("cospherical tessellate --box 1 1 1 --code 80000000000Z", checkout, in_process=True)
    with pytest.raises(AssertionError, match=r"left files in the checkout: \['t\.vtu'\]"):
        run_shell_example("cospherical tessellate --box 1 1 1 --code 880000000000 --vtu t.vtu", checkout, in_process=True)
    with pytest.raises(AssertionError, match=r"left files in the checkout: \['new/deep\.py'\]"):
        run_python_example("from pathlib import Path\nPath('new').mkdir()\nPath('new/deep.py').write_text('')",
                           checkout, "a page")


def test_cuboid_diagram_numbers_the_nodes_as_the_code_does():
    from cospherical import Configuration

    page = PAGES["concepts/conventions.md"]
    block = re.search(r" z = 0 \(bottom\).*?```", page, re.S).group(0)
    rows = [re.findall(r"\d+", line) for line in block.splitlines() if re.search(r"\d", line) and "z =" not in line]
    assert [len(row) for row in rows] == [9, 9, 9], rows  # y = B, B/2, 0: three layers of three columns each
    nodes = Configuration.from_code("888888888888").nodes()
    seen = {}
    for row, y in zip(rows, (2, 1, 0)):
        for n, node in enumerate(row):
            z, x = divmod(n, 3)
            seen[int(node)] = (x, y, z)  # in half box lengths
    assert sorted(seen) == list(range(27))
    for node, position in seen.items():
        assert tuple(2 * c for c in nodes[node]) == position, node


def test_edge_table_is_the_code_s():
    from cospherical.core.shapes import EDGES, edge_axis

    rows = re.findall(r"^\| (\d+) \| (\d+)-(\d+) \| ([xyz]) \| node (\d+) \|$", PAGES["concepts/conventions.md"], re.M)
    assert [(int(a), int(b)) for _, a, b, _, _ in rows] == list(EDGES)
    assert [int(node) for *_, node in rows] == [8 + k for k in range(12)]
    assert ["xyz"[edge_axis(k)] for k in range(12)] == [axis for *_, axis, _ in rows]


@pytest.fixture(scope="module")
def lookup_programs(tmp_path_factory):
    """examples/lookup.c compiled as C (cc) and as C++ (g++ -x c++), warnings as errors."""
    folder = tmp_path_factory.mktemp("lookup")
    programs = {}
    for language, compiler in (("c", shutil.which("cc") or shutil.which("gcc")), ("c++", shutil.which("g++"))):
        assert compiler, "scripts/setup.sh installs gcc, g++, libsqlite3-dev and zlib1g-dev"
        programs[language] = folder / f"lookup-{language}"
        subprocess.run([compiler, "-Wall", "-Wextra", "-Werror", "-x", language, str(ROOT / "examples" / "lookup.c"),
                        "-lsqlite3", "-lz", "-o", str(programs[language])], check=True, capture_output=True,
                       timeout=120)
    return programs


def _store(folder: Path):
    """A small store written by the library: its path, codes, entry texts and dictionary."""
    from cospherical.formats.patterns import load
    from cospherical.formats.sqlite_store import dictionary_of, pack, write_store

    table = load(ROOT / "patterns" / "bisection-tetrahedron-1x1x1.yaml")
    codes = sorted(table.configurations)[:20]
    texts = {code: json.dumps(table.configurations[code]) for code in codes}
    dictionary = dictionary_of(list(texts.values()))
    store = folder / "t.sqlite"
    write_store(store, table.header, dictionary, [(code, pack(texts[code], dictionary)) for code in codes])
    return store, codes, texts, dictionary


@pytest.mark.parametrize("language", ["c", "c++"])
def test_c_reader_of_the_store_gives_the_entries_python_gives(tmp_path, lookup_programs, language):
    from cospherical.formats.patterns import load

    store, codes, texts, _ = _store(tmp_path)
    for code in codes[::5]:
        result = subprocess.run([str(lookup_programs[language]), str(store), code], capture_output=True, text=True,
                                timeout=30)
        assert result.returncode == 0, result.stderr
        assert json.loads(result.stdout) == json.loads(texts[code])
        assert json.loads(result.stdout) == load(store).configurations[code]
    missing = subprocess.run([str(lookup_programs[language]), str(store), "fffffffff"], capture_output=True,
                             text=True, timeout=30)
    assert missing.returncode == 2 and len(missing.stderr.strip().splitlines()) == 1


def _sql(*statements):
    def edit(store: Path, codes, dictionary) -> None:
        connection = sqlite3.connect(store)
        for statement in statements:
            connection.execute(statement)
        connection.commit()
        connection.close()
    return edit


def _entry(text: bytes | str):
    """The first entry replaced by ``text`` packed as the library packs it (bytes: not UTF-8)."""
    import zlib

    def edit(store: Path, codes, dictionary) -> None:
        packer = zlib.compressobj(6, zdict=dictionary)
        data = text if isinstance(text, bytes) else text.encode()
        connection = sqlite3.connect(store)
        connection.execute("UPDATE entries SET entry = ? WHERE code = ?", (packer.compress(data) + packer.flush(),
                                                                            codes[0]))
        connection.commit()
        connection.close()
    return edit


def _truncated(store: Path, codes, dictionary) -> None:
    store.write_bytes(store.read_bytes()[:-4096])


def _wal(store: Path, codes, dictionary) -> None:
    connection = sqlite3.connect(store)
    connection.execute("PRAGMA journal_mode = WAL")
    connection.close()


MIB = 1 << 20
# Stores the C reader must refuse as `cospherical check` does: at once, one line, nothing printed.
HOSTILE_STORES = {
    "entries a view that never ends": (_sql(
        "DROP TABLE entries", "CREATE VIEW entries AS WITH RECURSIVE n(k) AS (SELECT 1 UNION ALL SELECT k + 1 FROM n) "
        "SELECT printf('%012x', k) AS code, zeroblob(10) AS entry FROM n"), "schema"),
    "dictionary a view of a 900 MB zeroblob": (_sql(
        "DROP TABLE dictionary", "CREATE VIEW dictionary AS SELECT zeroblob(900000000) AS data"), "schema"),
    "a trigger": (_sql("CREATE TRIGGER t AFTER UPDATE ON meta BEGIN SELECT 1; END"), "schema"),
    "another table": (_sql("CREATE TABLE notes (text TEXT)"), "schema"),
    "an index": (_sql("CREATE INDEX by_data ON dictionary (data)"), "schema"),
    "entries declared otherwise": (_sql(
        "CREATE TABLE e2 (code TEXT PRIMARY KEY, entry BLOB)", "INSERT INTO e2 SELECT * FROM entries",
        "DROP TABLE entries", "ALTER TABLE e2 RENAME TO entries"), "schema"),
    "an entry of 2 MiB stored": (_sql(f"UPDATE entries SET entry = zeroblob({2 * MIB}) "
                                     "WHERE code = (SELECT min(code) FROM entries)"), "stored in over"),
    "a code of 3 MiB": (_sql(f"INSERT INTO entries VALUES (hex(zeroblob({3 * MIB // 2})), x'00')"), "stored in over"),
    "an entry as text": (_sql("UPDATE entries SET entry = 'abc' WHERE code = (SELECT min(code) FROM entries)"), "not a blob"),
    "an entry unpacking to 2 MiB": (_entry(b" " * (2 * MIB)), "unpacks to over"),
    "an entry with ESC and a newline": (_entry('{"a": "\x1b[2J\nfake"}'), "one line of UTF-8"),
    "an entry not UTF-8": (_entry(b'{"a": "\xff\xfe"}'), "one line of UTF-8"),
    "an entry with a C1 control (CSI)": (_entry('{"a": "\u009b2J"}'), "one line of UTF-8"),
    "a dictionary of 100 kB": (_sql("UPDATE dictionary SET data = zeroblob(100000)"), "dictionary"),
    "two dictionaries": (_sql("INSERT INTO dictionary VALUES (x'00')"), "dictionary"),
    "a count that is not the entries'": (_sql("UPDATE meta SET value = '21' WHERE key = 'count'"), "count says"),
    "layout 2": (_sql("UPDATE meta SET value = '2' WHERE key = 'layout'"), "layout 1"),
    "no header": (_sql("DELETE FROM meta WHERE key = 'header'"), "with a header"),
    "truncated": (_truncated, "not a complete"),
    "in WAL mode": (_wal, "not a complete"),
    "a FIFO in its place": (lambda store, codes, dictionary: store.unlink() or os.mkfifo(store), "not a complete"),
}


@pytest.mark.parametrize("case", list(HOSTILE_STORES))
def test_c_reader_refuses_what_check_refuses_at_once_in_one_line(tmp_path, lookup_programs, case, capsys):
    import resource
    import time

    from cospherical.cli import main

    store, codes, _, dictionary = _store(tmp_path)
    edit, needle = HOSTILE_STORES[case]
    edit(store, codes, dictionary)
    assert main(["check", str(store)]) == 2, case  # the rule the C reader follows
    capsys.readouterr()

    def limited():  # a reader that read the 900 MB blob would fail here, not fill the machine's memory
        resource.setrlimit(resource.RLIMIT_AS, (256 * MIB, 256 * MIB))

    for language, program in lookup_programs.items():
        start = time.monotonic()
        result = subprocess.run([str(program), str(store), codes[0]], capture_output=True, text=True, timeout=20,
                                preexec_fn=limited, errors="replace")
        assert time.monotonic() - start < 5, (language, case)
        lines = result.stderr.strip().splitlines()
        assert result.returncode == 2 and len(lines) == 1 and result.stdout == "", (language, case, result)
        assert lines[0].startswith("lookup: ") and needle in lines[0], (language, case, lines)



@pytest.fixture(scope="module")
def browser():
    """One headless Chromium (Debian's package) for every page, driven through Debian's chromedriver."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    chromium, driver = shutil.which("chromium"), shutil.which("chromedriver")
    assert chromium and driver, "scripts/setup.sh installs Debian's chromium and chromium-driver"
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-extensions",
                     "--hide-scrollbars", "--window-size=1280,900"):
        options.add_argument(argument)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})  # the console, and failed loads
    session = webdriver.Chrome(service=Service(driver), options=options)
    session.set_page_load_timeout(60)
    yield session
    session.quit()


# What a reader would see wrong on a page, found in the page itself: the text column is the
# <article>; a table in Material's scroll wrapper still counts as too wide (it is cut, and
# scrolls), a formula is typeset when KaTeX has put its .katex inside arithmatex's wrapper.
PAGE_FAULTS = r"""
const faults = [], article = document.querySelector("article");
const column = article.getBoundingClientRect().width;
if (document.documentElement.scrollWidth > window.innerWidth)
  faults.push(`the page is ${document.documentElement.scrollWidth} px wide, the window ${window.innerWidth}`);
for (const table of article.querySelectorAll("table")) {
  const width = table.getBoundingClientRect().width;
  if (width > column + 1)
    faults.push(`a table ${Math.round(width)} px wide in a ${Math.round(column)} px column: ` +
                table.rows[0].innerText.replace(/\s+/g, " ").slice(0, 60));
}
for (const name of article.querySelectorAll("td:first-child code"))
  if (!/\s/.test(name.textContent) && name.getClientRects().length > 1)
    faults.push(`a name broken across lines: ${name.textContent.slice(0, 60)}`);
for (const math of article.querySelectorAll(".arithmatex"))
  if (!math.querySelector(".katex") || math.querySelector(".katex-error"))
    faults.push(`a formula not typeset: ${math.textContent.slice(0, 60)}`);
for (const display of article.querySelectorAll(".katex-display"))
  if (display.scrollWidth > display.clientWidth + 1)
    faults.push(`a formula wider than the column: ${display.textContent.slice(0, 60)}`);
const walker = document.createTreeWalker(article, NodeFilter.SHOW_TEXT);
for (let node = walker.nextNode(); node; node = walker.nextNode())
  if (!node.parentElement.closest("pre, code, .katex") && /\\[(\[]|\$\$/.test(node.textContent))
    faults.push(`TeX left as text: ${node.textContent.trim().slice(0, 60)}`);
for (const img of article.querySelectorAll("img"))
  if (!img.complete || img.naturalWidth === 0) faults.push(`a picture that does not load: ${img.src}`);
return faults;
"""


def _faults(browser, url: str) -> list[str]:
    """Open ``url`` and say everything wrong with it: layout, formulas, pictures, console messages."""
    from selenium.webdriver.support.ui import WebDriverWait

    browser.get(url)
    # KaTeX typesets when Material's document$ fires, just after the load event
    WebDriverWait(browser, 10).until(lambda b: b.execute_script(
        "return typeof renderMathInElement === 'undefined' || "
        "[...document.querySelectorAll('.arithmatex')].every(m => m.querySelector('.katex, .katex-error'))"))
    faults = browser.execute_script(PAGE_FAULTS)
    return faults + [f"console {entry['level']}: {entry['message']}" for entry in browser.get_log("browser")
                     if entry["level"] in ("WARNING", "SEVERE")]


def test_the_browser_checks_see_each_fault(browser, tmp_path):
    page = tmp_path / "bad.html"
    page.write_text("""<html><head><style>body { margin: 0 } table { width: 2000px }</style></head><body>
        <article><p>\\(x^2\\) left as text</p><table><tr><td>wide</td></tr></table>
        <table style="width: 60px"><tr><td><code style="word-break: break-all">control_volume_exact</code></td></tr></table>
        <span class="arithmatex">\\(y\\)</span><img src="missing.png"></article>
        <script>console.error("boom"); notDefined();</script></body></html>""")
    faults = "\n".join(_faults(browser, page.as_uri()))
    for fault in ("the page is", "a table 2000 px wide", "a name broken across lines: control_volume_exact",
                  "a formula not typeset", "TeX left as text",
                  "a picture that does not load", "boom", "notDefined"):
        assert fault in faults, (fault, faults)


def test_every_page_renders_at_1280_px_in_chromium(site, browser):
    pages = [page.replace(".md", ".html") for page in PAGES]
    faults = {page: found for page in pages if (found := _faults(browser, (site / page).as_uri()))}
    assert faults == {}
    typeset = {page: _text((site / page).read_text()).count("\\(") for page in pages}
    assert sum(typeset.values()) > 10, "the pages have formulas for the check above to see"
    browser.get((site / "results" / "gallery.html").as_uri())
    assert len(browser.get_screenshot_as_png()) > 50_000  # the pictures drawn: a blank page compresses to a few kB


def test_a_benchmark_run_is_recorded_with_its_machine_and_rendered_from_its_file(tmp_path, capsys):
    import html
    import importlib.util
    import os

    import markdown

    from cospherical.errors import FormatError

    def load(name, path):
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module

    record = load("record", ROOT / "benchmarks" / "record.py")
    with pytest.raises(RuntimeError), record.recorded("bench_fails.py", tmp_path):
        raise RuntimeError("a failed run")
    assert not (tmp_path / "bench_fails.json").exists()  # a failed run leaves the previous file as it was
    with record.recorded("bench_example.py", tmp_path) as run:
        print("figure line")
        run.add("one call | median", "0.85 ms")
        run.table(["level", "error"], [[3, "1.29e-02"]])
    data = json.loads((tmp_path / "bench_example.json").read_text())
    assert data["output"] == ["figure line"] and data["rows"] == [["one call | median", "0.85 ms"]]
    assert data["machine"]["cores"] == os.cpu_count() and len(data["load_average"]["before"]) == 3
    assert data["command"].startswith("python benchmarks/bench_example.py") and data["cpu_seconds"] > 0
    hooks = load("docs_hooks", ROOT / "scripts" / "docs_hooks.py")
    page = "\n".join(hooks._recorded_run(tmp_path / "bench_example.json"))
    shown = html.unescape(page)  # what the browser shows: the record's texts as numeric references
    assert data["command"] in shown and f"{data['machine']['cores']} cores" in page
    assert "| one call &#124; median | 0.85 ms |" in page and "    figure line" in page
    assert "| level | error |" in page and "| 3 | 1.29e&#45;02 |" in page

    # a hostile record (a file in the repository, put into the site): shown, never read as markup
    data["command"] = "python x` <script>alert(1)</script> `"
    data["machine"]["cpu"] = "<img src=x onerror=alert(2)>"
    data["rows"].append(["a | b <script>alert(3)</script>", '--8<-- "pyproject.toml"'])
    data["output"] += ["```", "<script>alert(4)</script>", '    --8<-- "pyproject.toml"']
    hostile = tmp_path / "bench_hostile.json"
    hostile.write_text(json.dumps(data))
    site = markdown.markdown("\n".join(hooks._recorded_run(hostile)), extensions=[
        "admonition", "tables", "md_in_html", "pymdownx.superfences", "pymdownx.details", "pymdownx.snippets"],
        extension_configs={"pymdownx.snippets": {"base_path": [str(ROOT)], "check_paths": True}})
    assert "<script>" not in site and "<img" not in site and "[project]" not in site, site
    assert "alert(4)" in site and "<td>a &#124; b &#60;script" in site  # shown, the cell not split at its |
    hostile.write_text('{"command": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(FormatError, match="nested too deeply"):
        hooks._recorded_run(hostile)
    hostile.write_text('{"command": "x"}')
    with pytest.raises(ValueError, match="not a benchmark record as benchmarks/record.py writes it: KeyError"):
        hooks._recorded_run(hostile)


# --- the generated parts from hostile records, summaries and reports ----------------------------------------------

def _hooks():
    import importlib.util

    spec = importlib.util.spec_from_file_location("docs_hooks_under_attack", ROOT / "scripts" / "docs_hooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _as_the_site_renders(text: str) -> str:
    """Markdown to HTML with the site's own extensions and their settings (mkdocs.yml)."""
    import markdown
    import yaml

    class Loader(yaml.SafeLoader):  # mkdocs.yml's !!python/name tags are not used by the markdown part
        pass

    config = yaml.load((ROOT / "mkdocs.yml").read_text(), Loader=Loader)
    names, settings = [], {}
    for entry in config["markdown_extensions"]:
        name, options = next(iter(entry.items())) if isinstance(entry, dict) else (entry, {})
        names.append(name)
        settings[name] = {**(options or {}), **({"base_path": [str(ROOT)]} if name == "pymdownx.snippets" else {})}
    return markdown.markdown(text, extensions=names, extension_configs=settings)


# What a hostile value tries: a tag, a tag after each kind of line break, the end of a code span or block,
# an attribute list, a table cell's end, a snippet inclusion, an entity the browser would decode.
BREAKS = ["\r", "\n", "\r\n", "\x0b", "\x0c", "\x1c", "\x1d", "\x1e", "\x85", "\u2028", "\u2029"]
HOSTILE = ["<script>alert(1)</script>", *(f"x{b}<script>alert(2)</script>" for b in BREAKS),
           "`` ` <img src=x onerror=alert(3)>", "x\r```\r<img src=x onerror=alert(5)>",
           "{: onclick=alert(4) }", "a | b", '--8<-- "pyproject.toml"', "&lt;script&gt;alert(6)&lt;/script&gt;",
           "\x1b[31mred"]
ALLOWED_TAGS = {"p", "table", "thead", "tbody", "tr", "th", "td", "code", "pre", "span", "div", "details", "summary",
                "h2", "h3", "a", "img", "figure", "figcaption", "b", "br", "em", "strong"}


def _markup(html: str) -> tuple[list[tuple[str, list]], str]:
    """The tags of a page and the text a browser shows of it."""
    from html.parser import HTMLParser

    class Parser(HTMLParser):
        def __init__(self):
            super().__init__(convert_charrefs=True)
            self.tags, self.text = [], []

        def handle_starttag(self, tag, attrs):
            self.tags.append((tag, attrs))

        def handle_data(self, data):
            self.text.append(data)

    parser = Parser()
    parser.feed(html)
    return parser.tags, "".join(parser.text)


def _assert_shown_never_markup(html: str, values) -> None:
    tags, shown = _markup(html)
    assert {tag for tag, _ in tags} <= ALLOWED_TAGS, sorted({tag for tag, _ in tags} - ALLOWED_TAGS)
    for tag, attrs in tags:
        assert not [name for name, _ in attrs if name.startswith("on")], (tag, attrs)
        for name, value in attrs:
            assert name not in ("src", "href") or not value.startswith(("x", "javascript")), (tag, attrs)
    assert "[project]" not in shown  # no snippet of pyproject.toml pulled in
    def seen(text: str) -> str:  # a browser shows no control character, and its line breaks as white space
        return " ".join("".join(c for c in text if c.isprintable() or c.isspace()).split())

    for value in values:  # each value is there, shown as it is written
        assert seen(value) in seen(shown), value


@pytest.mark.parametrize("value", HOSTILE, ids=[repr(v)[1:25] for v in HOSTILE])
def test_a_hostile_benchmark_record_is_shown_never_read_as_markup(tmp_path, value):
    hooks = _hooks()
    record = {"command": f"python benchmarks/bench_x.py {value}", "date": value, "commit": value,
              "machine": {"cores": 2, "memory_gib": 7.8, "cpu": value},
              "load_average": {"before": [0.5, value, 1], "after": [1, 1, 1]}, "cpu_seconds": 1.5,
              "wall_seconds": value, "peak_memory_gib": 0.1, "rows": [[value, value]],
              "tables": [{"columns": [value, "b"], "rows": [[value, 1]]}],
              "output": ["before", value, f"{value}{value}", "after"]}
    path = tmp_path / "bench_x.json"
    path.write_text(json.dumps(record))
    _assert_shown_never_markup(_as_the_site_renders("\n".join(hooks._recorded_run(path))), [value])


def _hostile_results(folder: Path, value: str) -> None:
    """results/ with every value a page shows from a summary, a report and an intersection summary hostile."""
    folder.mkdir()
    summary = json.loads((ROOT / "results" / "bisection-1x2x4.json").read_text())
    summary["face_points"] = "octree"  # the paper's tables are shown for these only
    optimal = summary["criteria"]["optimal"]
    first = next(iter(optimal["types"]))
    optimal["types"][first]["paper_class"] = value
    optimal["types_count"] = value
    (folder / f"bisection-{value[:3].strip()}.json").write_text(json.dumps(summary))
    other = dict(summary, study=value, box=[value, "2", "4"], face_points=value, configurations=value,
                 element=value)
    (folder / "other.json").write_text(json.dumps(other))
    order = folder / "intersection" / "x"
    order.mkdir(parents=True)
    source = next((ROOT / "results" / "intersection").glob("*/intersection-r*-*.json"))
    intersection = json.loads(source.read_text())
    intersection["insertion_order"] = value
    intersection["configurations"] = value
    (order / "intersection-r16-x.json").write_text(json.dumps(intersection))
    report = json.loads((ROOT / "results" / "mesh" / "sphere-1x2x4-L5" / "report.json").read_text())
    report["domain"] = [value, "2", "4"]
    report["tree"]["refine"] = [value]
    report["delaunay_mode"] = value
    report["negative_coefficients"]["interior"] = value
    (folder / "mesh" / "m").mkdir(parents=True)
    (folder / "mesh" / "m" / "report.json").write_text(json.dumps(report))


@pytest.mark.parametrize("value", HOSTILE[:2] + HOSTILE[3:4] + HOSTILE[-7:],
                         ids=[repr(v)[1:25] for v in HOSTILE[:2] + HOSTILE[3:4] + HOSTILE[-7:]])
def test_hostile_summaries_and_reports_are_shown_never_read_as_markup(tmp_path, value):
    hooks = _hooks()
    hooks.RESULTS = tmp_path / "results"
    _hostile_results(hooks.RESULTS, value)
    for name in ("studies", "paper", "intersection", "meshes", "dual"):
        html = _as_the_site_renders(hooks.GENERATORS[name]("../"))
        _assert_shown_never_markup(html, [value] if name != "dual" else [])


def _page(uri: str):
    from types import SimpleNamespace

    return SimpleNamespace(file=SimpleNamespace(src_uri=uri))


@pytest.mark.parametrize("case, text", [
    ("not JSON", "{"), ("a list", "[1, 2]"), ("output a string", None), ("a key with an ESC and a newline", None),
    ("not UTF-8", b"\xff\xfe{"), ("deep", "[" * 100_000), ("a huge number", '{"cpu_seconds": 1' + "0" * 5000 + "}"),
    ("rows of numbers", None)])
def test_a_malformed_benchmark_record_stops_the_build_with_one_line(tmp_path, case, text):
    from mkdocs.exceptions import PluginError

    hooks = _hooks()
    hooks.RESULTS = tmp_path
    (tmp_path / "benchmarks").mkdir()
    record = json.loads((ROOT / "results" / "benchmarks" / "bench_patterns.json").read_text())
    if case == "output a string":
        record["output"] = "one line"
    elif case == "a key with an ESC and a newline":
        record = {"\x1b[2J\nfake: line": 1}
    elif case == "rows of numbers":
        record["rows"] = [1, 2]
    path = tmp_path / "benchmarks" / "bench_x.json"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text if text is not None else json.dumps(record))
    with pytest.raises(PluginError) as raised:
        hooks.on_page_markdown("a\n<!-- generated: benchmark:bench_x -->\n", _page("results/x.md"), None, None)
    message = str(raised.value)
    assert len(message.splitlines()) == 1 and message.isprintable() and len(message) < 500, message
    assert message.startswith("results/x.md: <!-- generated: benchmark:bench_x -->: ") and "bench_x.json" in message


@pytest.mark.parametrize("case", ["a box of numbers", "counts as text", "a report not an object", "no criteria"])
def test_a_malformed_summary_or_report_stops_the_build_with_one_line(tmp_path, case):
    from mkdocs.exceptions import PluginError

    hooks = _hooks()
    hooks.RESULTS = tmp_path
    summary = json.loads((ROOT / "results" / "bisection-1x2x4.json").read_text())
    report = json.loads((ROOT / "results" / "mesh" / "sphere-1x2x4-L5" / "report.json").read_text())
    marker = "studies"
    if case == "a box of numbers":
        summary["box"] = 5
    elif case == "no criteria":
        del summary["criteria"]
    elif case == "counts as text":
        report["dual"]["mixed"]["edges"] = "many"
        marker = "dual"
    else:
        report = ["not", "an", "object"]
        marker = "meshes"
    (tmp_path / "s.json").write_text(json.dumps(summary))
    (tmp_path / "mesh" / "m").mkdir(parents=True)
    (tmp_path / "mesh" / "m" / "report.json").write_text(json.dumps(report))
    with pytest.raises(PluginError) as raised:
        hooks.on_page_markdown(f"<!-- generated: {marker} -->", _page("index.md"), None, None)
    message = str(raised.value)
    assert len(message.splitlines()) == 1 and message.startswith(f"index.md: <!-- generated: {marker} -->: "), message
