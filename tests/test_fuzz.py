"""A property-based fuzz test of names, paths and values (issue 23): a topology whose ids,
coordinate, name, description, folder and numbers are drawn by hypothesis goes through
derive -> import -> compile -> simulate -> map on the command line; then, as drawn, its
cached model is spoilt (emptied, cut short, replaced by text, or the digests file made a
list) and the simulation repeated, the map runs without a compiler or with one that fails,
and a frequency response runs over a drawn range and damping (down to 0).

Whatever the draw, the command ends with exit code 0, or 2 (bad input) or 3 (a run that
failed numerically) with one line that says so; no traceback; no file is created outside
``--out`` and the derivation cache; and the drawn text never runs as code (a drawn
statement would create a file, which the file check catches).

The seed is fixed (``derandomize``) and the examples bounded, so CI runs the same cases
every time: 12 draws of anything and 6 of models that can be made (some 17 s each: derive,
compile, simulate, map, respond), within CI's time; ``GEARSYM_FUZZ_EXAMPLES`` raises the
count for a longer local run.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import traceback
import warnings
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, Phase, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

EXAMPLES = int(os.environ.get("GEARSYM_FUZZ_EXAMPLES", "12"))

# Words of C, of the C host file, of the generated Python, and of Python itself.
WORDS = "int q NAN restrict n j X P DX th0 double np ca x p tau print self INFINITY main prep w0"
WORDS = WORDS.split()

plain = st.from_regex(r"[A-Za-z][A-Za-z0-9]{0,5}", fullmatch=True)
anything = st.text(max_size=12)
# Mostly names and values a model can be made of, so that most draws reach the later
# steps; the rest anything at all, which must be refused in one line.
names = st.one_of(*[plain] * 4, *[st.sampled_from(WORDS)] * 4, anything)
target = st.one_of(*[st.from_regex(r"[A-Za-z][A-Za-z0-9_-]{0,10}", fullmatch=True)] * 4, anything)
folder = st.text(min_size=1, max_size=24).filter(
    lambda s: "/" not in s and "\x00" not in s and s not in (".", "..")
)


def number(low: float, high: float):
    """A value in a gear train's range [low, high] mostly, else any float at all."""
    wild = st.floats(allow_nan=True, allow_infinity=True)
    return st.one_of(*[st.floats(min_value=low, max_value=high)] * 8, wild)


def _toml_string(value: str) -> str:
    """A TOML basic string holding ``value`` (JSON's escapes are TOML's, less DEL)."""
    return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")


def _toml_number(value: float) -> str:
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return repr(float(value))


def _topology(root: Path, draw: dict) -> str:
    text = (root / "scenes" / "topologies" / "siso.toml").read_text(encoding="utf-8")
    swaps = {
        'name = "siso"': f"name = {_toml_string(draw['name'])}",
        "description = \"Single helical pair: pinion p drives gear g (reference study's "
        'gear data)"': f"description = {_toml_string(draw['description'])}",
        'id = "p"': f"id = {_toml_string(draw['pinion'])}",
        'gear = "p"': f"gear = {_toml_string(draw['pinion'])}",
        'driver = "p"': f"driver = {_toml_string(draw['pinion'])}",
        'id = "pg"': f"id = {_toml_string(draw['mesh'])}",
        'coordinate = "u"': f"coordinate = {_toml_string(draw['coordinate'])}",
        "half_backlash_um = 50": f"half_backlash_um = {_toml_number(draw['backlash'])}",
        "torque_Nm = 500": f"torque_Nm = {_toml_number(draw['torque'])}",
        "speed_rpm = 1500": f"speed_rpm = {_toml_number(draw['speed'])}",
    }
    for old, new in swaps.items():
        assert old in text, old
        text = text.replace(old, new)
    return text


