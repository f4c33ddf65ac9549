"""Writing outputs: whole files renamed into place, never through a link, in folders locked for the run.

Two shapes of the same rule, that an output is either as it was or complete:

- :func:`atomic_path` (and :func:`atomic_open`, :func:`atomic_write`) for one
  file: written to a temporary file in the same folder, renamed when complete.
- :class:`FolderLock` for a folder a command fills over a long run (``study --out``,
  with checkpoints that must outlive a failed run): locked for the run, nothing else.
- :class:`OutputFolder` for the several files of one run (``mesh --out``,
  ``render --out``): the folder is locked for the run, every file is made in a
  private staging folder inside it (programs the tool runs, such as pdflatex,
  work there too, so nothing they write can follow a link in the user's
  folder), and only when the whole run has succeeded are the files renamed into
  place, together.  A failed run leaves the folder as it found it.

Neither ever replaces what is not a regular file at an output's name (a
symbolic link, a folder, a FIFO, a device): the run is refused with one line
and the link's target is never touched.  A folder keeps a manifest of what each
command wrote there (name and SHA-256); a later run of that command removes a
file of its earlier run that it did not write again (another study's table, a
PDF not made this time) only if the manifest names it, its content is still
what was written, and its name is one the command writes itself.  The manifest
is a file on disk like any other, which anyone may have edited: it alone never
vouches for a file, so a file the user put there, or changed, is never removed,
whatever the manifest says.  The same for a killed run's staging folder: only a
folder that carries the mark of the run that made it (its own device and inode,
which a copied, unpacked or hand-made folder does not share) is removed.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import re
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterable, Iterator
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path
from types import TracebackType
from typing import IO, Any, BinaryIO, Literal, TextIO, overload

from ..errors import InputError

__all__ = ["MANIFEST", "FolderLock", "OutputFolder", "atomic_open", "atomic_path", "atomic_write", "refuse_special"]

MANIFEST = ".cospherical-manifest.json"
_STAGING_PREFIX = ".cospherical-staging."
# The staging folder's mark: a hidden name, never an output's (outputs are plain names).
_STAGING_MARK = ".cospherical-staging"
_MAX_MARK_BYTES = 200
_MAX_MANIFEST_BYTES = 1 << 20
# A name an output folder holds: one plain file name, never a path and never hidden.
_PLAIN_NAME = re.compile(r"[0-9A-Za-z][0-9A-Za-z._-]*")


def _user_path(path: str | Path) -> Path:
    """The output the user asked for: a file in an :class:`OutputFolder`'s staging folder is named
    by its place in the output folder, where it goes at the end; any other path as it is."""
    path = Path(path)
    return path.parent.parent / path.name if path.parent.name.startswith(_STAGING_PREFIX) else path


def _output_error(path: str | Path, error: OSError) -> InputError:
    return InputError(f"{_user_path(path)}: cannot write: {error.strerror or error}")


def refuse_special(path: Path) -> None:
    """An existing output must be a regular file: never replace a device, a FIFO, a symlink or a folder."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as error:
        raise _output_error(path, error) from None
    if not stat.S_ISREG(mode):
        kind = "a symbolic link" if stat.S_ISLNK(mode) else "a folder" if stat.S_ISDIR(mode) else "a special file"
        raise InputError(f"{_user_path(path)}: exists and is {kind}, not a regular file: not replacing it")


def _temporary_name(path: Path, identity: os.stat_result) -> str:
    """The name of ``path``'s temporary file: ``.NAME.DEV-INO.tmp``, its own device and inode (hexadecimal).

    The name is the file's mark: a later run removes a temporary file left by a killed
    one only when the name states the very file it is on (see
    :func:`_remove_stale_temporaries`).  A file the user made, copied or unpacked under
    such a name is another inode and is never removed.
    """
    return f".{path.name}.{identity.st_dev:x}-{identity.st_ino:x}.tmp"


