"""One error hierarchy for the whole library; the CLI turns it into exit codes.

Every error the library raises on purpose is a :class:`CosphericalError`, and its
message names the value, or the file and the place in it, so that one line on
stderr tells a user what to fix.  The library never exits; ``cospherical.cli``
maps these to exit status 2.

Examples
--------
>>> issubclass(FormatError, InputError), issubclass(UsageError, CosphericalError)
(True, True)
"""

from __future__ import annotations

__all__ = ["CosphericalError", "CosphericalWarning", "FormatError", "InputError", "UsageError", "one_line", "shown"]


class CosphericalError(Exception):
    """Base class of every error cospherical raises on purpose."""


class InputError(CosphericalError, ValueError):
    """A value given by the user cannot be used; the message names it."""


class FormatError(InputError):
    """A file does not have the expected format; the message names the file and the place."""


class UsageError(CosphericalError):
    """A command-line usage error: a missing, conflicting or malformed option."""


class CosphericalWarning(UserWarning):
    """An input that is used but most likely not what was meant (a refinement shape outside the
    domain): the library warns with :func:`warnings.warn`, the CLI prints one line on stderr."""


def shown(value: object, most: int = 40) -> str:
    """A value as an error line names it: its repr, cut after ``most`` characters (a hostile input of
    megabytes is named, not echoed).

    >>> shown("8" * 12), shown("x" * 100)
    ("'888888888888'", "'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...")
    """
    try:
        text = repr(value)
    except ValueError:  # an int past Python's 4,300-digit limit of int-to-text conversion
        if not isinstance(value, int):
            raise
        return f"an integer of {value.bit_length():,} bits"
    return text if len(text) <= most else text[:most] + "..."


def one_line(text: str) -> str:
    r"""A message as one line that a terminal shows as written: every character that is not
    printable (a line break of any kind, ESC and the other controls, an invisible format
    character such as a bidirectional override) written as its Python escape.

    A message names paths and values that came from outside (a file name may hold a newline
    or an ESC sequence): printed raw, one would split the error line in two, the other
    would drive the terminal.

    >>> one_line("out\nfake: ok\x1b[2J\u2028\u202e")
    'out\\nfake: ok\\x1b[2J\\u2028\\u202e'
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))
