"""MkDocs hooks: the pages' generated parts, made at build time from the code and results/.

Nothing generated is typed into ``docs/``: a page holds a marker such as
``<!-- generated: cli -->`` and this module replaces it, so the CLI reference is
the parser itself, the tables are ``results/*.json`` as ``cospherical reproduce``
last wrote them, and the gallery is whatever pictures ``results/elements/`` holds.
The JSON Schemas and the pictures are added to the site from where they live.

What a record, a summary or a report says, and the names of the files in
``results/``, are data from files anyone may have edited: each is written for the
place it lands (:func:`_text` in Markdown and HTML, :func:`_code_block` in a code
block, :func:`_url` in a link), never read as markup; a file that is not what its
writer writes stops the build with one line naming it.
"""

from __future__ import annotations

import argparse
import json
import os
import re
from pathlib import Path
from urllib.parse import quote

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

from cospherical.choices import CRITERIA

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "results"
SCHEMAS = ROOT / "src" / "cospherical" / "data" / "schemas"
MARKER = re.compile(r"<!-- generated: ([a-z-]+)(?::([a-z._-]+))? -->")


# --- files taken into the site from where they live -------------------------------------------

def _assets() -> dict[str, Path]:
    """Site path -> source file, for every schema and every picture the pages show."""
    assets = {f"schemas/{path.name}": path for path in sorted(SCHEMAS.glob("*.json"))}
    for path in sorted((RESULTS / "elements").glob("*.png")):
        assets[f"figures/elements/{path.name}"] = path
    for path in sorted((RESULTS / "sweep").glob("*.png")):
        assets[f"figures/sweep/{path.name}"] = path
    for path in sorted(RESULTS.glob("mesh/*/mesh.png")):
        assets[f"figures/mesh/{path.parent.name}.png"] = path
    for path in sorted(RESULTS.glob("devices/*/mesh.png")):
        assets[f"figures/devices/{path.parent.name}.png"] = path
    return assets


def on_files(files, config):
    for uri, path in _assets().items():
        files.append(File.generated(config, uri, abs_src_path=str(path)))
    return files


def on_page_content(html, page, config, files):
    # docstrings rendered by mkdocstrings keep their reST roles (":func:`name`" becomes
    # ":func:<code>name</code>", or left as typed where Markdown made no code span of it): the
    # site shows the name alone, as code
    html = re.sub(r":(?:func|class|mod|meth|data|attr|exc|obj):<code>~?", "<code>", html)
    return re.sub(r":(?:func|class|mod|meth|data|attr|exc|obj):`~?([^`<>]+)`", r"<code>\1</code>", html)


def on_page_markdown(markdown, page, config, files):
    depth = page.file.src_uri.count("/")
    up = "../" * depth  # from the page's folder to the site's root, as MkDocs resolves links

    def generated(match):
        name, argument = match.groups()
        try:
            return GENERATORS[name](up, argument) if argument else GENERATORS[name](up)
        except _MALFORMED as error:
            # a damaged record or summary: one line naming the page, the marker and the file, no traceback
            raise PluginError(f"{page.file.src_uri}: {match.group(0)}: {_one_line(error)}") from None

    return MARKER.sub(generated, markdown)


def _one_line(error: BaseException, most: int = 300) -> str:
    """An error as one printable line: every control character and line break escaped, cut to ``most``."""
    text = f"{type(error).__name__}: {error}" if isinstance(error, (KeyError, IndexError, TypeError,
                                                                    AttributeError)) else str(error)
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
    return text if len(text) <= most else text[:most] + "..."


# --- the CLI reference, from the parser ---------------------------------------------------------

def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _options_table(parser: argparse.ArgumentParser) -> list[str]:
    formatter = parser._get_formatter()
    rows = ["| option | value | default | what it does |", "|---|---|---|---|"]
    for action in parser._actions:
        if action.help == argparse.SUPPRESS or isinstance(action, (argparse._SubParsersAction,
                                                                     argparse._HelpAction)):
            continue
        names = ", ".join(f"`{name}`" for name in action.option_strings) or f"`{action.dest}`"
        if action.choices is not None:
            value = " \\| ".join(f"`{choice}`" for choice in action.choices)
        elif action.nargs == 0:
            value = "(flag)"
        else:
            metavar = action.metavar or action.dest.upper()
            value = "`" + " ".join(metavar if isinstance(metavar, tuple) else [metavar]) + "`"
        default = action.default
        shown = "" if default in (None, False, argparse.SUPPRESS) or action.nargs == 0 else f"`{_cell(default)}`"
        if isinstance(default, list):
            shown = "`" + " ".join(default) + "`" if default else ""
        rows.append(f"| {names} | {value} | {shown} | {_cell(formatter._expand_help(action))} |")
    return rows


