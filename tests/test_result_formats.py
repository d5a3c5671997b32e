"""One result format from every command (issue 25, point 5).

Every command that writes a result writes it as JSON, CSV and MATLAB ``.mat``; a reader
without our code (``scipy.io.loadmat``, the ``csv`` module) finds in the ``.mat`` the same
keys and values as in the JSON, and in the CSV the same header block and the table that
the ``.mat`` carries beside it, whose key column is the JSON's.  The reference values are
the JSON file's own: the files must agree with each other, not with a computed number.
"""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from gearsym.cli import main
from gearsym.solver.export import _field
from scipy.io import loadmat

HEADER = ("gearsym_version", "model", "model_hash", "scales", "overrides", "command")
SHORT = ["--transient", "20", "--periods", "20", "--budget", "0", "--lyapunov-periods", "10"]

# command, its files' stem, its arguments (small and short: the whole file runs in about
# 30 s), and per command the JSON list that the CSV's first key column repeats
COMMANDS = {
    "simulate": ("point", ["simulate", "reference-linear", *SHORT]),
    "sweep": (
        "sweep",
        ["sweep", "reference-linear", "--param", "omega", "--range", "0.5:0.6:3"]
        + ["--executor", "serial", "--no-figure", "--quiet", *SHORT],
    ),
    "map": (
        "map",
        ["map", "reference-linear", "--x", "omega=0.5:0.6:2", "--y", "lambda=0.1:0.2:2"]
        + ["--initial-states", "2", "--executor", "serial", "--quiet", *SHORT],
    ),
    "shoot": ("orbit", ["shoot", "reference-linear", "--settle", "50"]),
    "continue": (
        "branches",
        ["continue", "reference-linear", "--param", "omega", "--from", "0.5", "--to", "0.55"]
        + ["--step", "0.02", "--settle", "50"],
    ),
    "frequency-response": (
        "frequency_response",
        ["frequency-response", "reference-linear", "--param=omega=0.5:0.6:5", "--no-figure"],
    ),
    "modes": ("modes", ["modes", "reference-linear"]),
}


def key_column(command: str, doc: dict) -> tuple[str, list]:
    """The CSV column that repeats a list of the JSON, and that list."""
    if command == "simulate":
        return "tau", doc["samples"]["t"]
    if command == "sweep":
        return doc["parameter"], doc["values"]
    if command == "map":
        return "share", [r["share"] for r in doc["records"]]
    if command == "shoot":
        return "abs", [math.hypot(m["re"], m["im"]) for m in doc["floquet"]["multipliers"]]
    if command == "modes":
        return "frequency_hz", [m["frequency_hz"] for m in doc["modes"]]
    if command == "continue":
        return doc["parameter"], [v for b in doc["branches"] for v in b["values"]]
    return doc["parameter"], [r[doc["parameter"]] for r in doc["records"]]


def close(a: float, b: float) -> bool:
    return a == b or abs(a - b) <= 1e-12 * max(1.0, abs(a), abs(b))


def same(j, m, where: str = "") -> None:
    """Assert the .mat value ``m`` (loadmat, simplify_cells) holds the JSON value ``j``."""
    if isinstance(j, dict):
        if not j:
            assert np.size(m) == 0 or m == {}, where
            return
        assert isinstance(m, dict), f"{where}: {type(m)}"
        assert {_field(k) for k in j} == set(m), where
        for k, v in j.items():
            same(v, m[_field(k)], f"{where}.{k}")
    elif isinstance(j, list):
        if not j:
            assert np.size(m) == 0, where
        elif all(isinstance(v, int | float) or v is None for v in j):
            got = np.atleast_1d(np.asarray(m, dtype=float)).ravel()
            assert got.size == len(j), where
            for k, v in enumerate(j):
                same(v, got[k], f"{where}[{k}]")
        elif (
            all(isinstance(r, list) and r for r in j)
            and len({len(r) for r in j}) == 1
            and all(isinstance(v, int | float) or v is None for r in j for v in r)
        ):
            got = np.reshape(np.asarray(m, dtype=float), (len(j), len(j[0])))
            for k, r in enumerate(j):
                same(r, list(got[k]), f"{where}[{k}]")
        else:
            got = [m] if len(j) == 1 and not isinstance(m, list | np.ndarray) else list(m)
            assert len(got) == len(j), where
            for k, v in enumerate(j):
                same(v, got[k], f"{where}[{k}]")
    elif isinstance(j, str):
        assert (m if isinstance(m, str) else "".join(np.ravel(m))) == j, where
    elif j is None:
        assert math.isnan(float(m)), where
    elif isinstance(j, bool):  # numeric booleans: double 0/1
        assert np.asarray(m).dtype == float and float(m) == float(j), where
    else:
        assert close(float(j), float(m)), f"{where}: {j} != {m}"


