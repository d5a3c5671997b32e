"""Reading user input: TOML tables with typed, range-checked keys and one-line errors.

Every mistake a user can make in a topology or scene file is reported as an
:class:`InputError` whose text is one line naming the file, the key, the value
and what is allowed.  Unknown keys are rejected with the nearest valid name.
"""

from __future__ import annotations

import ast
import difflib
import keyword
import math
import operator
import re
import tomllib
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from ..escape import is_identifier, is_target_name, one_line

__all__ = ["InputError", "Table", "load_toml", "nearest", "parse_expression"]


class InputError(ValueError):
    """A user input is wrong.  ``str(err)`` is one line: ``source: key: message``."""

    def __init__(self, source: str, key: str, message: str):
        self.source = source
        self.key = key
        self.message = message
        where = f"{source}: {key}" if key else source
        super().__init__(one_line(f"{where}: {message}"))


def nearest(name: str, allowed: Iterable[str]) -> str:
    """Return ``" (did you mean 'x'?)"`` for the closest allowed name, or ``""``."""
    close = difflib.get_close_matches(name, list(allowed), n=1, cutoff=0.5)
    return f" (did you mean '{close[0]}'?)" if close else ""


def load_toml(path: Path) -> dict[str, Any]:
    """Parse a TOML file, turning I/O and syntax errors into :class:`InputError`."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(str(path), "", "file not found; give the path of a .toml file") from None
    except IsADirectoryError:
        raise InputError(str(path), "", "is a folder; give the path of a .toml file") from None
    except OSError as err:
        raise InputError(str(path), "", f"cannot be read ({err.strerror})") from None
    except UnicodeDecodeError as err:
        raise InputError(
            str(path), "", f"is not UTF-8 text (byte {err.start}); save it as UTF-8"
        ) from None
    return parse_toml(text, str(path))


MAX_DEPTH = 32  # scenes nest 3 levels; far below Python's recursion limit, for every reader


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse TOML ``text`` of file ``source``: syntax errors and nesting deeper than
    :data:`MAX_DEPTH` arrays or tables (tomllib, copies, hashes recurse) are InputErrors."""
    deep = f"nests arrays or tables deeper than {MAX_DEPTH} levels; flatten it"
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(source, "", f"is not valid TOML: {err}") from None
    except RecursionError:
        raise InputError(source, "", deep) from None
    pending = [(data, 1, "")]
    while pending:  # iterative: the check must not recurse itself
        value, depth, key = pending.pop()
        if depth > MAX_DEPTH:
            raise InputError(source, key.split(".")[0], deep)
        items = value.items() if isinstance(value, dict) else enumerate(value)
        for k, v in items:
            if isinstance(v, dict | list):
                pending.append((v, depth + 1, key or str(k)))
    return data


_MISSING = object()
_MAX_EXPRESSION = 200


def shown(value: Any) -> str:
    """What a wrong value is, for a message: ``"an array [1, 2]"``, ``"the text 'x'"``
    (its ``repr`` cut to 60 characters)."""
    kinds = (
        (bool, "true or false"),
        (int | float, "a number"),
        (str, "the text"),
        (list, "an array"),
        (dict, "a table"),
    )
    what = next((w for t, w in kinds if isinstance(value, t)), type(value).__name__)
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        what = "an array of tables"
    text = repr(value)
    return f"{what} {text if len(text) <= 60 else text[:57] + '...'}"


def not_a_table(source: str, key: str, value: Any) -> InputError:
    """The error for ``value`` at ``key`` where a table belongs, saying how to write one."""
    if key.endswith("]"):  # an entry of an array of tables
        form = f"one [[{key.rsplit('[', 1)[0]}]] entry with its keys below"
    else:
        head = f"[{key}] with its keys below, or " if "[" not in key else ""
        form = f"{head}{key.rsplit('.', 1)[-1]} = {{ key = value, ... }}"
    fix = f"; write [{key}] once" if isinstance(value, list) and "[" not in key else ""
    return InputError(source, key, f"must be a table ({form}), got {shown(value)}{fix}")


