"""Results as text: JSON laid out for people reading it, or YAML.

Below the command line, so that a library pipeline (``reproduce``) writes
exactly what the commands print.
"""

from __future__ import annotations

import json

__all__ = ["dump", "to_json"]


def to_json(data: object, indent: int = 0) -> str:
    """Indented JSON with lists of numbers and strings kept on one line, for people reading it."""
    pad, inner = " " * indent, " " * (indent + 2)
    if isinstance(data, dict) and data:
        items = [f"{inner}{json.dumps(str(k))}: {to_json(v, indent + 2)}" for k, v in data.items()]
        return "{\n" + ",\n".join(items) + f"\n{pad}}}"
    if isinstance(data, list) and any(isinstance(x, (dict, list)) for x in data):
        items = [f"{inner}{to_json(v, indent + 2)}" for v in data]
        return "[\n" + ",\n".join(items) + f"\n{pad}]"
    return json.dumps(data)


def dump(data: object, fmt: str) -> str:
    if fmt == "yaml":
        import yaml  # here: most commands write JSON, and start faster without it

        return yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=120)
    return to_json(data) + "\n"
