"""``gearsym derive`` of four or more targets derives them in worker processes
(``derive/build.py``): the files must be those one process writes, byte for byte, and a
target that cannot be derived must fail as it does in one process (its one line)."""

from __future__ import annotations

import pytest
from gearsym.derive.build import build_files, shipped_targets
from gearsym.derive.input.reader import InputError

SMALL = ("siso", "ring-pinion", "reference-linear", "diso")


def _targets():
    found = [p for p in shipped_targets() if p.stem in SMALL]
    assert len(found) == len(SMALL)
    return found


def test_workers_write_what_one_process_writes(monkeypatch):
    import gearsym.derive.build as build

    made = []
    real = build._pool
    monkeypatch.setattr(build, "_pool", lambda jobs: made.append(real(jobs)) or made[-1])
    monkeypatch.setenv("GEARSYM_DERIVE_WORKERS", "2")
    together = build_files(_targets())
    assert made[-1] is not None  # derived by workers
    monkeypatch.setenv("GEARSYM_DERIVE_WORKERS", "1")
    alone = build_files(_targets())
    assert made[-1] is None  # in this process
    assert list(together.files) == list(alone.files)  # the same files in the same order
    assert together.files == alone.files
    assert [m.name for m in together.models] == [m.name for m in alone.models]


def test_a_target_a_worker_cannot_derive_fails_in_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARSYM_DERIVE_WORKERS", "2")
    bad = tmp_path / "bad.toml"
    bad.write_text('[topology]\nname = "bad"\n', encoding="utf-8")
    with pytest.raises(InputError, match="bad.toml: gear: is required") as err:
        build_files([*_targets(), bad])
    assert "\n" not in str(err.value)
