"""Nothing a user writes becomes code (issue 23): the escaper on hostile text, scene files in
folders whose names hold Python code, and model names that are C or Python words.

References: Python's own grammar (``ast.parse``, ``compile``) and the C compiler decide
what is code; the tests assert that the hostile text stays text (it reads back unchanged
from the docstring, and the statement it carries never runs)."""

from __future__ import annotations

import ast
import re

import numpy as np
import pytest
from gearsym.derive.escape import (
    code_name,
    is_identifier,
    is_target_name,
    literal,
    markdown,
    one_line,
    text,
)

HOSTILE = [
    'a\nimport os; os.system("touch PWNED")\nb',
    'x"""\nimport os\n"""',
    "trailing backslash \\",
    "c comment */ int main(void) { return 1; } /*",
    "nul \x00 and bell \x07 and escape \x1b[31m red",
    "carriage\rreturn and form\x0cfeed and line\u2028separator",
    "letters: λ = |f2/f1|, Zahnrad, 歯車",
    "quotes ' \" ''' \"\"\" and a backslash-n \\n",
    "{braces} and f'{strings}' and %s",
]


@pytest.mark.parametrize("value", HOSTILE)
def test_text_is_one_printable_line_that_reads_back_from_a_docstring(value):
    out = text(value)
    assert re.fullmatch(r"[ -~]*", out), out  # printable ASCII, so one line
    assert "*/" not in out
    source = f'"""{out}"""\n'
    tree = ast.parse(source)
    assert len(tree.body) == 1 and isinstance(tree.body[0].value, ast.Constant)
    assert tree.body[0].value.value == value  # the docstring says what the user wrote
    comment = ast.parse(f"# {out}\n")
    assert comment.body == []  # a comment stays a comment


@pytest.mark.parametrize("value", HOSTILE)
def test_literal_evaluates_to_the_text(value):
    assert ast.literal_eval(literal(value)) == value


@pytest.mark.parametrize("value", HOSTILE)
def test_markdown_has_no_html_and_no_line_break(value):
    out = markdown(value)
    assert "\n" not in out and "\r" not in out
    assert not re.search(r"(?<!\\)[<>]", out)
    assert "`" not in markdown(value, code=True)


def test_one_line_keeps_letters_and_escapes_control_characters():
    assert one_line("Zahnrad λ\nnext") == "Zahnrad λ\\nnext"
    assert "\x1b" not in one_line("\x1b[2J")


@pytest.mark.parametrize(
    "name", ["u\n", "u ", " u", "", "1u", "u-v", "u_v", "lambda", "None", "ü", "u\x00", 5]
)
def test_an_identifier_is_the_whole_string(name):
    assert not is_identifier(name)


@pytest.mark.parametrize("name", ["u", "int", "q", "NAN", "restrict", "X", "th0", "match"])
def test_plain_words_are_identifiers(name):
    assert is_identifier(name)


@pytest.mark.parametrize("name", ["scene\n", "a/b", "a.b", "-a", "", "a b"])
def test_a_target_name_is_the_whole_string(name):
    assert not is_target_name(name)


@pytest.mark.parametrize("name", ["x\n", "a b", "_t0", "a;b", "", "1a"])
def test_code_name_refuses_what_is_not_a_symbol_name(name):
    with pytest.raises(ValueError):
        code_name(name)


# -- end to end: a scene in a hostile folder ----------------------------------------------


def _user_scene(root, folder, name="mine"):
    folder.mkdir(parents=True, exist_ok=True)
    scene = (root / "scenes" / "reference-light.toml").read_text(encoding="utf-8")
    scene = scene.replace('topology = "topologies/diso.toml"', 'topology = "diso"')
    scene = scene.replace('name = "reference-light"', f'name = "{name}"')
    path = folder / "scene.toml"
    path.write_text(scene, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    "folder",
    [
        'a\nimport pathlib; pathlib.Path("PWNED").touch()\nb',
        'q"""\nimport pathlib; pathlib.Path("PWNED").touch()\n"""',
        "c*/ int PWNED; /*",
    ],
    ids=["newline", "triple-quotes", "c-comment"],
)
def test_a_scene_in_a_folder_named_with_code_derives_and_runs_nothing(
    folder, root, tmp_path, monkeypatch, capsys
):
    from gearsym.cli import main

    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    path = _user_scene(root, tmp_path / folder)
    argv = ["simulate", str(path), "--periods", "2", "--transient", "1"]
    code = main(argv + ["--lyapunov-periods", "0", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "Traceback" not in err
    assert not list(tmp_path.rglob("PWNED")), "text from the path ran as code"
    module = next((tmp_path / "cache" / "models").glob("mine_*.py"))
    source = module.read_text(encoding="utf-8")
    assert re.fullmatch(r"[ -~\n]*", source.split('"""', 2)[1])  # the docstring: printable
    tree = ast.parse(source)
    # The module's statements are the emitter's own: imports, constants and functions.
    kinds = {type(node).__name__ for node in tree.body}
    assert kinds <= {"Expr", "Import", "Assign", "FunctionDef"}, kinds
    assert [n.names[0].name for n in tree.body if isinstance(n, ast.Import)] == ["numpy"]


# -- names that are words of C or of the generated code -----------------------------------

WORDS = ["int", "q", "NAN", "restrict", "n", "j", "X", "P", "DX", "th0", "double"]


def _topology_with_coordinates(root, folder, u, v):
    text_ = (root / "scenes" / "topologies" / "diso.toml").read_text(encoding="utf-8")
    text_ = text_.replace('coordinate = "u"', f'coordinate = "{u}"')
    text_ = text_.replace('coordinate = "v"', f'coordinate = "{v}"')
    text_ = text_.replace('name = "diso"', f'name = "words-{u}-{v}"')
    path = folder / f"words-{u}-{v}.toml"
    path.write_text(text_, encoding="utf-8")
    return path


@pytest.mark.parametrize("u,v", [("int", "q"), ("NAN", "restrict"), ("X", "th0")])
def test_a_coordinate_named_like_a_c_word_compiles_and_simulates(u, v, root, tmp_path, monkeypatch):
    """The compiled right-hand side of a model whose coordinates are C words (``int``,
    ``NAN``, ...) or names of the generated code (``q``, ``X``, ``th0``) builds, and its
    compiled simulation agrees with SciPy's on the same model (rtol 1e-8 runs: 1e-6)."""
    from gearsym.resolve import load
    from gearsym.solver.integrate import native, simulate

    if native.compiler() is None:
        pytest.skip("no C compiler on this machine")
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    system = load(_topology_with_coordinates(root, tmp_path, u, v))
    assert system.module.COORDINATES == (u, v)
    lib, facts = native.library(system.module)  # raises NativeUnavailable if C failed
    assert facts["path"]
    options = dict(transient=2, periods=2, samples_per_period=4)
    compiled = simulate(system, method="dop853", **options)
    reference = simulate(system, method="scipy-dop853", **options)
    assert compiled.status == "ok" and reference.status == "ok"
    np.testing.assert_allclose(compiled.poincare, reference.poincare, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("word", WORDS)
def test_every_c_word_is_namespaced_in_the_generated_c(word, root, tmp_path, monkeypatch):
    from gearsym.resolve import module_for

    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    other = "v" if word != "v" else "u"
    module = module_for(_topology_with_coordinates(root, tmp_path, word, other))
    declared = re.findall(r"const double (\w+) = x\[", module.C_SOURCE)
    assert code_name(word) in declared
    assert word not in declared
