"""The ``cospherical`` command: a thin layer, one module per subcommand.

A subcommand's module says what it is (``HELP``, one line; ``DESCRIPTION``), which options it
takes (``add_arguments(parser)``) and what it does (``run(args)``, the exit status); the
parser is put together here.
"""

from __future__ import annotations

import argparse
import errno
import gc
import importlib
import os
import signal
import sys
import threading
import warnings
from types import FrameType
from typing import TYPE_CHECKING, NoReturn, TextIO

from ..errors import CosphericalError, CosphericalWarning, UsageError, one_line
from ..version import __version__

if TYPE_CHECKING:
    from _typeshed import SupportsWrite

__all__ = ["build_parser", "main"]

# One module per subcommand, imported inside main() so that an interrupt while
# the heavy libraries load is handled like any other.
_SUBCOMMANDS = ("tessellate", "study", "reproduce", "render", "diff", "check", "sweep", "mesh")


class _Parser(argparse.ArgumentParser):
    # argparse prints the whole usage block; a usage error here is one line.
    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{self.prog}: error: {message}")

    # argparse drops a failed write of --help or --version (a closed stdout, /dev/full) and exits 0;
    # written and flushed here, the failure reaches main's one line and exit 2 like any other output's.
    def _print_message(self, message: str, file: SupportsWrite[str] | None = None) -> None:
        if message:
            stream = file or sys.stderr
            stream.write(message)
            flush = getattr(stream, "flush", None)  # argparse hands sys.stdout or sys.stderr
            if flush is not None:
                flush()


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The whole command's parser; ``only``: with that one subcommand alone.

    A subcommand module imports what its ``run`` needs; importing all eight to
    parse one command line would load everything (numpy, jinja2, ...) for a
    command that takes milliseconds.
    """
    parser = _Parser(
        prog="cospherical",
        description="Delaunay tessellations of 1-irregular cuboids with co-spherical elements.",
    )
    parser.add_argument("--version", action="version", version=f"cospherical {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name in _SUBCOMMANDS if only is None else (only,):
        command = importlib.import_module(f"{__name__}.{name}")
        subparser = commands.add_parser(name, help=command.HELP, description=command.DESCRIPTION)
        command.add_arguments(subparser)
        subparser.set_defaults(run=command.run)
    return parser


_interrupted = threading.Event()
_terminated = threading.Event()
_redelivery: list[threading.Timer] = []  # signals held back while numba's compiler or a fork hook ran


def _on_signal(signum: int, frame: FrameType | None) -> None:
    # SIGINT unwinds as KeyboardInterrupt, SIGTERM as SystemExit(143), so that temporary
    # files are removed and every output stays either the old complete file or the new
    # complete file. Each is remembered as well as raised: raised inside a call into
    # compiled code it can come back as that library's own error (numba: SystemError,
    # numpy: ImportError) or be swallowed there, and the run must still end as signalled.
    (_terminated if signum == signal.SIGTERM else _interrupted).set()
    if _cannot_unwind(frame):
        # Unwinding through numba's compiler or cache loader crashes the process (SIGSEGV), and
        # an exception raised in logging's fork hooks (os.fork runs them while a pool starts a
        # worker) is printed as "Exception ignored" with a traceback, then dropped: deliver the
        # signal again shortly, until it arrives outside.
        # A daemon, and cancelled when the run ends first: never delivered after main returns.
        timer = threading.Timer(0.1, os.kill, (os.getpid(), signum))
        timer.daemon = True
        _redelivery.append(timer)
        timer.start()
        return
    if signum == signal.SIGTERM:
        raise SystemExit(128 + signum)
    raise KeyboardInterrupt


def _cannot_unwind(frame: FrameType | None) -> bool:
    while frame is not None:
        name = frame.f_globals.get("__name__", "")
        if name.startswith(("numba.", "llvmlite.")) or name == "logging":
            return True
        frame = frame.f_back
    return False


class _ClosedStdout:
    """Standard output when the command was started with it closed (``>&-``): the first write
    fails as a write to a closed descriptor does, and the error policy turns that into one line."""

    def write(self, text: str) -> int:
        raise OSError(errno.EBADF, "standard output is closed")

    def flush(self) -> None:
        pass

    def fileno(self) -> int:
        return 1  # /dev/null by now (see _closed_standard_streams)


def _closed_standard_streams() -> None:
    # A closed descriptor 1 or 2 would be reused by the next file opened (an output's
    # temporary file, a pipe to pdflatex), and whatever is written to the stream would land
    # in it: /dev/null takes the place first.
    for fd, name in ((1, "stdout"), (2, "stderr")):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, os.O_WRONLY)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)
            setattr(sys, name, _ClosedStdout() if fd == 1 else open(fd, "w", closefd=False))


def main(argv: list[str] | None = None) -> int:
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _on_signal)
        signal.signal(signal.SIGINT, _on_signal)
    _interrupted.clear()
    _terminated.clear()
    if argv is None:
        # Run as the process's command, before numpy loads: OpenBLAS starts a thread per core as it
        # loads and they spin, ~0.05 s CPU of every run (0.11 -> 0.06 s for `import numpy`), for
        # linear algebra no command calls. One thread, unless the environment asks for more.
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
        # The cycle collector's first generation every 50,000 allocations instead of 700: a command's
        # objects (arrays, tuples, Fractions, frozen dataclasses) hold almost no cycles, and at the
        # default the collector ran ~160 times in a level-7 mesh run for 0.025 s CPU (0.008 s now).
        gc.set_threshold(50_000, *gc.get_threshold()[1:])
    _closed_standard_streams()
    with warnings.catch_warnings():
        python_shows = warnings.showwarning

        def show(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                 file: TextIO | None = None, line: str | None = None) -> None:
            # the library's warnings about the input are one line, as its errors are; others as Python shows them
            if issubclass(category, CosphericalWarning):
                _say(f"cospherical: warning: {message}")
            else:
                python_shows(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    try:
        words = sys.argv[1:] if argv is None else argv
        command = next((word for word in words if not word.startswith("-")), None)
        args = build_parser(command if command in _SUBCOMMANDS else None).parse_args(argv)
        status: int = args.run(args)
        sys.stdout.flush()  # a full disk or /dev/full shows here, as one line, not at exit
        if _terminated.is_set():
            raise SystemExit(128 + signal.SIGTERM)
        if _interrupted.is_set():
            raise KeyboardInterrupt
        if argv is None:
            # Run as the process's command, which ends now: what it made is moved out of
            # the cycle collector's reach, so that the collector's pass at exit does not
            # traverse it all once more (30-40 ms of the 0.4 s of `study bisection`).
            gc.freeze()
        return status
    except UsageError as error:  # the message already names the command
        _say(str(error))
        return 2
    except CosphericalError as error:
        _say(f"cospherical: error: {error}")
        return 2
    except KeyboardInterrupt:
        _stop_workers()
        print("cospherical: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader (``| head``) has gone: stop quietly; keep Python from
        # complaining again when it flushes stdout at exit.
        _silence_stdout()
        return 141
    except OSError as error:  # the system refused: a full disk, a missing device, too many files, ...
        where = f"{error.filename}: " if error.filename else ""
        _say(f"cospherical: error: {where}{error.strerror or error}")
        _silence_stdout()
        return 2
    except MemoryError:  # the tree or table outgrew what this process may allocate (RLIMIT_AS, the machine)
        _stop_workers()
        print("cospherical: error: out of memory: the work needs more memory than this process may use "
              "(a smaller tree or table, or --max-leaves for mesh)", file=sys.stderr)
        _silence_stdout()
        return 2
    except Exception:
        # A signal that a library turned into its own error (numba: SystemError, numpy: ImportError).
        if _terminated.is_set():
            _stop_workers()
            print("cospherical: terminated", file=sys.stderr)
            raise SystemExit(128 + signal.SIGTERM) from None
        if _interrupted.is_set():
            _stop_workers()
            print("cospherical: interrupted", file=sys.stderr)
            return 130
        raise
    except SystemExit as exit:
        if exit.code == 128 + signal.SIGTERM:
            _stop_workers()
            print("cospherical: terminated", file=sys.stderr)
        raise
    finally:
        while _redelivery:  # the run has ended as signalled: a held-back signal is not sent again
            _redelivery.pop().cancel()


def _say(message: str) -> None:
    """The one way an error reaches stderr: one line, whatever paths or values it names
    (their line breaks and control characters escaped, see :func:`cospherical.errors.one_line`)."""
    print(one_line(message), file=sys.stderr)


def _stop_workers() -> None:
    # Worker processes still running (a pool, a local Dask cluster) are stopped now, not
    # joined at exit, which would wait for the chunks they are running.
    pool = sys.modules.get("cospherical.execution.pool")  # loaded only if workers were started
    if pool is not None:
        pool.stop_all()


def _silence_stdout() -> None:
    # Whatever is still buffered for stdout is dropped: Python would report the
    # same failure again when it flushes at exit.
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