def _spoil(models: Path, how: str) -> None:
    """Spoil the derivation cache as a crash, a full disk or an editor would."""
    if how == "digest list":
        (models / "digests.json").write_text("[1, 2, 3]", encoding="utf-8")
        return
    for module in models.glob("*.py"):
        text = module.read_text(encoding="utf-8")
        spoilt = {"empty": "", "cut": text[: len(text) // 3], "text": "not python (\n"}[how]
        module.write_text(spoilt, encoding="utf-8")


def _run(argv: list[str]) -> tuple[int, str, str]:
    from gearsym.cli import main

    out, err = io.StringIO(), io.StringIO()
    # pytest holds warnings back from stderr: record them, and write each as the command
    # line would (gearsym.cli's one-line format), so that they count as stderr lines.
    with (
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
        warnings.catch_warnings(record=True) as caught,
    ):
        warnings.simplefilter("always")
        try:
            code = main(argv)
        except SystemExit as stop:
            code = stop.code
        except BaseException:  # a traceback: what the test exists to catch
            pytest.fail(f"gearsym {' '.join(argv)} raised:\n{traceback.format_exc()}")
    from gearsym.cli import _one_line_warning

    shown = "".join(_one_line_warning(w.message, w.category, w.filename, w.lineno) for w in caught)
    return code, out.getvalue(), shown + err.getvalue()


def _files(top: Path, skip: tuple[Path, ...]) -> set[Path]:
    return {p for p in top.rglob("*") if not any(p == s or s in p.parents for s in skip)}


def _check(code: int, err: str, argv: list[str]) -> None:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code in (0, 2, 3), (argv, code, err)
    assert all(ln.startswith("gearsym") for ln in lines), (argv, err)
    failures = [ln for ln in lines if ln.startswith(("gearsym: error", "gearsym: run failed"))]
    if code == 2:  # bad input: refused in one line
        assert len(failures) == 1, (argv, err)
    else:  # a run that failed numerically says so in its report; at most one line here
        assert len(failures) <= 1, (argv, err)


FUZZ = settings(
    max_examples=EXAMPLES,
    derandomize=True,
    database=None,
    deadline=None,
    phases=(Phase.explicit, Phase.generate),  # shrinking a failure can take many minutes
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
LATER_STEPS = {
    "cache": st.sampled_from(["kept", "empty", "cut", "text", "digest list"]),
    "compiler": st.sampled_from(["default", "none", "false"]),
    "omegas": st.tuples(st.floats(1e-3, 2.0), st.floats(0.05, 1.0), st.booleans()),
    "damping": st.sampled_from([0.0, 1e-4, 0.03, 1.0]),
}
# Anything at all: most draws are refused in one line at the first step.
ANY_DRAW = st.fixed_dictionaries(
    {
        "folder": folder,
        "name": target,
        "description": st.text(max_size=40),
        "pinion": names,
        "mesh": names,
        "coordinate": names,
        "backlash": number(1.0, 500.0),
        "torque": number(-5e3, 5e3),
        "speed": number(10.0, 1e4),
        **LATER_STEPS,
    }
)
# Models that can be made (any folder, words of C and Python as names): every draw goes
# through every step.
good_name = st.one_of(plain, st.sampled_from(WORDS))
MODEL_DRAW = st.fixed_dictionaries(
    {
        "folder": folder,
        "name": st.from_regex(r"[A-Za-z][A-Za-z0-9_-]{0,10}", fullmatch=True),
        "description": st.text(max_size=40),
        "pinion": good_name,
        "mesh": good_name,
        "coordinate": good_name,
        "backlash": st.floats(1.0, 500.0),
        "torque": st.floats(10.0, 5e3),
        "speed": st.floats(100.0, 1e4),
        **LATER_STEPS,
    }
)


@pytest.mark.slow
@FUZZ
@given(draw=ANY_DRAW)
def test_no_draw_ends_in_a_traceback_or_a_stray_file(draw, root, tmp_path_factory, monkeypatch):
    _pipeline(draw, root, tmp_path_factory, monkeypatch)


@pytest.mark.slow
@settings(FUZZ, max_examples=max(1, EXAMPLES // 2))
@given(draw=MODEL_DRAW)
def test_every_step_of_a_model_that_can_be_made(draw, root, tmp_path_factory, monkeypatch):
    _pipeline(draw, root, tmp_path_factory, monkeypatch)


def _pipeline(draw, root, tmp_path_factory, monkeypatch) -> None:
    base = tmp_path_factory.mktemp("fuzz")
    cache, out, work = base / "cache", base / "out", base / "work"
    work.mkdir()
    monkeypatch.setenv("GEARSYM_CACHE", str(cache))
    monkeypatch.chdir(work)
    where = base / draw["folder"]
    where.mkdir(parents=True, exist_ok=True)
    path = where / "topology.toml"
    path.write_text(_topology(root, draw), encoding="utf-8")
    before = _files(base, (cache, out))

    short = ["--periods", "2", "--transient", "1", "--lyapunov-periods", "0"]
    argv = ["simulate", str(path), "--method", "dop853", *short, "--json"]
    code, stdout, err = _run(argv)
    _check(code, err, argv)
    hypothesis.event(f"simulate exit {code}: {err.strip()[:150]}")
    if code == 0:
        json.loads(stdout, parse_constant=lambda c: pytest.fail(f"{c} in --json"))
        if draw["cache"] != "kept":  # a spoilt cache: derived again, one warning
            _spoil(cache / "models", draw["cache"])
            code, _, err = _run(argv)
            _check(code, err, argv)
            warned = [ln for ln in err.splitlines() if not ln.startswith("gearsym: note:")]
            assert code == 0 and len(warned) <= 1, err
        from gearsym.solver.integrate import native

        if draw["compiler"] != "default":
            monkeypatch.setenv("GEARSYM_CC", draw["compiler"])
        native.reset()
        grid = ["--x", "omega=0.4:0.6:2", "--y", "damping_ratio=0.02:0.04:2"]
        argv = ["map", str(path), *grid, "--initial-states", "1", *short, "--quiet"]
        argv += ["--out", str(out / "map")]
        code, _, err = _run(argv)
        _check(code, err, argv)
        hypothesis.event(f"map exit {code}")
        monkeypatch.delenv("GEARSYM_CC", raising=False)
        native.reset()
        low, width, down = draw["omegas"]
        a, b = (low + width, low) if down else (low, low + width)
        argv = ["frequency-response", str(path), "--param", f"omega={a!r}:{b!r}:8"]
        argv += ["--set", f"damping_ratio={draw['damping']!r}", "--harmonics", "2"]
        argv += ["--no-figure", "--out", str(out / "response")]
        code, _, err = _run(argv)
        _check(code, err, argv)
        hypothesis.event(f"frequency-response exit {code}: {err.strip()[-90:]}")
    assert _files(base, (cache, out)) == before, "a file outside --out and the cache"