def read_csv(path) -> tuple[dict, list[str], list[list[str]]]:
    """The ``# key: value`` header block (values in JSON), the columns and the rows."""
    header, lines = {}, []
    with open(path, newline="", encoding="utf-8") as fh:
        for line in fh:
            if line.startswith("#"):
                key, _, value = line[1:].partition(":")
                header[key.strip()] = json.loads(value)
            else:
                lines.append(line)
    columns, *rows = list(csv.reader(lines))
    return header, columns, rows


def csv_same(text: str, m, where: str) -> None:
    """A CSV cell against the .mat table's entry: empty is missing (NaN)."""
    if isinstance(m, str):
        assert text == m, where
    elif text == "":
        assert math.isnan(float(m)), where
    else:
        assert close(float(text), float(m)), f"{where}: {text} != {m}"


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_command_writes_the_same_keys_and_values_in_json_csv_and_mat(
    command, tmp_path, capsys
):
    stem, argv = COMMANDS[command]
    code = main([*argv, "--out", str(tmp_path)])
    capsys.readouterr()
    assert code == 0
    doc = json.loads((tmp_path / f"{stem}.json").read_text(encoding="utf-8"))
    mat = loadmat(tmp_path / f"{stem}.mat", simplify_cells=True)
    header, columns, rows = read_csv(tmp_path / f"{stem}.csv")

    for key in HEADER:  # the header block, in all three
        assert key in doc and key in mat["result"] and key in header, key
    assert doc["command"].startswith(f"gearsym {argv[0]} ")
    assert set(header) <= set(doc)
    for key, value in header.items():
        assert value == doc[key], key
    same(doc, mat["result"], stem)

    # the CSV is the .mat's table, column for column, booleans as 1/0
    table = mat["table"]
    assert [_field(c) for c in columns] == list(table)
    assert rows, "an empty table shows nothing"
    for c in columns:
        got = table[_field(c)]
        got = [got] if len(rows) == 1 else list(got)
        assert len(got) == len(rows), c
        for k, row in enumerate(rows):
            cell = row[columns.index(c)]
            assert cell not in ("True", "False"), c
            csv_same(cell, got[k], f"{c}[{k}]")
    # and its key column is the JSON's
    name, values = key_column(command, doc)
    assert len(values) == len(rows), name
    for k, v in enumerate(values):
        assert close(float(rows[k][columns.index(name)]), v), (name, k)


def test_text_is_a_cell_array_and_booleans_numbers_in_the_mat(tmp_path, capsys):
    # A .mat written from a branch: 'stable' as double 0/1 and 'stability' as a cell array
    # of strings (scipy loads a cell array as an object array; a char matrix as str).
    code = main([*COMMANDS["continue"][1], "--out", str(tmp_path), "--format", "mat"])
    capsys.readouterr()
    data = [p.name for p in tmp_path.glob("branches.*") if p.suffix in (".json", ".csv", ".mat")]
    assert code == 0 and data == ["branches.mat"]
    branch = loadmat(tmp_path / "branches.mat", squeeze_me=True)["result"]["branches"].item()
    branch = branch[0] if branch.dtype == object else branch
    assert branch["stable"].item().dtype == float
    stability = branch["stability"].item()
    assert stability.dtype == object and all(isinstance(s, str) for s in stability)