def _remove_stale_temporaries(path: Path) -> None:
    """Remove the temporary files of ``path`` that earlier runs left when they were killed (SIGKILL, power loss).

    A temporary file is removed only when it proves itself one: a regular file of
    this user, its name stating its own device and inode (:func:`_temporary_name`),
    and its lock free.  A live writer holds an exclusive lock on its temporary file,
    so a file whose lock can be taken belongs to a dead process: removing it never
    disturbs a concurrent run.  A name alone proves nothing: a user's file named like
    one stays.
    """
    prefix = f".{path.name}."
    try:
        candidates = [p for p in path.parent.iterdir() if p.name.startswith(prefix) and p.name.endswith(".tmp")
                      and re.fullmatch(r"[0-9a-f]{1,16}-[0-9a-f]{1,16}", p.name[len(prefix):-4])]
    except OSError:
        return
    for candidate in candidates:
        try:
            fd = os.open(candidate, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        except OSError:
            continue
        try:
            identity = os.fstat(fd)
            if stat.S_ISREG(identity.st_mode) and identity.st_uid == os.getuid() and \
                    candidate.name == _temporary_name(path, identity):
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                candidate.unlink(missing_ok=True)
        except OSError:
            pass  # locked: a live writer
        finally:
            os.close(fd)


def _new_temporary(path: Path) -> tuple[int, Path]:
    """A new temporary file beside ``path``, locked, under its marked name (:func:`_temporary_name`).

    ``mkstemp`` makes it under a random name; it is then linked under the name that
    states its identity (a link never replaces an existing file) and the random name
    removed.  A run killed between the two leaves an empty file under the random
    name, which no later run removes: only a marked name is ever removed.
    """
    fd, first = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".new", dir=path.parent)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)  # held until the rename: marks the file as live
        marked = path.parent / _temporary_name(path, os.fstat(fd))
        try:
            os.link(first, marked)
        except OSError:  # a name too long, or taken: the file stays under its random name, never removed by a run
            return fd, Path(first)
        os.unlink(first)
    except BaseException:
        os.close(fd)
        Path(first).unlink(missing_ok=True)
        raise
    return fd, marked


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write, renamed to ``path`` only when the block ends without an error.

    The temporary file is in the same folder, so the rename is atomic: never a
    half-written file, and no temporary file left behind (one left by a killed
    run is removed by the next).  An existing ``path`` that is not a regular file
    is refused; an unwritable place raises :class:`InputError` with one line.
    """
    path = Path(path)
    refuse_special(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _remove_stale_temporaries(path)
        fd, tmp = _new_temporary(path)
    except OSError as error:
        raise _output_error(path, error) from None
    try:
        try:
            yield Path(tmp)
            refuse_special(path)
            os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file ordinary permissions
            os.replace(tmp, path)
        except OSError as error:
            raise _output_error(path, error) from None
        finally:
            os.close(fd)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@overload
def atomic_open(path: str | Path, binary: Literal[False] = False) -> AbstractContextManager[TextIO]: ...
@overload
def atomic_open(path: str | Path, binary: Literal[True]) -> AbstractContextManager[BinaryIO]: ...
@overload
def atomic_open(path: str | Path, binary: bool) -> AbstractContextManager[IO[Any]]: ...
def atomic_open(path: str | Path, binary: bool = False) -> AbstractContextManager[IO[Any]]:
    """A file to write, in place at ``path`` only when the block ends without an error (see :func:`atomic_path`)."""
    return _atomic_open(path, binary)


@contextmanager
def _atomic_open(path: str | Path, binary: bool) -> Iterator[IO[Any]]:
    with atomic_path(path) as tmp:
        try:
            handle = open(tmp, "wb") if binary else open(tmp, "w", encoding="utf-8", newline="\n")
        except OSError as error:
            raise _output_error(Path(path), error) from None
        with handle:
            yield handle


def atomic_write(path: str | Path, text: str | bytes) -> None:
    """Write text (UTF-8) or bytes atomically (see :func:`atomic_open`)."""
    with atomic_open(path, binary=isinstance(text, bytes)) as handle:
        handle.write(text)


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


class OutputFolder:
    """The outputs of one run into one folder: locked, staged, renamed into place together at the end.

    Use it as a context manager; write each output to :meth:`path` (a file of
    that name in the private staging folder).  When the block ends without an
    error every staged file is renamed to its name in the folder and the
    manifest is updated; on an error (or Ctrl-C, or SIGTERM) the staging folder
    is removed and the folder is as it was.  A second run into the same folder
    while this one holds it is refused at once with one line, rather than made
    to wait: it would overwrite this run's files the moment it got the folder,
    and a wait of minutes with no word is worse than a clear refusal.

    Parameters
    ----------
    folder : path
        The output folder; created (with its parents) if missing, and removed
        again if the run fails and the folder is still empty.
    writer : str
        The command writing (``mesh``, ``render``): the manifest keeps each
        command's files apart, so one never removes another's.
    names : iterable of str, optional
        Outputs known from the start: refused at once if their names are taken
        by a link, a folder or a special file, before any long work.
    writes : callable, optional
        Whether this command can write a file of the given name: the only names
        under which a file of an earlier run is removed.  Without it nothing is
        removed.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with OutputFolder(Path(d) / "out", "example") as out:
    ...         _ = out.path("a.txt").write_text("A")
    ...     sorted(p.name for p in (Path(d) / "out").iterdir())
    ['.cospherical-manifest.json', 'a.txt']
    """

    def __init__(self, folder: str | Path, writer: str, names: Iterable[str] = (),
                 writes: Callable[[str], object] | None = None) -> None:
        self.folder = Path(folder)
        self.writer = writer
        self._writes = writes
        self.staging: Path | None = None
        self._names = list(names)
        self._staged: list[str] = []
        self._lock: FolderLock | None = None

    def __enter__(self) -> OutputFolder:
        self._lock = FolderLock(self.folder)
        self._lock.acquire()
        try:
            for name in self._names:
                self._check_name(name)
            refuse_special(self.folder / MANIFEST)  # the manifest is written last: refuse a link there before any work
            self._remove_stale_staging()
            self.staging = Path(tempfile.mkdtemp(prefix=_STAGING_PREFIX, dir=self.folder))
            _mark_staging(self.staging)
        except BaseException:
            self._release(failed=True)
            raise
        return self

    def path(self, name: str) -> Path:
        """Where to write the output ``name``: a file in the staging folder, moved into place at the end."""
        self._check_name(name)
        if name not in self._staged:
            self._staged.append(name)
        return self._open_staging() / name

    def _open_staging(self) -> Path:
        """The staging folder, made when the ``with`` block was entered."""
        if self.staging is None:
            raise RuntimeError(f"{self.folder}: the output folder is not open (write inside its with block)")
        return self.staging

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        if kind is not None:
            staging = self.staging
            self._release(failed=True)
            # a writer in the block that failed on a staged file (a full disk): name the user's file
            if isinstance(value, OSError) and value.filename and Path(value.filename).parent == staging:
                raise _output_error(value.filename, value) from None
            return
        try:
            self._commit()
        except BaseException:
            self._release(failed=True)
            raise
        self._release(failed=False)

    def _check_name(self, name: str) -> None:
        if not _PLAIN_NAME.fullmatch(name) or name == MANIFEST:
            raise InputError(f"{name!r}: not a plain file name for an output")
        refuse_special(self.folder / name)

    def _remove_stale_staging(self) -> None:
        # The folder is locked: a staging folder that carries its mark is a killed run's. A folder of the
        # user's under a name like it (made by hand, copied, unpacked) has no mark of its own and stays.
        try:
            paths = list(self.folder.iterdir())
        except OSError as error:
            raise _output_error(self.folder, error) from None
        for path in paths:
            if path.name.startswith(_STAGING_PREFIX) and _is_marked_staging(path):
                shutil.rmtree(path, ignore_errors=True)

    def _read_manifest(self) -> dict[str, Any]:
        """The manifest, or an empty one if it is missing or damaged: then nothing is removed."""
        path = self.folder / MANIFEST
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        except OSError:
            return {}
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                return {}
            with os.fdopen(os.dup(fd), "rb") as handle:
                text = handle.read(_MAX_MANIFEST_BYTES + 1)
            data = json.loads(text.decode("utf-8")) if len(text) <= _MAX_MANIFEST_BYTES else {}
        except (OSError, ValueError, RecursionError):
            return {}
        finally:
            os.close(fd)
        if not isinstance(data, dict):
            return {}
        return {writer: {name: digest for name, digest in files.items()
                         if isinstance(name, str) and _PLAIN_NAME.fullmatch(name) and isinstance(digest, str)}
                for writer, files in data.items() if isinstance(writer, str) and isinstance(files, dict)}

    def _commit(self) -> None:
        staging = self._open_staging()
        missing = [name for name in self._staged if not os.path.isfile(staging / name)]
        if missing:
            raise InputError(f"{self.folder / missing[0]}: was not written")
        for name in [*self._staged, MANIFEST]:  # every name checked before the first rename
            refuse_special(self.folder / name)
        manifest = self._read_manifest()
        ours = {name: _sha256(staging / name) for name in self._staged}
        earlier = manifest.get(self.writer, {})
        mode = 0o666 & ~_umask()
        try:
            for name in self._staged:
                os.chmod(staging / name, mode)  # files made by mkstemp or pdflatex: ordinary permissions
                os.replace(staging / name, self.folder / name)
            for name, digest in sorted(earlier.items()):
                if name not in ours and self._writes is not None and self._writes(name):
                    self._remove_if_ours(self.folder / name, digest)
        except OSError as error:
            raise _output_error(error.filename or self.folder, error) from None
        manifest[self.writer] = dict(sorted(ours.items()))
        atomic_write(self.folder / MANIFEST, json.dumps(dict(sorted(manifest.items())), indent=1) + "\n")

    @staticmethod
    def _remove_if_ours(path: Path, digest: str) -> None:
        try:
            if stat.S_ISREG(os.lstat(path).st_mode) and _sha256(path) == digest:
                path.unlink()
        except OSError:
            pass  # gone, or unreadable: not ours to remove

    def _release(self, failed: bool) -> None:
        if self.staging is not None:
            shutil.rmtree(self.staging, ignore_errors=True)
            self.staging = None
        if self._lock is not None:
            self._lock.release(failed)


def _identity(path_stat: os.stat_result) -> str:
    return f"{path_stat.st_dev} {path_stat.st_ino}\n"


def _mark_staging(staging: Path) -> None:
    """Write into a new staging folder its own identity (device and inode): the proof, for a later run,
    that a run of the tool made it and that it is not a folder of the user's under the same name."""
    fd = os.open(staging / _STAGING_MARK, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
    with os.fdopen(fd, "w", encoding="ascii") as handle:
        handle.write(_identity(os.stat(staging)))


def _is_marked_staging(path: Path) -> bool:
    """Whether ``path`` is a staging folder that a run of the tool made, by its mark (see :func:`_mark_staging`)."""
    try:
        folder_fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
    except OSError:
        return False  # gone, a link, not a folder, unreadable
    try:
        folder = os.fstat(folder_fd)
        if folder.st_uid != os.getuid():
            return False
        fd = os.open(_STAGING_MARK, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK, dir_fd=folder_fd)
        try:
            mark = os.read(fd, _MAX_MARK_BYTES) if stat.S_ISREG(os.fstat(fd).st_mode) else b""
        finally:
            os.close(fd)
    except OSError:
        return False
    finally:
        os.close(folder_fd)
    return mark == _identity(folder).encode("ascii")


class FolderLock:
    """An output folder held by one run: created if missing, locked (``flock`` on the folder itself,
    so no lock file is left), and removed again by a run that created it, failed, and left it empty.

    A second run that asks for the folder while it is held is refused at once with one
    line (see :class:`OutputFolder` for why it is not made to wait).
    """

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        self._fd: int | None = None
        self._created = False

    def acquire(self) -> None:
        try:
            self._created = not self.folder.exists()
            self.folder.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.folder, os.O_RDONLY | os.O_DIRECTORY)
        except FileExistsError:  # mkdir's word for a file in the way says neither what is wanted nor what to do
            raise InputError(f"{self.folder}: cannot write: the output is a folder, and this name is taken by "
                             "something else (a file): remove it or choose another name") from None
        except OSError as error:
            raise _output_error(self.folder, error) from None
        try:
            fcntl.flock(self._fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.release(failed=True)
            raise InputError(f"{self.folder}: another cospherical run is writing into this folder; "
                             "wait for it to end, or choose another folder") from None

    def release(self, failed: bool) -> None:
        if self._fd is not None:
            os.close(self._fd)  # releases the lock
            self._fd = None
        if failed and self._created:
            try:
                self.folder.rmdir()  # made by this run, and still empty
            except OSError:
                pass

    def __enter__(self) -> FolderLock:
        self.acquire()
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        self.release(failed=kind is not None)
