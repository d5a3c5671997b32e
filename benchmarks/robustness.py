"""Write docs/robustness.md: the extremes matrix (every case with every back end).

Run from a checkout (it writes the checkout's ``docs/`` and lists the bad-input cases of
its ``tests/``): ``python -m gearsym.benchmarks.robustness`` or
``python benchmarks/robustness.py``.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from gearsym.benchmarks._output import checkout_docs, output_folder, run_script
from gearsym.derive.build import project_root
from gearsym.solver.integrate import METHODS
from gearsym.studies.robustness import CASES, describe, harmonics_models, matrix

REPORT = "robustness.md"


def _bad_input_cases() -> list[tuple[str, str]]:
    """The bad-input cases of the test suite (the checkout's tests/), by label and
    expected message."""
    import sys

    sys.path.insert(0, str(project_root()))
    from tests.derive import test_input_errors as t
    from tests.solver import test_cli_solver as c

    cases = [(f"topology: {w}", e) for w, _, _, e in t.TOPOLOGY_CASES]
    cases += [(f"scene: {w}", e) for w, _, _, e in t.SCENE_CASES]
    cases += [(f"command line: {' '.join(a)}", e) for a, e in c.BAD_COMMANDS]
    return [(w.replace("|", "\\|"), e.replace("|", "\\|")) for w, e in cases]


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _command_table() -> list[tuple[str, int, str]]:
    """Every case of the bad-input table (``tests/bad_inputs.py``) run as the test runs
    it: (command line, exit code, the one line on stderr), temporary paths shortened."""
    import os
    import sys

    sys.path.insert(0, str(project_root()))
    from tests.bad_inputs import CASES, make_files
    from tests.test_bad_inputs import run_case

    rows = []
    here = os.getcwd()
    with tempfile.TemporaryDirectory() as tmp:
        files = make_files(Path(tmp), project_root())
        for argv, _ in CASES:
            with tempfile.TemporaryDirectory() as cwd:
                os.chdir(cwd)
                try:
                    code, _, err = run_case(argv, files)
                finally:
                    os.chdir(here)
            lines = [ln for ln in err.splitlines() if ln.strip()]
            text = " ⏎ ".join(lines).replace(tmp, "TMP").replace(str(project_root()), ".")
            rows.append((argv, code, text))
    return rows


def _memory_rows() -> list[tuple[str, int, float]]:
    """Peak resident size of `gearsym simulate` at 20,000 and 100,000 sampled periods
    (figure and JSON written), measured as tests/test_memory.py measures it."""
    import sys

    sys.path.insert(0, str(project_root()))
    from tests.test_memory import peak_mb

    rows = []
    for scene in ("reference-light", "reference-dead-zone"):
        for periods in (20_000, 100_000):
            with tempfile.TemporaryDirectory() as tmp:
                args = [
                    "simulate",
                    scene,
                    "--set",
                    "lambda=0.05",
                    "--periods",
                    str(periods),
                    "--lyapunov-periods",
                    "0",
                    "--out",
                    f"{tmp}/out",
                ]
                code, mb = peak_mb(args, tmp)
            rows.append((f"`gearsym {' '.join(args[:-2])} --out DIR`", code, mb))
    return rows


# The classes of hostile and careless input (issue 23) and the tests that hold each.
HOSTILE_CLASSES = [
    (
        "No input text becomes code: paths, names, descriptions in generated files",
        "`derive/escape.py` (one escaper; model symbols as `m_<name>` in Python and C); "
        "`tests/test_hostile_text.py`, `tests/test_fuzz.py`",
    ),
    (
        "Identifiers match as whole strings (no trailing newline)",
        "`tests/test_hostile_text.py`, `tests/derive/test_input_shapes.py`",
    ),
    (
        "C and Python words as names (`int`, `q`, `NAN`, `restrict`, `th0`, ...)",
        "`tests/test_hostile_text.py` (compiled simulate against SciPy), `tests/test_fuzz.py`",
    ),
    (
        "The cache verified, never trusted: models and compiled libraries",
        "`tests/test_cache_trust.py`, `tests/test_fuzz.py`; who can write it: `docs/user-guide.md`",
    ),
    (
        "Files of the wrong shape, nesting past 32 levels",
        "`tests/bad_inputs.py` (block 'files of the wrong shape'), "
        "`tests/derive/test_input_shapes.py`",
    ),
    (
        "Maps without a C compiler; a compiler that fails",
        "`tests/solver/test_map_fallback.py`, `tests/test_fuzz.py`",
    ),
    (
        "Continuations inside the parameters' valid ranges; any scene parameter or a refusal",
        "`tests/test_cli_limits.py`, `tests/test_fuzz.py`, `tests/bad_inputs.py` (block "
        "'continuation parameters')",
    ),
    (
        "Strict JSON; values that would overflow refused at the input",
        "`tests/test_unix_manners.py`, `tests/bad_inputs.py` (block 'strict JSON')",
    ),
    (
        "Bounded work: every size that sets the cost has a stated limit",
        "`tests/test_cli_limits.py`, `tests/bad_inputs.py` (block 'bounded work')",
    ),
    (
        "Unix manners: a closed pipe ends quietly (SIGPIPE, 141); Ctrl-C one line, work kept",
        "`tests/test_unix_manners.py`",
    ),
]


def _hostile_section() -> list[str]:
    """The classes of issue 23 and the probe (benchmarks/hostile.py) run on this checkout."""
    from gearsym.benchmarks.hostile import LIMIT_S, rows

    table = rows()
    bad = [r for r in table if r["problems"]]
    tracebacks = sum("traceback" in r["problems"] for r in table)
    return [
        "## Hostile and careless input",
        "",
        "Each class below is held by tests (fixed cases, and a property-based fuzz test of",
        "names, paths and values with a fixed seed: `tests/test_fuzz.py`).",
        "",
        "| class | where it is held |",
        "|---|---|",
        *(f"| {_cell(c)} | {_cell(w)} |" for c, w in HOSTILE_CLASSES),
        "",
        "The probe (`python benchmarks/hostile.py`) runs each class as a user would, each case",
        f"its own process with a limit of {LIMIT_S:.0f} s, and counts what goes wrong: a",
        "traceback, a run past the limit, a refusal of more than one line, a file nobody asked",
        f"for, JSON that is not strict. On this checkout: **{len(table)} cases, {len(bad)} went",
        f"wrong, {tracebacks} with a traceback**.",
        "",
        "| class | case | exit | seconds | what went wrong | last line on stderr |",
        "|---|---|---|---|---|---|",
        *(
            f"| {r['class']} | {_cell(r['case'])} | {r['exit']} | {r['seconds']:.1f} | "
            f"{', '.join(r['problems']) or 'nothing'} | {_cell(r['stderr'])} |"
            for r in table
        ),
        "",
    ]


def main() -> None:
    out = output_folder(checkout_docs(), (REPORT,)) / REPORT
    with tempfile.TemporaryDirectory() as tmp:
        rows = matrix(harmonics_models(Path(tmp)))
    by = {(r["case"], r["method"]): r for r in rows}
    lines = [
        "# Robustness: the extremes matrix",
        "",
        "Written by `python benchmarks/robustness.py`. Each case changes one thing of the",
        "light-load reference scene (λ = 0.1, f1 = 0.1, ζ = 0.03, ω̄ = 0.5, 3 harmonics,",
        "rtol 1e-8) and runs with every back end: 6 transient + 2 sampled periods, 16 samples",
        "per period, 256 steps per period for the fixed-step methods. A cell gives the motion",
        "of u (so short a run is not meant to classify well: the point is that every run ends",
        "in a result with finite numbers or a clear failure), or the status and message.",
        "Output files turn any non-finite number into null (`solver/_json.py`).",
        "",
        "| case | " + " | ".join(METHODS) + " |",
        "|---|" + "---|" * len(METHODS),
    ]
    for case in CASES:
        cells = [describe(by[(case.label, m)]).replace("|", "\\|") for m in METHODS]
        lines.append(f"| {case.label} | " + " | ".join(cells) + " |")
    total = len(rows)
    failed = sum(r["status"] != "ok" for r in rows)
    lines += [
        "",
        f"{total} runs: {total - failed} finished with finite results, {failed} ended with a "
        "stated status (divergent, invalid, failed) and message. Seconds per run: "
        f"median {sorted(r['seconds'] for r in rows)[total // 2]:.2f}, "
        f"max {max(r['seconds'] for r in rows):.1f}.",
        "",
        "## Bad input",
        "",
        "Every case below is a test (`tests/derive/test_input_errors.py`,",
        "`tests/solver/test_cli_solver.py`): the run stops with exit code 2 and one line naming",
        "the file (or option), the key and what is allowed; no traceback (`--debug` shows one).",
        "",
        "| input | the message contains |",
        "|---|---|",
        *(f"| {what} | `{fragment}` |" for what, fragment in _bad_input_cases()),
        "",
    ]
    table = _command_table()
    clean = sum(
        code == 2 and " ⏎ " not in text and "Traceback" not in text for _, code, text in table
    )
    lines += [
        "## Bad input on every command",
        "",
        f"The {len(table)} cases of `tests/bad_inputs.py`, run by `tests/test_bad_inputs.py`",
        "(each must exit with code 2 and one line naming the input, before computing) and",
        f"here: **{clean} of {len(table)} end that way**. `TMP` stands for the test's",
        "temporary folder (placeholders in the command: `{tmp}` a folder, `{file}` a regular",
        "file, `{bad_utf8}` a TOML file that is not UTF-8, `{brace}` a JSON file holding",
        "`{}`, `{torn}` a truncated JSON file, `{scene:KEY}` a scene with one line changed).",
        "Exit codes: 0 ok, 2 bad input, 3 a run that ended invalid, divergent or failed.",
        "",
        "| command line | exit | stderr |",
        "|---|---|---|",
        *(f"| `{_cell(argv)}` | {code} | {_cell(text)} |" for argv, code, text in table),
        "",
        *_hostile_section(),
        "## Memory of long runs",
        "",
        "Peak resident size of the command's own process (the kernel's count), with the",
        "figure and the JSON written; the floors are 300 MB at 20,000 and 500 MB at 100,000",
        "sampled periods (`tests/test_memory.py`). A command keeps at most 2^20 samples per",
        "state (fewer samples per period past 16,384 periods, said on stderr); requests whose",
        "estimate exceeds half the machine's memory are refused before allocating.",
        "",
        "| command | exit | peak MB |",
        "|---|---|---|",
        *(f"| {what} | {code} | {mb:.0f} |" for what, code, mb in _memory_rows()),
        "",
    ]
    out.write_text("\n".join(lines), encoding="utf-8")
    print(out.read_text(encoding="utf-8"))


if __name__ == "__main__":
    run_script(main)