def test_an_unknown_format_is_refused_in_one_line(tmp_path, capsys):
    code = main([*COMMANDS["shoot"][1], "--out", str(tmp_path), "--format", "json,xlsx"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--format json,xlsx: 'xlsx'" in err, err


def test_long_arrays_are_written_in_blocks_as_the_same_text(tmp_path):
    """A long run's samples are written block by block (bounded memory, tests/test_memory.py):
    the JSON must be the text of ``dumps`` on the whole (the reference: the unstreamed
    writer), non-finite numbers null in JSON, empty in CSV and NaN in the .mat."""
    from gearsym.solver import export
    from gearsym.solver._json import dumps

    t = np.linspace(0.0, 1.0, 3 * export._BLOCK + 5)
    x = np.sin(t)
    x[7], x[export._BLOCK + 1] = np.nan, np.inf
    doc = export.Document(
        {"model": "m", "samples": {"t": t, "x": x}}, ["tau", "x"], np.column_stack([t, x])
    )
    for suffix in (".json", ".csv", ".mat"):
        export.save(doc, tmp_path / f"a{suffix}")
    assert (tmp_path / "a.json").read_text(encoding="utf-8") == dumps(doc.to_dict())
    header, columns, rows = read_csv(tmp_path / "a.csv")
    assert header == {"model": "m"} and columns == ["tau", "x"] and len(rows) == t.size
    assert rows[7][1] == "" and rows[export._BLOCK + 1][1] == ""
    assert [float(r[1]) for r in rows[-3:]] == x[-3:].tolist()
    mat = loadmat(tmp_path / "a.mat", simplify_cells=True)
    for got in (mat["table"]["x"], mat["result"]["samples"]["x"]):
        assert np.isnan(got[7]) and np.isinf(got[export._BLOCK + 1])
        assert np.allclose(got[export._BLOCK + 2 :], x[export._BLOCK + 2 :], rtol=0, atol=0)


def test_a_table_of_plain_numbers_is_the_text_csv_writer_writes(tmp_path):
    """Rows of finite floats and ints take the fast path (``repr`` joined by commas); the
    reference is the standard library's ``csv.writer`` on the same rows, with blocks that
    fall back to it (a NaN, a bool, a NumPy scalar, a text) mixed in."""
    import io

    from gearsym.solver import export

    rng = np.random.default_rng(7)
    rows = [
        [float(v), i, -0.0, 1e-300 * v, *rng.standard_normal(5).tolist(), 10**20 + i]
        for i, v in enumerate(rng.standard_normal(2 * export._BLOCK + 3).tolist())
    ]
    odd = [list(r) for r in rows[:4]]
    odd[0][2], odd[1][1], odd[2][3], odd[3][4] = math.nan, True, np.float64(2.5), "a,b"
    columns = ["p", "point", "z", "tiny", *"abcde", "big"]
    # rows that can be read once, and rows that are not lists
    once = [iter(r) for r in rows[:5]] + [range(3), (1.5, 2)]
    tables = [(t, t) for t in (rows, odd, rows[:3] + odd + rows[3:])]
    for table, same in [*tables, (once, [*rows[:5], [0, 1, 2], [1.5, 2]])]:
        export.save_csv(tmp_path / "t.csv", {}, columns, table)
        expected = io.StringIO()
        writer = csv.writer(expected, lineterminator="\n")
        writer.writerow(columns)
        writer.writerows([export._cell(v) for v in r] for r in same)
        assert (tmp_path / "t.csv").read_text(encoding="utf-8") == expected.getvalue()
    assert export._plain(rows) and not any(export._plain([r]) for r in odd)


def test_a_trajectory_file_carries_the_header_block(tmp_path):
    import gearsym

    tr = gearsym.simulate(gearsym.load("reference-linear"), transient=5, periods=3)
    for suffix in (".json", ".csv", ".mat"):
        tr.save(tmp_path / f"run{suffix}", command="a test")
    doc = json.loads((tmp_path / "run.json").read_text(encoding="utf-8"))
    header, columns, rows = read_csv(tmp_path / "run.csv")
    for key in HEADER:
        assert key in doc and header[key] == doc[key], key
    assert doc["model_hash"] == tr.system.model_hash and columns[0] == "tau"
    assert len(rows) == len(doc["t"]) == tr.t.size
    same(doc, loadmat(tmp_path / "run.mat", simplify_cells=True)["result"], "run")


def test_a_sweeps_poincare_points_are_a_csv_table_of_the_jsons_values(tmp_path, capsys):
    # the bifurcation diagram's data for pandas or MATLAB: one row per point and sampled
    # period; the reference is the JSON's own points[i].poincare (files agree)
    code = main([*COMMANDS["sweep"][1], "--out", str(tmp_path)])
    capsys.readouterr()
    assert code == 0
    doc = json.loads((tmp_path / "sweep.json").read_text(encoding="utf-8"))
    header, columns, rows = read_csv(tmp_path / "sweep_poincare.csv")
    assert {k: header[k] for k in HEADER} == {k: doc[k] for k in HEADER}
    states = list(doc["points"][0]["poincare"])
    assert columns == [doc["parameter"], "point", "period", *states]
    want = [
        (i, k, point["values"][doc["parameter"]], [point["poincare"][s][k] for s in states])
        for i, point in enumerate(doc["points"])
        for k in range(len(point["poincare"][states[0]]))
    ]
    assert len(rows) == len(want) == 3 * 20
    for row, (i, k, value, xs) in zip(rows, want, strict=True):
        assert (int(row[1]), int(row[2])) == (i, k) and close(float(row[0]), value)
        assert all(close(float(a), b) for a, b in zip(row[3:], xs, strict=True)), (i, k)
