"""A file's text as committed in git, read with the same bounds as a file on disk."""

from __future__ import annotations

import subprocess
from pathlib import Path

from ..errors import FormatError
from . import yamlio

__all__ = ["git_text"]


def _git(args: list[str], cwd: Path, what: str) -> subprocess.CompletedProcess[bytes]:
    try:
        result = subprocess.run(["git", *args], cwd=cwd, capture_output=True, stdin=subprocess.DEVNULL)
    except OSError as error:
        raise FormatError(f"git: {error.strerror}") from None
    if result.returncode != 0:
        message = (result.stderr.decode("utf-8", "replace").strip().splitlines() or ["git failed"])[-1]
        raise FormatError(f"{what}: {message}")
    return result


def git_text(rev: str, path: str | Path) -> str:
    """The UTF-8 text of ``path`` at revision ``rev`` of the repository that holds it.

    The blob's size is asked first (``git cat-file -s``) and a blob larger than
    the file reader's bound (:data:`~cospherical.files.yamlio.MAX_INPUT_BYTES`)
    is refused before a byte of it is read; a blob that is not UTF-8 is refused
    as a file would be.  ``rev`` must already be checked to be a revision, not an
    option (it follows ``--end-of-options`` here as well).
    """
    path = Path(path).resolve()
    what = f"{path.name} at {rev}"
    spec = f"{rev}:./{path.name}"
    limit = yamlio.MAX_INPUT_BYTES
    size_text = _git(["cat-file", "-s", "--end-of-options", spec], path.parent, what).stdout.strip()
    if not size_text.isdigit():
        raise FormatError(f"{what}: git cat-file -s gave no size")
    if int(size_text) > limit:
        raise FormatError(f"{what}: cannot read: too large ({int(size_text)} bytes; at most {limit})")
    data = _git(["cat-file", "blob", "--end-of-options", spec], path.parent, what).stdout
    if len(data) > limit:  # the revision moved between the two calls
        raise FormatError(f"{what}: cannot read: too large (more than {limit} bytes)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise FormatError(f"{what}: cannot read: not UTF-8 text (byte {error.start})") from None
