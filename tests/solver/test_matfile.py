"""The .mat writer against SciPy's: the same file content, as ``scipy.io.loadmat`` reads it.

The reference route is the one gearsym took before its own writer: the document turned
into what ``scipy.io.savemat`` takes (``_reference`` below, the old conversion) and
written by ``savemat(..., long_field_names=True, do_compression=True)``.  Both files are
read back with ``loadmat`` and compared class by class, shape by shape, value by value.
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from gearsym.solver._json import clean
from gearsym.solver._matfile import _field, mat_bytes
from scipy.io import loadmat, savemat


def _cells(items: list) -> np.ndarray:
    out = np.empty(len(items), dtype=object)
    out[:] = items
    return out


def _number(v) -> bool:
    return v is None or (isinstance(v, int | float) and not isinstance(v, str))


def _reference(obj):
    """The document as savemat takes it (the conversion export.py used before)."""
    if isinstance(obj, np.ndarray) and obj.dtype.kind in "fiub":
        return np.asarray(obj, dtype=float)
    if isinstance(obj, dict):
        return {_field(k): _reference(v) for k, v in obj.items()}
    obj = clean(obj)
    if isinstance(obj, dict):
        return {_field(k): _reference(v) for k, v in obj.items()}
    if isinstance(obj, list):
        if obj and all(_number(v) for v in obj):
            return np.array([np.nan if v is None else float(v) for v in obj], dtype=float)
        if (
            obj
            and all(isinstance(r, list) and r and all(_number(v) for v in r) for r in obj)
            and len({len(r) for r in obj}) == 1
        ):
            return np.array([[np.nan if v is None else float(v) for v in r] for r in obj])
        return _cells([_reference(v) for v in obj])
    if obj is None:
        return np.nan
    if isinstance(obj, bool):
        return float(obj)
    return obj


def _equal(a, b, where: str = "") -> None:
    assert type(a) is type(b), (where, type(a), type(b))
    if isinstance(a, dict):
        assert set(a) - {"__header__"} == set(b) - {"__header__"}, where
        for k in set(a) - {"__header__"}:
            _equal(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, np.ndarray):
        assert a.shape == b.shape, (where, a.shape, b.shape)
        assert a.dtype == b.dtype, (where, a.dtype, b.dtype)
        if a.dtype.names:
            assert a.dtype.names == b.dtype.names, where
            for n in a.dtype.names:
                for i in np.ndindex(a.shape):
                    _equal(a[n][i], b[n][i], f"{where}.{n}{i}")
        elif a.dtype == object:
            for i in np.ndindex(a.shape):
                _equal(a[i], b[i], f"{where}{i}")
        else:
            assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), where
    else:
        assert a == b, where


def _same_as_scipy(variables: dict) -> None:
    ref = io.BytesIO()
    savemat(
        ref,
        {k: _reference(v) for k, v in variables.items()},
        long_field_names=True,
        do_compression=True,
    )
    ours = mat_bytes(variables)
    _equal(loadmat(io.BytesIO(ref.getvalue())), loadmat(io.BytesIO(ours)))
    # and the readings a MATLAB-minded user picks in Python
    for how in ({"simplify_cells": True}, {"squeeze_me": True}, {"struct_as_record": False}):
        loadmat(io.BytesIO(ours), **how)


def test_every_rule_of_the_conversion_gives_scipys_file():
    document = {
        "int": 1,
        "float": 2.5,
        "text": "µ λ ω̄ text",
        "empty text": "",
        "numbers with null": [1, 2, None],
        "matrix": [[1.0, 2.0], [3.0, 4.0]],
        "texts": ["x", "yy"],
        "records": [{"p": 1}, {"q": "z"}],
        "empty dict": {},
        "empty list": [],
        "boolean": True,
        "null": None,
        "array 2-D": np.arange(6.0).reshape(2, 3),
        "array empty": np.array([]),
        "mixed": [1, "a"],
        "nested": {"deep": {"deeper": [0.5]}},
        "non-finite array": np.array([1.0, np.inf, np.nan]),  # kept as it is
        "arrays in a list": [np.array([1.0, np.inf]), 2],  # JSON form: inf as null
        "tuple": (1, 2.0),
        "rows with null": [[1, None], [2, 3]],
        "ragged": [[1], [2, 3]],
        "booleans in numbers": [True, 2],
        "9 starts with a digit": np.float64(2.5),
        "numpy int": np.int64(7),
        "inf in a record": [{"a": float("inf")}],
        "list of empty list": [[]],
        "unicode array": np.array(["a", "b"]),
        "one null": [None],
        "a-b": 1,  # and "a_b": one field name, the later value (as savemat's dict)
        "a_b": [{"x-y": 1, "x_y": 2}],
        # the writer's short cuts: plain lists and scalars not put through their JSON
        # form, lists holding records written element by element
        "plain non-finite": [1.0, float("inf"), float("-inf"), float("nan"), None],
        "plain inf": float("-inf"),
        "plain mixed": [1, True, "s", None, float("inf")],
        "numpy in a list": [np.float64(2.0), 1.0],
        "records among others": [{"a": np.float64(1.0), "b": [1.0, None]}, 2.0, "x", [1.0]],
        "records in a tuple": ({"q": (1, 2)}, {"r": float("nan")}),
        # arrays inside a list are in their JSON form (inf as null), records or not
        "arrays in records": [
            {"x": np.array([1.0, np.inf]), "e": np.array([]), "z": np.array(3)},
            {"m": np.zeros((2, 2)), "k": [np.int64(2), 1.5]},
        ],
    }
    table = {"x": np.array([1.0, 2.0]), "s": _cells(["a", ""])}
    _same_as_scipy({"result": document, "table": table})


@pytest.mark.parametrize("periods", [2, 40])
def test_a_simulation_and_a_sweep_give_scipys_file(periods):
    import gearsym
    from gearsym.solver.export import document

    system = gearsym.load("reference-light", **{"lambda": 0.8})
    run = gearsym.simulate(system, transient=2, periods=periods)
    _same_as_scipy({"result": document(run)})
    sweep = gearsym.sweep(system, "lambda", [0.2, 0.5, 0.8], transient=20, periods=periods)
    _same_as_scipy({"result": document(sweep)})


def test_an_integer_past_int64_is_written_as_a_double():
    """savemat cannot write 2**70 at all (TypeError): a result holding one (a seed, say)
    would lose its whole .mat; it is written as the nearest double."""
    got = loadmat(io.BytesIO(mat_bytes({"result": {"big": 2**70, "small": -(2**64)}})))
    assert float(got["result"]["big"][0, 0][0, 0]) == float(2**70)
    assert float(got["result"]["small"][0, 0][0, 0]) == float(-(2**64))
