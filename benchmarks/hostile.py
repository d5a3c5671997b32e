"""The hostile-input probe: the classes of issue 23 run as a user would run them, each as
its own process with a time limit, counting what goes wrong.

A case goes wrong when it ends in a Python traceback, runs past its time limit, prints a
refusal of more than one line, leaves a file it was not asked for (a statement hidden in a
path or name that ran), or prints JSON that is not strict (NaN, Infinity).  The probe is
the same for any checkout, so it measures a change: ``python benchmarks/hostile.py``
prints the table; :func:`rows` gives it to ``benchmarks/robustness.py``, which writes it
into ``docs/robustness.md``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

LIMIT_S = 90.0  # per case: every case finishes in seconds when it is handled
SHORT = ["--periods", "2", "--transient", "1", "--lyapunov-periods", "0"]
GRID = ["--x", "omega=0.4:0.6:2", "--y", "damping_ratio=0.02:0.04:2", "--quiet"]
WORDS = ["int", "q", "n", "j", "double", "restrict", "NAN", "INFINITY", "X", "P", "DX", "th0"]


@dataclass(frozen=True)
class Case:
    cls: str  # the class of issue 23 it belongs to
    label: str
    argv: tuple[str, ...]
    env: tuple[tuple[str, str], ...] = ()
    pipe_closed: bool = False  # stdout's reader leaves after the first line


def _siso(root: Path) -> str:
    return (root / "scenes" / "topologies" / "siso.toml").read_text(encoding="utf-8")


def _files(root: Path, tmp: Path) -> dict[str, str]:
    """The files the cases name (placeholders ``{key}``)."""
    files: dict[str, str] = {}
    scene = (root / "scenes" / "reference-light.toml").read_text(encoding="utf-8")
    scene = scene.replace('topology = "topologies/diso.toml"', 'topology = "diso"')
    for key, folder in {
        "newline": 'a\nimport pathlib; pathlib.Path("PWNED").touch()\nb',
        "quotes": 'q"""\nimport pathlib; pathlib.Path("PWNED").touch()\n"""',
    }.items():
        (tmp / folder).mkdir()
        path = tmp / folder / "scene.toml"
        path.write_text(scene.replace('name = "reference-light"', f'name = "h{key}"'), "utf-8")
        files[f"scene_{key}"] = str(path)

    def topology(key: str, *edits: tuple[str, str]) -> None:
        text = _siso(root).replace('name = "siso"', f'name = "h-{key}"')
        for old, new in edits:
            assert old in text, old
            text = text.replace(old, new)
        path = tmp / f"{key}.toml"
        path.write_text(text, encoding="utf-8")
        files[f"topo_{key}"] = str(path)

    for word in WORDS:
        topology(f"w{word}", ('coordinate = "u"', f'coordinate = "{word}"'))
    topology("coord_newline", ('coordinate = "u"', 'coordinate = "u\\n"'))
    topology("mesh_newline", ('id = "pg"', 'id = "pg\\n"'))
    topology("desc_quotes", ("description = ", 'description = "x\\"\\"\\"\\nimport os" #'))
    topology("shape_mesh_table", ("[[mesh]]", "[mesh]"))
    topology("deep", ("[topology]", "deep = " + "[" * 2000 + "]" * 2000 + "\n[topology]"))
    topology("tiny_inertia", ('id = "p"\n', 'id = "p"\ninertia_kg_m2 = 1e-320\n'))
    topology(
        "young",
        (
            "[[gear]]",
            "[materials.steel]\nyoungs_modulus_Pa = 1e200\npoisson_ratio = 0.3\n"
            "density_kg_m3 = 7850\n[[gear]]",
        ),
    )
    for key, (old, new) in {
        "topology_number": ('topology = "diso"', "topology = 5"),
        "features_list": ("[features]", "features = [1, 2]\n[unused]"),
        "parameters_text": ("[parameters]", 'parameters = "all"\n[unused2]'),
    }.items():
        path = tmp / f"scene-{key}.toml"
        path.write_text(scene.replace(old, new), encoding="utf-8")
        files[f"scene_{key}"] = str(path)
    arr = tmp / "array.toml"
    arr.write_text("scene = [1, 2, 3]\n", encoding="utf-8")
    files["scene_array"] = str(arr)
    return files


def cases() -> list[Case]:
    S = ("simulate",)
    out: list[Case] = [
        Case(
            "code from text",
            "scene in a folder named with a newline and code",
            (*S, "{scene_newline}", *SHORT),
        ),
        Case(
            "code from text",
            "scene in a folder named with triple quotes",
            (*S, "{scene_quotes}", *SHORT),
        ),
        Case(
            "code from text",
            "mesh coordinate ending in a newline",
            (*S, "{topo_coord_newline}", *SHORT),
        ),
        Case("code from text", "mesh id ending in a newline", (*S, "{topo_mesh_newline}", *SHORT)),
        Case(
            "code from text", "description with triple quotes", (*S, "{topo_desc_quotes}", *SHORT)
        ),
    ]
    for word in WORDS:
        out.append(
            Case(
                "C identifiers",
                f"coordinate '{word}', compiled simulate",
                (*S, f"{{topo_w{word}}}", "--method", "dop853", *SHORT),
            )
        )
    out += [
        Case(
            "C identifiers",
            "coordinate 'restrict', map",
            ("map", "{topo_wrestrict}", *GRID, *SHORT),
        ),
        Case("cache", "empty cached module", (*S, "{topo_wint}", *SHORT), (("CORRUPT", "empty"),)),
        Case(
            "cache", "cut-short cached module", (*S, "{topo_wint}", *SHORT), (("CORRUPT", "cut"),)
        ),
        Case(
            "cache", "cached module not Python", (*S, "{topo_wint}", *SHORT), (("CORRUPT", "text"),)
        ),
        Case(
            "cache",
            "digest file a list",
            (*S, "{topo_wint}", *SHORT),
            (("CORRUPT", "digest-list"),),
        ),
        Case("file shape", "scene with topology = 5", (*S, "{scene_topology_number}")),
        Case("file shape", "a list where a table is expected", (*S, "{scene_features_list}")),
        Case("file shape", "a string where a table is expected", (*S, "{scene_parameters_text}")),
        Case(
            "file shape",
            "a table where an array of tables is expected",
            (*S, "{topo_shape_mesh_table}"),
        ),
        Case("file shape", "2000 nested arrays", (*S, "{topo_deep}")),
        Case("file shape", "a scene that is an array", (*S, "{scene_array}")),
        Case(
            "no compiler",
            "map with GEARSYM_CC=none",
            ("map", "reference-light", *GRID, *SHORT),
            (("GEARSYM_CC", "none"),),
        ),
        Case(
            "no compiler",
            "map with a compiler that fails",
            ("map", "reference-light", *GRID, *SHORT),
            (("GEARSYM_CC", "false"),),
        ),
        Case(
            "continuation",
            "frequency response with damping 0",
            (
                "frequency-response",
                "reference-light",
                "--set",
                "damping_ratio=0",
                "--param",
                "omega=0.05:2:40",
                "--harmonics",
                "3",
            ),
        ),
        Case(
            "continuation",
            "frequency response over a wide range on the dead zone",
            (
                "frequency-response",
                "reference-dead-zone",
                "--param",
                "omega=0.05:3:50",
                "--harmonics",
                "5",
            ),
        ),
        Case(
            "continuation",
            "--param damping_ratio",
            (
                "frequency-response",
                "reference-light",
                "--param",
                "damping_ratio=0.05:0.02:5",
                "--harmonics",
                "3",
            ),
        ),
        Case(
            "continuation",
            "--param lambda=0:1:5",
            (
                "frequency-response",
                "reference-light",
                "--param",
                "lambda=0:1:5",
                "--harmonics",
                "3",
            ),
        ),
        Case(
            "strict JSON",
            "modes of a gear with a tiny inertia",
            ("modes", "{topo_tiny_inertia}", "--json"),
        ),
        Case(
            "strict JSON",
            "stiffness with an absurd Young's modulus",
            ("stiffness", "{topo_young}", "--json"),
        ),
        Case(
            "bounded work",
            "shoot --period 100000",
            ("shoot", "reference-light", "--period", "100000"),
        ),
        Case(
            "bounded work",
            "continue --step 1e300",
            (
                "continue",
                "reference-light",
                "--param",
                "lambda",
                "--from",
                "0.1",
                "--to",
                "0.2",
                "--step",
                "1e300",
            ),
        ),
        Case(
            "Unix manners",
            "simulate --json, its reader gone",
            ("simulate", "reference-light", *SHORT, "--json"),
            pipe_closed=True,
        ),
    ]
    return out


def _corrupt(how: str, cache: Path) -> None:
    """Spoil the derivation cache of a model derived before (the ``CORRUPT`` cases)."""
    models = cache / "models"
    module = next(p for p in sorted(models.glob("h_wint_*.py")))
    if how == "empty":
        module.write_text("", encoding="utf-8")
    elif how == "cut":
        module.write_text(module.read_text(encoding="utf-8")[:500], encoding="utf-8")
    elif how == "text":
        module.write_text("this is not python (\n", encoding="utf-8")
    elif how == "digest-list":
        (models / "digests.json").write_text(json.dumps([1, 2, 3]), encoding="utf-8")


def _run(case: Case, files: dict, cache: Path, work: Path) -> dict:
    argv = [a.format(**files) if "{" in a else a for a in case.argv]
    env = {**os.environ, "GEARSYM_CACHE": str(cache), **dict(case.env)}
    corrupt = env.pop("CORRUPT", None)
    if corrupt:  # a spoilt copy of the cache, so that the cases after it find it whole
        spoilt = cache.with_name(f"{cache.name}-{corrupt}")
        shutil.copytree(cache, spoilt)
        _corrupt(corrupt, spoilt)
        env["GEARSYM_CACHE"] = str(spoilt)
    started = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "gearsym.cli", *argv],
        cwd=work,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        errors="replace",
    )
    timed_out = False
    try:
        if case.pipe_closed:  # the reader is gone before the first line
            proc.stdout.close()
            err = proc.stderr.read()
            proc.wait(timeout=LIMIT_S)
            out = ""
        else:
            out, err = proc.communicate(timeout=LIMIT_S)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        timed_out = True
    lines = [ln for ln in err.splitlines() if ln.strip()]
    strict = True
    if "--json" in argv and proc.returncode == 0 and not case.pipe_closed:
        try:
            json.loads(out, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
        except ValueError:
            strict = False
    problems = []
    if timed_out:
        problems.append(f"ran past {LIMIT_S:.0f} s")
    if "Traceback" in err:
        problems.append("traceback")
    if proc.returncode == 2 and len(lines) != 1:
        problems.append(f"refusal of {len(lines)} lines")
    if not strict:
        problems.append("not strict JSON")
    if case.pipe_closed and lines:
        problems.append("spoke after its reader left")
    if case.cls == "C identifiers" and lines:  # a valid model: compiled, nothing to say
        problems.append("the C did not compile: " + lines[0][:60])
    if list(work.parent.rglob("PWNED")):
        problems.append("text ran as code")
    last = lines[-1] if lines else ""
    return {
        "class": case.cls,
        "case": case.label,
        "exit": "timeout" if timed_out else proc.returncode,
        "seconds": time.perf_counter() - started,
        "problems": problems,
        "stderr": last.replace(str(work.parent), "TMP")[:160],
    }


def rows(root: Path | None = None) -> list[dict]:
    """Every case's outcome, run in a fresh temporary folder and cache."""
    from gearsym.derive.build import project_root

    root = Path(root or project_root())
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        work, cache = tmp / "work", tmp / "cache"
        work.mkdir()
        (tmp / "files").mkdir()
        files = _files(root, tmp / "files")
        return [_run(case, files, cache, work) for case in cases()]


def main() -> None:
    table = rows()
    for r in table:
        print(
            f"{r['class']:<16} {r['case'][:48]:<48} exit {r['exit']!s:<7} "
            f"{r['seconds']:6.1f} s  {', '.join(r['problems']) or 'ok'}"
        )
    bad = [r for r in table if r["problems"]]
    tracebacks = sum("traceback" in r["problems"] for r in table)
    print(f"{len(table)} cases: {len(bad)} went wrong, {tracebacks} with a traceback")


if __name__ == "__main__":
    main()