class Table:
    """One TOML table being read: typed accessors, then :meth:`finish` rejects leftovers.

    Parameters
    ----------
    data : dict
        The parsed table.
    source : str
        The file name, used in messages.
    prefix : str
        Dotted path of this table inside the file (``"gear[2]"``), used in messages.
    """

    def __init__(self, data: Any, source: str, prefix: str = ""):
        if not isinstance(data, dict):
            raise not_a_table(source, prefix, data)
        self.data = data
        self.source = source
        self.prefix = prefix
        self._seen: set[str] = set()

    def key(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def error(self, name: str, message: str) -> InputError:
        return InputError(self.source, self.key(name), message)

    def where(self, name: str) -> str:
        """``source: key`` for messages that are not errors (warnings)."""
        return f"{self.source}: {self.key(name)}"

    def has(self, name: str) -> bool:
        """Whether ``name`` is present; it counts as a known key from then on."""
        self._seen.add(name)
        return name in self.data

    def _get(self, name: str, default: Any) -> Any:
        self._seen.add(name)
        if name in self.data:
            return self.data[name]
        if default is _MISSING:
            raise self.error(name, "is required but missing")
        return default

    def number(
        self,
        name: str,
        default: Any = _MISSING,
        *,
        low: float | None = None,
        high: float | None = None,
        low_open: bool = False,
        high_open: bool = False,
    ) -> float:
        """A finite real number in ``[low, high]`` (open ends as flagged)."""
        value = self._get(name, default)
        if value is None:
            return value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(name, f"must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise self.error(name, f"must be finite, got {value!r}")
        if low is not None and (value < low or (low_open and value == low)):
            sign = ">" if low_open else ">="
            raise self.error(name, f"must be {sign} {low:g}, got {value:g}")
        if high is not None and (value > high or (high_open and value == high)):
            sign = "<" if high_open else "<="
            raise self.error(name, f"must be {sign} {high:g}, got {value:g}")
        return value

    def integer(
        self, name: str, default: Any = _MISSING, *, low: int | None = None, high: int | None = None
    ) -> int:
        value = self._get(name, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(name, f"must be a whole number, got {value!r}")
        if low is not None and value < low:
            raise self.error(name, f"must be >= {low}, got {value}")
        if high is not None and value > high:
            raise self.error(name, f"must be <= {high}, got {value}")
        return value

    def string(
        self, name: str, default: Any = _MISSING, *, choices: Iterable[str] | None = None
    ) -> str:
        value = self._get(name, default)
        if value is None:
            return value
        if not isinstance(value, str):
            raise self.error(name, f'must be text in quotes ("..."), got {shown(value)}')
        if choices is not None:
            choices = list(choices)
            if value not in choices:
                raise self.error(
                    name,
                    f"'{value}' is not one of {', '.join(repr(c) for c in choices)}"
                    + nearest(value, choices),
                )
        return value

    def target_name(self, name: str) -> str:
        """A scene or topology name: it names ``generated/<name>.py`` ('-' becomes '_')."""
        value = self.string(name)
        if not is_target_name(value):
            raise self.error(
                name,
                f"{value!r} must start with a letter and use only letters, digits, '-' and '_' "
                "(it names the generated module)",
            )
        return value

    def identifier(self, name: str) -> str:
        """A name that becomes a Python identifier in generated code (letters, digits)."""
        value = self.string(name)
        if not is_identifier(value):
            raise self.error(
                name,
                f"{value!r} must be letters and digits starting with a letter, and not a "
                "Python keyword (it becomes a name in generated code)",
            )
        return value

    def boolean(self, name: str, default: Any = _MISSING) -> bool:
        value = self._get(name, default)
        if not isinstance(value, bool):
            raise self.error(name, f"must be true or false, got {value!r}")
        return value

    def numbers(
        self,
        name: str,
        default: Any = _MISSING,
        *,
        length: int | None = None,
        low: float | None = None,
    ) -> tuple[float, ...]:
        value = self._get(name, default)
        if not isinstance(value, list | tuple) or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in value
        ):
            raise self.error(name, f"must be a list of finite numbers, got {shown(value)}")
        if length is not None and len(value) != length:
            raise self.error(name, f"must have {length} entries, got {len(value)}")
        if low is not None and any(v < low for v in value):
            raise self.error(name, f"entries must be >= {low:g}, got {list(value)}")
        return tuple(float(v) for v in value)

    def table(self, name: str, default: Any = _MISSING) -> Table | None:
        value = self._get(name, default)
        if value is None:
            return None
        if not isinstance(value, dict):
            raise not_a_table(self.source, self.key(name), value)
        return Table(value, self.source, self.key(name))

    def tables(self, name: str) -> list[Table]:
        """An array of tables ``[[name]]`` (required, non-empty)."""
        value = self._get(name, _MISSING)
        if not isinstance(value, list) or not value:
            raise self.error(
                name,
                f"must be a non-empty array of tables (one [[{self.key(name)}]] header per "
                f"entry), got {shown(value)}",
            )
        return [Table(v, self.source, f"{self.key(name)}[{i}]") for i, v in enumerate(value)]

    def raw(self, name: str, default: Any = _MISSING) -> Any:
        return self._get(name, default)

    def finish(self, allowed_extra: Iterable[str] = ()) -> None:
        """Reject any key that was not read (with the nearest valid name)."""
        known = self._seen | set(allowed_extra)
        for name in self.data:
            if name not in known:
                raise self.error(
                    name,
                    "unknown key"
                    + nearest(name, known)
                    + f"; allowed keys: {', '.join(sorted(known))}",
                )


_KEYWORD = re.compile(r"\b(?:" + "|".join(keyword.kwlist) + r")\b")

_BINARY: dict[type, Callable[[float, float], float]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}


def parse_expression(text: str, names: dict[str, float], *, source: str, key: str) -> float:
    """Evaluate an arithmetic expression of named scene parameters, safely.

    Only numbers, the given names, ``+ - * / **``, unary signs and parentheses are
    allowed; nothing is executed.  ``"-lambda*f1"`` with ``lambda=0.1, f1=0.5`` gives -0.05.
    """
    if isinstance(text, bool):
        raise InputError(source, key, f"must be a number or an expression, got {text!r}")
    if isinstance(text, int | float):
        return float(text)
    if not isinstance(text, str):
        raise InputError(source, key, f"must be a number or an expression, got {text!r}")
    if len(text) > _MAX_EXPRESSION or "__kw" in text:
        raise InputError(
            source,
            key,
            f"'{text[:40]}...' is not a plain arithmetic expression of at most "
            f"{_MAX_EXPRESSION} characters",
        )
    # Scene parameters may be named like Python keywords ("lambda"): rename before parsing.
    mangled = _KEYWORD.sub(lambda mo: mo.group(0) + "__kw", text)
    try:
        tree = ast.parse(mangled, mode="eval")
    except SyntaxError:
        raise InputError(source, key, f"'{text}' is not an arithmetic expression") from None

    def walk(node: ast.AST) -> float:
        if isinstance(node, ast.Expression):
            return walk(node.body)
        if (
            isinstance(node, ast.Constant)
            and isinstance(node.value, int | float)
            and not isinstance(node.value, bool)
        ):
            return float(node.value)
        if isinstance(node, ast.Name):
            name = node.id.removesuffix("__kw")
            if name not in names:
                raise InputError(
                    source,
                    key,
                    f"'{name}' in '{text}' is not a scene parameter"
                    + nearest(name, names)
                    + f"; parameters: {', '.join(sorted(names))}",
                )
            return float(names[name])
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            value = walk(node.operand)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            try:
                return _BINARY[type(node.op)](walk(node.left), walk(node.right))
            except ZeroDivisionError:
                raise InputError(source, key, f"'{text}' divides by zero") from None
        raise InputError(
            source,
            key,
            f"'{text}' may use only numbers, scene parameters, + - * / ** and parentheses",
        )

    try:
        value = walk(tree)
    except (OverflowError, RecursionError):
        raise InputError(source, key, f"'{text}' overflows; use smaller numbers") from None
    if isinstance(value, complex):
        raise InputError(
            source, key, f"'{text}' is not a real number (negative base to a fractional power)"
        )
    if not math.isfinite(value):
        raise InputError(source, key, f"'{text}' evaluates to {value}")
    return value


def expression_source(text: str | float, mapping: str = "s") -> str:
    """Python source of a load expression already checked by :func:`parse_expression`,
    with each parameter ``name`` read as ``s['name']``: ``"-lambda*f1"`` gives
    ``"-s['lambda'] * s['f1']"``."""
    if not isinstance(text, str):
        return repr(float(text))
    tree = ast.parse(_KEYWORD.sub(lambda mo: mo.group(0) + "__kw", text), mode="eval")

    class _Names(ast.NodeTransformer):
        def visit_Name(self, node):  # noqa: N802 (ast API)
            key = ast.Constant(node.id.removesuffix("__kw"))
            return ast.Subscript(ast.Name(mapping, ast.Load()), key, ast.Load())

    return ast.unparse(_Names().visit(tree))
