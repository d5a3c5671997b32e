"""The one door through which text enters a generated file.

A generated module is imported, and its C is compiled: nothing a user writes (a file path,
a scene or gear name, a description) may become code there.  Every emitter (``emit.py``,
``emit_c.py``, the audit pages) takes user text through this module only:

* :func:`literal` -- a Python string literal (``repr``), for values the module keeps;
* :func:`text` -- printable ASCII for comments, docstrings and C comments: a backslash,
  a double quote, a ``*/`` and every character outside ``' '..'~'`` (a newline, a NUL,
  a non-ASCII letter) are written as backslash escapes, so no line can be broken, no
  docstring or comment closed;
* :func:`markdown` -- the same for Markdown prose and code spans of the audit pages;
* :func:`code_name` -- the identifier a model symbol takes in generated Python and C:
  ``m_<name>``, a namespace that no name of the generated code or of the C host file
  (``solver/integrate/native/native_*.c``, ``math.h``) uses, so that any name a topology
  accepts (``int``, ``q``, ``NAN``, ``restrict``, ``np``, ``th0``) compiles in both;
* :func:`is_identifier` -- the check of a user's name: the *whole* string matches (a
  trailing newline does not pass, as it would with ``re.match`` and ``$``).

Following SymPy's printers and PyDy's code generators, which never paste user strings into
source (STYLE.md, rule 16).
"""

from __future__ import annotations

import keyword
import re

__all__ = [
    "CODE_PREFIX",
    "code_name",
    "code_names",
    "is_identifier",
    "is_target_name",
    "literal",
    "markdown",
    "one_line",
    "text",
]

CODE_PREFIX = "m_"

# A user's name that becomes part of an identifier: ASCII letters and digits.
_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9]*")
# A scene or topology name: it names generated/<name>.py ('-' becomes '_').
_TARGET_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
# A model symbol's name (derived from user identifiers: kc_u_1, xi_u_v, du).
_SYMBOL = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def is_identifier(value: object) -> bool:
    """Whether ``value`` is a name a user may give a gear, mesh, coordinate or shaft: ASCII
    letters and digits, starting with a letter, the whole string, not a Python keyword."""
    return (
        isinstance(value, str)
        and _IDENTIFIER.fullmatch(value) is not None
        and not keyword.iskeyword(value)
    )


def is_target_name(value: object) -> bool:
    """Whether ``value`` may name a scene or topology (letters, digits, '-', '_')."""
    return isinstance(value, str) and _TARGET_NAME.fullmatch(value) is not None


def code_name(name: str) -> str:
    """The identifier of model symbol ``name`` in generated Python and C: ``m_<name>``.

    Raises ``ValueError`` for a name that is not a plain identifier (the derivation makes
    symbol names from checked identifiers only, so this is a bug, never user error)."""
    if not isinstance(name, str) or _SYMBOL.fullmatch(name) is None:
        raise ValueError(f"not a symbol name for generated code: {name!r}")
    return CODE_PREFIX + name


def code_names(symbols) -> dict:
    """``{symbol: code_name(symbol.name)}`` for the model symbols a printer maps."""
    return {s: code_name(s.name) for s in symbols}


def literal(value: str) -> str:
    """A Python string literal of ``value`` (its ``repr``): evaluates to ``value``."""
    return repr(str(value))


_ESCAPES = {"\\": "\\\\", '"': '\\"', "\n": "\\n", "\r": "\\r", "\t": "\\t"}


def _char(c: str) -> str:
    if c in _ESCAPES:
        return _ESCAPES[c]
    if " " <= c <= "~":
        return c
    code = ord(c)
    if code <= 0xFF:
        return f"\\x{code:02x}"
    if code <= 0xFFFF:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def text(value: object) -> str:
    """``value`` as printable ASCII that is safe in a ``#`` comment, a ``\"\"\"`` docstring
    and a C ``/* */`` comment: backslash escapes for ``\\``, ``\"``, every character outside
    ``' '..'~'``, and the ``/`` of ``*/`` as ``\\x2f``.  In a docstring the escapes read back
    as the original text; in a comment they are shown as they are."""
    out = "".join(_char(c) for c in str(value))
    return out.replace("*/", "*\\x2f")


_MARKDOWN_SPECIAL = re.compile(r"([\\`*_\[\]<>|&])")


def markdown(value: object, *, code: bool = False) -> str:
    """``value`` for an audit page: printable ASCII (:func:`text`), and for prose each
    Markdown or HTML character backslash-escaped; in a code span (``code=True``) a
    backtick, which would close it, becomes ``'``."""
    out = text(value)
    if code:
        return out.replace("`", "'")
    return _MARKDOWN_SPECIAL.sub(r"\\\1", out)


def one_line(value: object) -> str:
    """``value`` for a one-line message on a terminal: control characters (a newline in a
    file path, an escape sequence) as backslash escapes; letters of any script kept."""
    return "".join(_char(c) if (c < " " or "\x7f" <= c <= "\x9f") else c for c in str(value))