def _command_section(parser: argparse.ArgumentParser, level: int) -> list[str]:
    lines = [f"{'#' * level} `{parser.prog}`", ""]
    if parser.description:
        lines += [parser.description, ""]
    lines += ["```text", parser.format_usage().strip(), "```", ""]
    table = _options_table(parser)
    if len(table) > 2:  # a command whose only option is --help has no table
        # the class keeps each option name on one line (extra.css): "--face-points", not "--face-" / "points"
        lines += ['<div class="cli-options" markdown>', "", *table, "", "</div>", ""]
    for child in _subparsers(parser).values():
        lines += _command_section(child, level + 1)
    return lines


def cli_reference(up: str) -> str:
    os.environ["COLUMNS"] = "100"  # argparse wraps usage to the terminal: the same page on every machine
    from cospherical.cli import build_parser

    parser = build_parser()
    lines = ["```text", parser.format_usage().strip(), "```", ""]
    for child in _subparsers(parser).values():
        lines += _command_section(child, 2)
    return "\n".join(lines)


# --- the Debian packages of the set-up, from scripts/setup.sh --------------------------------------

def setup_packages() -> list[str]:
    """Every Debian package ``scripts/setup.sh`` installs on a fresh machine, in its order.

    Its package section is run by bash with every "is it there already?" test failing
    (``command -v``, ``[ -e ... ]``, ``ldconfig``, ``python3``), so the list is what a
    machine with none of them gets: whatever way the script finds a package missing.
    """
    import subprocess

    script = (ROOT / "scripts" / "setup.sh").read_text()
    section = script[script.index("packages=()"):script.index("if [ ${#packages[@]}")]
    absent = ("command() { return 1; }; ldconfig() { :; }; python3() { return 1; }; "
              "function [ { return 1; }; ")
    result = subprocess.run(["bash", "-c", absent + section + 'printf "%s\\n" "${packages[@]}"'],
                            capture_output=True, text=True, check=True, timeout=30)
    return result.stdout.split()


def debian_packages(up: str) -> str:
    """The set-up's Debian packages as a table, one row per line of setup.sh, with the reason it gives."""
    script = (ROOT / "scripts" / "setup.sh").read_text()
    rows, described, above = ["| Debian packages | why |", "|---|---|"], [], ""
    for line in script[script.index("packages=()"):script.index("if [ ${#packages[@]}")].splitlines():
        literal = re.search(r"packages\+=\(([^)$]*)\)", line)
        if line.startswith("#"):
            above = line.lstrip("# ").strip()
        elif literal:
            names = literal.group(1).split()
            described += names
            rows.append(f"| {', '.join(f'`{n}`' for n in names)} | {_cell(line.partition('#')[2].strip())} |")
    # what a loop adds (the libraries of the gmsh wheel), under the comment above it
    rest = [name for name in setup_packages() if name not in described]
    if rest:
        rows.append(f"| {', '.join(f'`{n}`' for n in rest)} | {_cell(above)} |")
    return "\n".join(rows)


# --- results tables, from results/*.json ---------------------------------------------------------

def _json(path: Path):
    """A results file read by the readers' one JSON parser (bounded size, nesting and digits)."""
    from cospherical.files.yamlio import parse_json, read_text

    return parse_json(read_text(path), str(path), max_digits=1000)


def _summaries() -> list[tuple[str, dict]]:
    return [(path.stem, _json(path)) for path in sorted(RESULTS.glob("*.json"))]


