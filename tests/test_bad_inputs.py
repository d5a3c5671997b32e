"""Every bad input of the table (``tests/bad_inputs.py``) ends the command with exit code
2 and one line on stderr that names the input, with no traceback and before anything is
computed (nothing on stdout, no output folder left in the working directory)."""

from __future__ import annotations

import pytest
from gearsym.cli import main

from tests.bad_inputs import CASES, materialise


def run_case(argv: str, files: dict) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``gearsym argv`` run in this process."""
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(materialise(argv, files))
        except SystemExit as stop:
            code = stop.code
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def files(tmp_path_factory, root):
    from tests.bad_inputs import make_files

    return make_files(tmp_path_factory.mktemp("bad-inputs"), root)


def test_the_table_holds_at_least_150_cases_on_every_command():
    assert len(CASES) >= 150
    commands = {argv.split()[0] for argv, _ in CASES}
    assert commands >= {
        "derive",
        "backlash",
        "stiffness",
        "simulate",
        "sweep",
        "shoot",
        "continue",
        "map",
        "frequency-response",
        "reproduce",
        "bench",
    }


@pytest.mark.parametrize("argv,fragment", CASES, ids=[c[0] for c in CASES])
def test_a_bad_input_is_one_line_and_exit_code_2(argv, fragment, files, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_case(argv, files)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2, (code, err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert lines[0].startswith("gearsym"), lines[0]
    assert fragment.lower() in lines[0].lower(), lines[0]
    assert out == "", out  # refused before anything was computed or written
    assert not [p for p in tmp_path.iterdir() if p.name != "probe"], list(tmp_path.iterdir())
