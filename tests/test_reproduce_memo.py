"""The result store of ``gearsym reproduce`` (issue 25, point 7): a unit computed once is
loaded by a run with the same code and inputs into another folder, with its files; any
change of an input, ``fresh`` or a damaged entry computes it again."""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from gearsym.solver.system import System
from gearsym.studies.memo import ResultStore, canonical

CALLS = []  # units computed in this process (the serial executor runs them here)


@dataclass(frozen=True)
class Drawn:
    value: float
    figure: Path


def _unit(task):
    """A unit that writes a file under the output folder and returns its path."""
    out, name, value = task
    CALLS.append(task)
    path = out / "figures" / f"{name}.txt"  # figures/ made by the caller, as reproduce's data/
    path.write_text(f"{name} = {value!r}\n")
    return Drawn(2 * value, path)


def _run(store, out, tasks):
    (out / "figures").mkdir(parents=True, exist_ok=True)
    return store.map(_unit, [(out, n, v) for n, v in tasks], executor="serial", workers=None)


def test_a_repeated_run_into_another_folder_loads_results_and_files(tmp_path):
    CALLS.clear()
    tasks = [("a", 1.5), ("b", np.float64(-0.25))]
    first = ResultStore(tmp_path / "cache", tmp_path / "one")
    got = _run(first, tmp_path / "one", tasks)
    assert (first.loaded, first.computed, len(CALLS)) == (0, 2, 2)
    assert got[0] == Drawn(3.0, tmp_path / "one" / "figures" / "a.txt")
    assert not (tmp_path / "one" / ".units").exists()  # each unit's own folder removed

    again = ResultStore(tmp_path / "cache", tmp_path / "two")
    loaded = _run(again, tmp_path / "two", tasks)
    assert (again.loaded, again.computed, len(CALLS)) == (2, 0, 2)  # nothing run again
    assert loaded[1] == Drawn(-0.5, tmp_path / "two" / "figures" / "b.txt")
    for name in ("a", "b"):  # the files too, byte for byte, in the new folder
        one = (tmp_path / "one" / "figures" / f"{name}.txt").read_bytes()
        assert (tmp_path / "two" / "figures" / f"{name}.txt").read_bytes() == one
    assert "2 of 2 units of work loaded" in again.summary()


def test_another_value_fresh_or_a_damaged_entry_computes_again(tmp_path):
    CALLS.clear()
    cache, out = tmp_path / "cache", tmp_path / "out"
    _run(ResultStore(cache, out), out, [("a", 1.0)])
    other = ResultStore(cache, out)
    _run(other, out, [("a", 1.0 + 1e-15)])  # the last bit of an input is an input
    assert (other.loaded, other.computed) == (0, 1)
    fresh = ResultStore(cache, out, fresh=True)
    _run(fresh, out, [("a", 1.0)])
    assert (fresh.loaded, fresh.computed) == (0, 1)
    assert "computed (--fresh)" in fresh.summary()
    for entry in cache.rglob("*.pickle"):
        data = bytearray(entry.read_bytes())
        data[-1] ^= 1
        entry.write_bytes(bytes(data))
    damaged = ResultStore(cache, out)
    got = _run(damaged, out, [("a", 1.0)])
    assert (damaged.loaded, damaged.computed) == (0, 1)
    assert got[0].value == 2.0
    assert len(CALLS) == 4


def test_a_model_is_keyed_by_its_module_bytes_and_values(tmp_path):
    light = System.load("reference_light")
    key = canonical(light, tmp_path)
    assert canonical(System.load("reference_light"), tmp_path / "elsewhere") == key
    assert canonical(light.with_values(f1=0.2), tmp_path) != key
    assert canonical(System.load("reference_heavy"), tmp_path) != key


def test_an_argument_it_cannot_key_is_computed_every_time(tmp_path):
    CALLS.clear()
    store = ResultStore(tmp_path / "cache", tmp_path)
    (tmp_path / "figures").mkdir()
    task = (tmp_path, "a", 1.0, object())
    assert store.key(_unit, task) is None
    store.map(lambda t: _unit(t[:3]), [task, task], executor="serial", workers=None)
    assert (store.loaded, store.computed, len(CALLS)) == (0, 2, 2)
    assert not list((tmp_path / "cache").rglob("*.pickle"))


def test_the_stores_of_older_sources_are_removed_beyond_the_newest(tmp_path, monkeypatch):
    import os

    from gearsym.studies import memo

    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path))
    root = tmp_path / "results"
    for k in range(5):  # stores of five older sources, the oldest first
        (root / f"old{k}").mkdir(parents=True)
        (root / f"old{k}" / "entry.pickle").write_bytes(b"x")
        os.utime(root / f"old{k}", (1000 + k, 1000 + k))
    store = memo.ResultStore.in_cache(tmp_path / "out")
    assert store.root == root / memo.source_hash()[:16]
    kept = sorted(d.name for d in root.iterdir())
    assert kept == sorted([store.root.name] + [f"old{k}" for k in range(5 - memo.KEEP + 1, 5)])


def test_the_key_tells_apart_what_differs_and_ignores_a_dicts_order(tmp_path):
    """Rows of one plain type are keyed in one go (a reproduce's tasks carry thousands of
    them): still a float from an int, a list from a tuple, a text from a number, -0.0 from
    0.0 and NaN from a number; a dict's insertion order does not change its key."""
    forms = [
        [1.0, 2.0],
        [1, 2],
        (1.0, 2.0),
        ["1.0", "2.0"],
        [1.0, 2.0, 3.0],
        [-0.0, 2.0],
        [0.0, 2.0],
        [float("nan"), 2.0],
        [1.0, 2],  # mixed: element by element
        [True, 2],
    ]
    keys = [canonical(f, tmp_path) for f in forms]
    assert len(set(keys)) == len(forms)
    a = {"x": [1.0], "y": {"p": 1, "q": (2.0,)}}
    b = {"y": {"q": (2.0,), "p": 1}, "x": [1.0]}
    assert canonical(a, tmp_path) == canonical(b, tmp_path)
    assert canonical(a, tmp_path) != canonical({**a, "x": [1.5]}, tmp_path)


def test_the_source_hash_covers_the_engine_s_c(monkeypatch):
    """A change to an integrator's C (native_*.c, monodromy.c) changes results as much
    as one to its Python: the stored results' key reads those files too."""
    from gearsym.studies import memo

    read = []
    real = memo._sha256_file
    monkeypatch.setattr(memo, "_sha256_file", lambda f: read.append(f.name) or real(f))
    monkeypatch.setattr(memo, "_source", [])
    memo.source_hash()
    assert {"native_1_job.c", "native_2_step.c", "native_3_loop.c", "monodromy.c"} <= set(read)