def _figure(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"  # as the report and the command's summary say it
    return "-" if value is None else f"{value:,}" if isinstance(value, int) else str(value)


def _n(value) -> str:
    """A figure of a summary or report, shown literally in a table cell or a line of text."""
    return "-" if value is None else _text(_figure(value))


def studies_table(up: str) -> str:
    from cospherical.paper import paper_comparison, paper_study_key

    names = {"optimal": "optimal", "internal_faces": "internal faces", "internal_edges_and_faces": "internal edges"}
    rows = ["| study | box | points | configurations (orbits) | FVM closed / open | "
            + " | ".join(f"{names[c]}: elements / types" for c in CRITERIA) + " | paper: elements / classes / FVM |",
            "|---|---|---|---:|---:|" + "---:|" * len(CRITERIA) + "---|"]
    for stem, summary in _summaries():
        key, _ = paper_study_key(summary)
        paper = "-"
        if key:
            optimal = paper_comparison(summary, key)
            paper = " / ".join(_n(x) for x in (optimal["total"]["paper"], optimal["classes"]["paper"],
                                               optimal["fvm_adequate"]["paper"]))
        criteria = [f"{_n(summary['criteria'][c]['total'])} / {_n(summary['criteria'][c]['types_count'])}"
                    for c in CRITERIA]
        element = summary.get("element", "cuboid")
        study = _text(summary["study"]) + ("" if element == "cuboid" else f" ({_text(element)})")
        rows.append(f"| {study} | {' x '.join(map(_text, summary['box']))} | {_text(summary['face_points'])} | "
                    f"{_n(summary['configurations'])} ({_n(summary['orbits'])}) | "
                    f"{_n(summary['fvm_adequate'])} / {_n(summary['fvm_adequate_open'])} | "
                    + " | ".join(criteria) + f" | {paper} |")
    return "\n".join(rows)


def paper_tables(up: str) -> str:
    """Per study the paper compares with, and per criterion it publishes: class by class."""
    from cospherical.paper import paper_comparison, paper_study_key
    from cospherical.paper.published import paper_studies

    out = []
    for stem, summary in _summaries():
        key, notes = paper_study_key(summary)
        if not key or summary["face_points"] != "octree":
            continue
        for criterion in CRITERIA:
            if criterion not in paper_studies()[key]:
                continue
            table = paper_comparison(summary, key, criterion)
            out += [f"### {_text(stem)}: {criterion.replace('_', ' ')} (paper: {_text(key)})", ""]
            out += ["| paper class | paper | ours | |", "|---|---:|---:|---|"]
            for row in table["rows"]:
                mark = "" if row["paper"] == row["ours"] else "differs"
                out.append(f"| {_text(row['class'])} | {_n(row['paper'])} | {_n(row['ours'])} | {mark} |")
            total = table["total"]
            out.append(f"| **total** | {_n(total['paper'])} | {_n(total['ours'])} | "
                       f"{'' if total['paper'] == total['ours'] else 'differs'} |")
            out.append("")
    return "\n".join(out)


def intersection_table(up: str) -> str:
    from cospherical.paper import paper_comparison

    tables = {}
    for path in sorted(RESULTS.glob("intersection/*/intersection-r*-*.json")):
        summary = _json(path)
        tables[summary["insertion_order"]] = (summary, paper_comparison(summary, "intersection_cube"))
    if not tables:
        return "*(no intersection results in results/intersection/)*"
    orders = list(tables)
    first = tables[orders[0]][1]
    rows = ["| paper class | paper | " + " | ".join(f"ours, order <code>{_text(o)}</code>" for o in orders) + " |",
            "|---|---:|" + "---:|" * len(orders)]
    labels = [row["class"] for row in first["rows"]]
    for order in orders[1:]:
        labels += [row["class"] for row in tables[order][1]["rows"] if row["class"] not in labels]
    for label in labels:
        paper = next((r["paper"] for r in first["rows"] if r["class"] == label), None)
        ours = [next((r["ours"] for r in tables[o][1]["rows"] if r["class"] == label), None) for o in orders]
        rows.append(f"| {_text(label)} | {_n(paper)} | " + " | ".join(_n(x) for x in ours) + " |")
    rows.append("| **total elements** | " + _n(first["total"]["paper"]) + " | "
                + " | ".join(_n(tables[o][1]["total"]["ours"]) for o in orders) + " |")
    rows.append("| configurations (orbits) | - | "
                + " | ".join(f"{_n(tables[o][0]['configurations'])} ({_n(tables[o][0]['orbits'])})" for o in orders)
                + " |")
    rows.append("| element types (of the paper's classes) | 38 classes | " + " | ".join(
        f"{_n(tables[o][0]['criteria']['optimal']['types_count'])} "
        f"({_n(tables[o][0]['criteria']['optimal'].get('paper_classes_count'))})"
        for o in orders) + " |")
    for criterion in CRITERIA[1:]:
        rows.append(f"| {criterion.replace('_', ' ')}: elements, types | - | " + " | ".join(
            f"{_n(tables[o][0]['criteria'][criterion]['total'])}, {_n(tables[o][0]['criteria'][criterion]['types_count'])}"
            for o in orders) + " |")
    rows.append("| FVM-adequate, closed / open | - | "
                + " | ".join(f"{_n(tables[o][0]['fvm_adequate'])} / {_n(tables[o][0]['fvm_adequate_open'])}"
                             for o in orders) + " |")
    return "\n".join(rows)


MESH_ROWS = [("delaunay_mode", "mode (--delaunay; - : made before the choice, each leaf from its table)"),
             ("leaves", "leaves"), ("vertices", "vertices"), ("elements", "elements"), ("types", "element types"),
             ("volume_ok", "volume_ok"), ("nonconforming_faces", "nonconforming faces"),
             ("circumcenters_outside_leaf", "circumcenters outside their leaf"),
             ("leaves_not_fvm_adequate", "leaves not FVM-adequate"),
             ("delaunay_violations", "Delaunay violations (elements)"),
             ("delaunay_violating_pairs", "(element, vertex) pairs"), ("delaunay_ties", "co-spherical ties"),
             ("regions_retessellated", "regions re-tessellated (global mode)"),
             ("cells_spanning_leaves", "cells spanning leaves (global mode)"),
             ("boundary_circumcenters_outside", "circumcenters outside the domain"),
             (lambda r: (r.get("leaf_mesh") or {}).get("elements_replaced"), "leaf elements replaced (global mode)"),
             ("largest_region_vertices", "largest region (vertices)"),
             (lambda r: (lambda n: n and f"{_figure(n['interior'])} / {_figure(n['boundary'])}")(
                 r.get("negative_coefficients")),
              "negative box-method coefficients, interior / boundary (--dual)"),
             ("configurations", "distinct configurations"), ("tessellated_on_the_fly", "tessellated on the fly"),
             ("paper_final_share", "share of the paper's seven final elements")]


def _reports() -> list[tuple[str, dict]]:
    return [(path.parent.name, _json(path)) for path in sorted(RESULTS.glob("mesh/*/report.json"))]


def mesh_table(up: str) -> str:
    reports = _reports()
    rows = ["| | " + " | ".join(f"<code>{_text(name)}</code>" for name, _ in reports) + " |",
            "|---|" + "---:|" * len(reports)]
    rows.append("| tree | " + " | ".join(
        f"{' x '.join(map(_text, r['domain']))}, levels {_n(r['tree'].get('levels', r['tree'].get('depth')))}, "
        + ", ".join(f"<code>{_text(s)}</code>" for s in r["tree"].get("refine", [])) for _, r in reports) + " |")
    for key, label in MESH_ROWS:
        value = key if callable(key) else (lambda r, key=key: r.get(key))
        rows.append(f"| {label} | " + " | ".join(_n(value(r)) for _, r in reports) + " |")
    pictures = [f"![{_text(name)}]({up}figures/mesh/{_url(name)}.png)" for name, _ in reports]
    return "\n".join(rows) + "\n\n" + "\n\n".join(pictures)


def device_report(up: str, name: str) -> str:
    """One example device's mesh (``results/devices/NAME/``): its picture coloured by region and its report's
    figures per region, contact and interface."""
    report = _json(RESULTS / "devices" / name / "report.json")
    device = report["device"]
    dual = report.get("dual") or {}
    lines = [f"![{_text(name)}]({up}figures/devices/{_url(name)}.png)", "",
             f"{_n(report['leaves'])} leaves (depth {_n(device['depth'])}, the boxes resolved at level "
             f"{_n(device['resolving_level'])}), {_n(report['vertices'])} vertices, {_n(report['elements'])} "
             f"elements, {_n(dual.get('edges'))} dual edges; volume exact: {_text(report['volume_ok'])}, "
             f"non-conforming faces: {_n(report['nonconforming_faces'])}, Delaunay mode "
             f"{_text(report['delaunay_mode'])}.", "",
             "| region | material | elements | nodes | volume | control volumes sum | negative interior coefficients |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for region in device["regions"]:
        negative = region.get("negative_coefficients") or {}
        lines.append(f"| {_text(region['name'])} | {_text(region['material'])} | {_n(region['elements'])} | "
                     f"{_n(region['nodes'])} | {_text(region['volume'])} | {_text(region.get('control_volume_sum', '-'))} | "
                     f"{_n(negative.get('interior'))} |")
    if device["contacts"]:
        lines += ["", "| contact | region | faces | nodes | area | area parts sum |", "|---|---|---:|---:|---:|---:|"]
        for contact in device["contacts"]:
            lines.append(f"| {_text(contact['name'])} | {_text(contact['region'])} | {_n(contact['faces'])} | "
                         f"{_n(contact['nodes'])} | {_text(contact['area'])} | "
                         f"{_text(contact.get('area_parts_sum', '-'))} |")
    if device["interfaces"]:
        lines += ["", "| interface | faces | nodes |", "|---|---:|---:|"]
        for interface in device["interfaces"]:
            lines.append(f"| {_text(interface['name'])} | {_n(interface['faces'])} | {_n(interface['nodes'])} |")
    return "\n".join(lines)


def dual_table(up: str) -> str:
    """The mixed mesh beside the tetrahedral Delaunay mesh of its vertices, per report made with --dual."""
    reports = [(name, r) for name, r in _reports() if r.get("dual", {}).get("tetrahedral")]
    if not reports:
        return "*(no report in results/mesh/ was made with --dual --tetrahedral-counts)*"
    rows = ["| | " + " | ".join(f"<code>{_text(name)}</code>" for name, _ in reports) + " |",
            "|---|" + "---:|" * len(reports)]
    for key in ("elements", "edges", "faces", "nonzeros"):
        cells = []
        for _, r in reports:
            mixed, tetrahedral = r["dual"]["mixed"][key], r["dual"]["tetrahedral"][key]
            if not all(isinstance(x, int) and not isinstance(x, bool) and x > 0 for x in (mixed, tetrahedral)):
                raise ValueError(f"report of {_figure(mixed)[:40]!r} / {_figure(tetrahedral)[:40]!r} {key}: "
                                 "not counts")
            cells.append(f"{mixed:,} / {tetrahedral:,} ({mixed / tetrahedral:.2f})")
        rows.append(f"| {key}: mixed / tetrahedral | " + " | ".join(cells) + " |")
    rows.append("| negative coefficients, interior / boundary | " + " | ".join(
        f"{_n(r['negative_coefficients']['interior'])} / {_n(r['negative_coefficients']['boundary'])}"
        for _, r in reports) + " |")
    rows.append("| mode (`--delaunay`) | " + " | ".join(_n(r.get("delaunay_mode")) for _, r in reports) + " |")
    return "\n".join(rows)


def gallery(up: str) -> str:
    from cospherical import shipped_catalogue

    catalogue = shipped_catalogue()

    def order(path):
        entry = catalogue.get(path.stem)
        return (entry.vertices, entry.faces, path.stem) if entry else (99, 99, path.stem)

    pictures = sorted((RESULTS / "elements").glob("*.png"), key=order)
    out = [f"{len(pictures)} pictures, one per element type of the shipped catalogue "
           f"({len(catalogue)} types), by number of vertices, then faces.", ""]
    for path in pictures:
        entry = catalogue.get(path.stem)
        name = _text(entry.name if entry else "(not in the catalogue)")
        faces = ", ".join(f"{_n(n)} {_text(kind)}" for kind, n in sorted(entry.face_kinds.items() if entry else ()))
        out += ['<figure class="element" markdown>', "",
                f'![{name}]({up}figures/elements/{_url(path.name)}){{ width="160" }}', "",
                f"<figcaption><b>{name}</b><br><code>{_text(path.stem)}</code> V {_n(entry and entry.vertices)}, "
                f"E {_n(entry and entry.edges)}, F {_n(entry and entry.faces)}: {faces}</figcaption>", "</figure>", ""]
    return '<div class="gallery" markdown>\n\n' + "\n".join(out) + "\n</div>"


def sweep_figures(up: str) -> str:
    return "\n\n".join(f"![{_text(path.stem)}]({up}figures/sweep/{_url(path.name)})"
                       for path in sorted((RESULTS / "sweep").glob("*.png")))


def schemas_list(up: str) -> str:
    return "\n".join(f"- [`{path.name}`]({up}schemas/{path.name}) (`src/cospherical/data/schemas/{path.name}`)"
                     for path in sorted(SCHEMAS.glob("*.json")))


# --- a schema's fields, from the schema itself -------------------------------------------------

def _resolve(node: dict, schema: dict) -> dict:
    while "$ref" in node:
        node = schema["$defs"][node["$ref"].rsplit("/", 1)[-1]]
    return node


def _kind(node: dict, schema: dict) -> str:
    node = _resolve(node, schema)
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    if "enum" in node:
        return " \\| ".join(f"`{json.dumps(value)}`" for value in node["enum"])
    if "oneOf" in node or "anyOf" in node:
        return " or ".join(_kind(option, schema) for option in node.get("oneOf", node.get("anyOf")))
    kind = node.get("type", "any")
    kind = " or ".join(kind) if isinstance(kind, list) else kind
    if kind == "array" and "items" in node:
        kind = f"array of {_kind(node['items'], schema)}"
    limits = [f"{word} {node[key]}" for key, word in (("minimum", ">="), ("maximum", "<="), ("minItems", "items >="),
                                                         ("maxItems", "items <="), ("minLength", "length >="))
              if key in node]
    if "pattern" in node:
        limits.append(f"matches `{node['pattern']}`")
    return kind + (f" ({', '.join(limits)})" if limits else "")


def _fields(node: dict, schema: dict, path: str, depth: int = 0):
    node = _resolve(node, schema)
    required = set(node.get("required", ()))
    for name, child in node.get("properties", {}).items():
        resolved = _resolve(child, schema)
        where = f"{path}.{name}" if path else name
        yield where, _kind(child, schema), name in required, resolved.get("description", "")
        if depth < 3:
            if resolved.get("type") == "object":
                yield from _fields(resolved, schema, where, depth + 1)
            items = _resolve(resolved.get("items", {}), schema)
            if items.get("type") == "object":
                yield from _fields(items, schema, where + "[]", depth + 1)
    extra = node.get("additionalProperties")
    if isinstance(extra, dict) and depth < 3:
        extra = _resolve(extra, schema)
        where = f"{path}.<key>" if path else "<key>"
        keys = _resolve(node.get("propertyNames", {}), schema)
        named = "any key"
        if "pattern" in keys:
            named = f"keys match `{keys['pattern']}`"
        elif "enum" in keys:
            named = "keys: " + ", ".join(f"`{json.dumps(value)}`" for value in keys["enum"])
        yield where, _kind(extra, schema), False, extra.get("description", named)
        if extra.get("type") == "object":
            yield from _fields(extra, schema, where, depth + 1)


def schema_fields(up: str, name: str) -> str:
    """The fields of one JSON Schema as a table: where, type and limits, required, meaning."""
    schema = json.loads((SCHEMAS / f"{name}.schema.json").read_text())
    rows = [f"Generated from [`{name}.schema.json`]({up}schemas/{name}.schema.json) "
            f"(`src/cospherical/data/schemas/`); the schema is what `check` and the readers enforce.", "",
            "| field | type | required | meaning |", "|---|---|---|---|"]
    for where, kind, required, description in _fields(schema, schema, ""):
        rows.append(f"| `{where}` | {kind} | {'yes' if required else ''} | {_cell(description)} |")
    return "\n".join(rows)


def _text(value) -> str:
    """A recorded value as Markdown that shows it literally, whatever it holds.

    A record is a file in the repository, and what it says is put into the site: every
    character that Markdown, HTML or the snippets extension could read as markup (a
    backtick ending a code span, ``<script>``, ``|`` splitting a table cell, ``--8<--``
    including a file) is written as a numeric character reference, which the browser shows
    as the character.
    """
    return "".join(c if (c.isascii() and c.isalnum()) or c in " .,:;/()%=+'\"" else f"&#{ord(c)};"
                   for c in " ".join(str(value).splitlines()))


def _url(name: str) -> str:
    """A file name of ``results/`` as a link's path: every character but letters, digits and ``._-`` quoted."""
    return quote(name, safe="")


# a line the snippets extension would read as an inclusion (``--8<-- "file"``), as in its own syntax
_SNIPPET_LINE = re.compile(r"^([ \t]*)(;*-+8<-+)")


def _code_block(lines, indent: str = "") -> list[str]:
    """Lines shown literally in a fenced code block, each indented by ``indent`` (inside an admonition).

    Every line break a reader may see is one: a CR, a form feed, NEL, LS and PS
    (what :meth:`str.splitlines` splits at) start a new line of the block, indented
    like the others, so that none can end the block early and put what follows
    outside it as markup. The fence is longer than any run of backticks inside.
    """
    shown = [piece for line in lines for piece in (str(line).splitlines() or [""])]
    fence = "`" * max([3] + [len(run) + 1 for line in shown for run in re.findall("`+", line)])
    return [f"{indent}{fence}text", *(indent + _SNIPPET_LINE.sub(r"\1;\2", line) for line in shown),
            f"{indent}{fence}"]


def _recorded_run(path: Path) -> list[str]:
    """One benchmark run as its script recorded it: the command, the machine and its load, the figures."""
    from cospherical.errors import FormatError

    # the readers' JSON parser: bounded nesting and digits, no repeated key; a record that is not
    # one stops the build with one line naming the file and what is wrong
    run = _json(path)
    try:
        machine, load = run["machine"], run["load_average"]
        lines = [f"Last run: <code>{_text(run['command'])}</code>, {_text(run['date'])} (commit "
                 f"<code>{_text(run.get('commit') or '?')}</code>), on {_text(machine['cores'])} cores, "
                 f"{_text(machine['memory_gib'])} GiB, {_text(machine['cpu'])}; load average "
                 f"{' / '.join(map(_text, load['before']))} before, {' / '.join(map(_text, load['after']))} after "
                 f"(1, 5, 15 min); the script's process {_text(run['cpu_seconds'])} s CPU (its children included), "
                 f"{_text(run['wall_seconds'])} s wall, peak {_text(run['peak_memory_gib'])} GiB. From "
                 f"`results/benchmarks/{path.name}`:", ""]
        if run["rows"]:
            lines += ["| what | measured |", "|---|---|"]
            lines += [f"| {_text(what)} | {_text(figure)} |" for what, figure in run["rows"]]
            lines.append("")
        for table in run.get("tables", []):
            lines += ["| " + " | ".join(map(_text, table["columns"])) + " |", "|" + "---|" * len(table["columns"])]
            lines += ["| " + " | ".join(map(_text, row)) + " |" for row in table["rows"]]
            lines.append("")
        if not isinstance(run["output"], list):
            raise TypeError(f"output is {type(run['output']).__name__}, not a list of lines")
        output = run["output"]
    except (KeyError, IndexError, TypeError, ValueError, AttributeError) as error:
        raise FormatError(f"{path}: not a benchmark record as benchmarks/record.py writes it: "
                          f"{_one_line(error)}") from None
    return lines + ['??? note "Everything it printed"', "", *_code_block(output, "    "), ""]


# --- docstrings (reStructuredText) as Markdown ----------------------------------------------------

_ROLE = re.compile(r":(?:func|class|mod|meth|data|attr|exc|obj):`~?([^`]+)`")
_LITERAL = re.compile(r"``(.+?)``")
_ITEM = re.compile(r"(?:\([a-z0-9]+\)|-) ")  # (a) or (1) enumerations, and bullets
_TABLE_RULE = re.compile(r"=+(?: +=+)+")


def _inline(text: str) -> str:
    """reST inline markup as Markdown: ``literal`` and :func:`name` become code spans."""
    text = _ROLE.sub(lambda m: f"``{m.group(1)}``", " ".join(text.split()))
    return _LITERAL.sub(lambda m: f"`{m.group(1)}`", text)


def _simple_table(lines: list[str]) -> list[str]:
    """A reST simple table (columns under ``===`` rules) as an HTML table with no header row.

    A line whose first column is blank continues the row above, as in reST; so does one that
    follows a first cell ending in a comma (a list of names run over two lines).
    """
    import html

    spans = [m.span() for m in re.finditer("=+", lines[0])]
    rows: list[list[str]] = []
    for line in lines[1:]:
        if _TABLE_RULE.fullmatch(line.strip()):
            continue
        cells = [line[start:(spans[i + 1][0] if i + 1 < len(spans) else None)].strip()
                 for i, (start, _) in enumerate(spans)]
        if rows and (not cells[0] or rows[-1][0].endswith(",")):
            rows[-1] = [f"{a} {b}".strip() for a, b in zip(rows[-1], cells)]
        else:
            rows.append(cells)

    def cell(text: str) -> str:
        parts = re.split(r"`([^`]+)`", _inline(text))  # odd parts were code spans
        return "".join(f"<code>{html.escape(part)}</code>" if i % 2 else html.escape(part)
                       for i, part in enumerate(parts))

    body = ["<tr>" + "".join(f"<td>{cell(text)}</td>" for text in row) + "</tr>" for row in rows]
    # the class keeps a member's name on one line (extra.css)
    return ['<div class="docstring-table">', "<table>", "<tbody>", *body, "</tbody>", "</table>", "</div>"]


def _markdown_of_docstring(text: str) -> str:
    """A docstring as the site shows it: paragraphs, lists, tables and indented blocks in Markdown.

    The docstrings are reStructuredText (numpy style), which Markdown would show raw: double
    backticks, roles, enumerations run together into one paragraph. This reads the few
    constructs they use; an indented block (a usage line) stays preformatted.
    """
    out = []
    for block in re.split(r"\n[ \t]*\n", text.strip("\n")):
        lines = block.splitlines()
        if _TABLE_RULE.fullmatch(lines[0].strip()):
            out += _simple_table(lines)
        elif all(line.startswith("    ") for line in lines):
            out += ["```text", *(line[4:] for line in lines), "```"]
        elif _ITEM.match(lines[0]):
            items: list[str] = []
            for line in lines:
                if _ITEM.match(line):
                    items.append(line)
                else:  # an indented continuation of the item above
                    items[-1] += " " + line.strip()
            out += [f"- {_inline(item[2:] if item.startswith('- ') else item)}" for item in items]
        else:
            out.append(_inline(block))
        out.append("")
    return "\n".join(out)


def benchmarks(up: str) -> str:
    """Each benchmark script's own docstring, then its last recorded run (results/benchmarks/*.json)."""
    import ast

    out = []
    for path in sorted((ROOT / "benchmarks").glob("bench_*.py")):
        text = ast.get_docstring(ast.parse(path.read_text())) or ""
        first, _, rest = text.partition("\n")
        out += [f"## `benchmarks/{path.name}`", "", _inline(first), "", _markdown_of_docstring(rest)]
        runs = sorted((RESULTS / "benchmarks").glob(f"{path.stem}*.json"))
        for run in runs:
            out += _recorded_run(run)
        if not runs:
            out += [f"*No recorded run yet: `python benchmarks/{path.name}` writes "
                    f"`results/benchmarks/{path.stem}.json`, and this page shows it when next built.*", ""]
    return "\n".join(out)


def benchmark_run(up: str, name: str) -> str:
    """One benchmark's last recorded run (``results/benchmarks/NAME.json``), where a page shows its figures."""
    path = RESULTS / "benchmarks" / f"{name}.json"
    if not path.is_file():
        return f"*No recorded run yet: the script writes `results/benchmarks/{name}.json` when it runs.*"
    return "\n".join(_recorded_run(path))


def module_doc(up: str, module: str) -> str:
    """A module's docstring as it stands (the specification of its file format), as Markdown."""
    import importlib

    text = importlib.import_module(module).__doc__ or ""
    return f"From the docstring of `{module}`:\n\n{_markdown_of_docstring(text)}"


# What a damaged results file raises on its way through a generator: one line, never a traceback.
_MALFORMED = (KeyError, IndexError, TypeError, ValueError, AttributeError, ArithmeticError, OSError)

GENERATORS = {
    "module-doc": module_doc,
    "benchmarks": benchmarks,
    "benchmark": benchmark_run,
    "schema": schema_fields,
    "cli": cli_reference,
    "debian-packages": debian_packages,
    "studies": studies_table,
    "paper": paper_tables,
    "intersection": intersection_table,
    "meshes": mesh_table,
    "dual": dual_table,
    "device": device_report,
    "gallery": gallery,
    "sweep": sweep_figures,
    "schemas": schemas_list,
}
