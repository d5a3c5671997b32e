"""The derivation cache is verified, never trusted (issue 23).

A cached model is imported only when the sha256 of its bytes equals the digest written
beside it; a module that is empty, cut short, edited or not Python, or whose digest is
missing or wrong, is derived again with one warning and is never run.  A ``digests.json``
of the wrong shape is written anew with one warning.  The shipped models in ``generated/``
are part of the package and load as before.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from gearsym import resolve


@pytest.fixture(scope="module")
def seeded(tmp_path_factory, root):
    """A user's scene (the light-load scene under another name) and a cache folder holding
    its model, derived once for the whole module: (scene, cache folder, module file)."""
    folder = tmp_path_factory.mktemp("trust")
    text = (root / "scenes" / "reference-light.toml").read_text(encoding="utf-8")
    text = text.replace('topology = "topologies/diso.toml"', 'topology = "diso"')
    text = text.replace('name = "reference-light"', 'name = "trust-light"')
    scene = folder / "trust-light.toml"
    scene.write_text(text, encoding="utf-8")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("GEARSYM_CACHE", str(folder / "seed"))
        module = resolve.module_for(scene)
    return scene, folder / "seed", Path(module.__file__)


@pytest.fixture
def cache(seeded, tmp_path, monkeypatch):
    """A copy of the seeded cache as this test's cache: (scene, module file, digest file)."""
    scene, seed, module = seeded
    shutil.copytree(seed, tmp_path / "cache")
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    mine = tmp_path / "cache" / module.relative_to(seed)
    return scene, mine, mine.with_suffix(".sha256")


def loaded(target):
    """(module, messages of the warnings raised) of ``resolve.module_for(target)``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        module = resolve.module_for(target)
    return module, [str(w.message) for w in caught]


def test_a_model_is_cached_with_the_digest_of_its_bytes_and_loads_without_deriving(
    cache, monkeypatch
):
    scene, module, digest = cache
    stated = digest.read_text(encoding="ascii")
    assert stated == hashlib.sha256(module.read_bytes()).hexdigest() + "\n"

    def derive_model(*args, **kwargs):
        raise AssertionError("a verified cached model was derived again")

    monkeypatch.setattr("gearsym.derive.derive_model", derive_model)
    got, messages = loaded(scene)
    assert messages == []
    assert got.__file__ == str(module) and got.NAME == "trust_light"


def _edited(module: Path, digest: Path) -> None:
    # Valid Python that would leave a file behind if it were ever run.
    marker = module.parent / "ran.txt"
    with module.open("a", encoding="utf-8") as fh:
        fh.write(f"\nopen({str(marker)!r}, 'w').write('ran')\n")


CORRUPTIONS = {
    "empty": lambda m, d: m.write_bytes(b""),
    "cut short": lambda m, d: m.write_bytes(m.read_bytes()[: m.stat().st_size // 2]),
    "edited": _edited,
    "not Python": lambda m, d: m.write_bytes(b"\x00\xff\xfe not ( Python"),
    "not UTF-8": lambda m, d: m.write_bytes(b"\xff" + m.read_bytes()[1:]),
    "no digest": lambda m, d: d.unlink(),
    "digest of other bytes": lambda m, d: d.write_text(hashlib.sha256(b"x").hexdigest()),
    "digest not a digest": lambda m, d: d.write_text("[1, 2]\n"),
    "digest empty": lambda m, d: d.write_bytes(b""),
    "digest not text": lambda m, d: d.write_bytes(b"\xff\xfe\x00"),
}


@pytest.mark.parametrize("how", CORRUPTIONS)
def test_a_corrupted_cached_model_is_derived_again_with_one_warning_and_never_run(
    cache, seeded, how
):
    scene, module, digest = cache
    CORRUPTIONS[how](module, digest)
    got, messages = loaded(scene)
    assert len(messages) == 1, messages
    assert str(module) in messages[0] and "deriving it again" in messages[0]
    assert "\n" not in messages[0]
    assert not (module.parent / "ran.txt").exists()  # the edited module never ran
    assert got.__file__ == str(module) and got.NAME == "trust_light"
    assert module.read_bytes() == seeded[2].read_bytes()  # derived again, byte for byte
    assert digest.read_text() == hashlib.sha256(module.read_bytes()).hexdigest() + "\n"
    assert loaded(scene)[1] == []  # mended: trusted again


def test_a_missing_cached_model_is_derived_without_a_warning(cache):
    scene, module, digest = cache
    module.unlink()
    got, messages = loaded(scene)
    assert messages == [] and got.__file__ == str(module)
    assert digest.read_text() == hashlib.sha256(module.read_bytes()).hexdigest() + "\n"


DIGEST_FILES = {
    "an array": "[]",
    "an array of numbers": "[1, 2]",
    "text": '"x"',
    "a number": "5",
    "empty": "",
    "cut short": '{"a',
    "not UTF-8": b"\xff\xfe{}",
    "nested without end": "[" * 100_000 + "]" * 100_000,
    "an entry that is text": json.dumps({"0" * 64: "reference_light"}),
    "an entry that is an array": json.dumps({"0" * 64: ["reference_light", "0" * 64]}),
    "an entry without a digest": json.dumps({"0" * 64: {"name": "reference_light"}}),
    "an entry naming a dotted module": json.dumps(
        {"0" * 64: {"name": "reference_light.os", "digest": "0" * 64}}
    ),
    "an entry with a digest that is a number": json.dumps(
        {"0" * 64: {"name": "reference_light", "digest": 5}}
    ),
    "a key that is not a fingerprint": json.dumps(
        {"../x": {"name": "reference_light", "digest": "0" * 64}}
    ),
}


@pytest.mark.parametrize("how", DIGEST_FILES)
def test_a_digests_file_of_the_wrong_shape_is_written_anew_with_one_warning(
    tmp_path, monkeypatch, how
):
    import gearsym.generated.reference_light as shipped

    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    file = tmp_path / "cache" / "models" / "digests.json"
    file.parent.mkdir(parents=True)
    content = DIGEST_FILES[how]
    file.write_bytes(content if isinstance(content, bytes) else content.encode())
    got, messages = loaded("reference-light")
    assert got is shipped
    assert len(messages) == 1, messages
    assert str(file) in messages[0] and "writing it anew" in messages[0]
    known = json.loads(file.read_text(encoding="utf-8"))
    assert isinstance(known, dict) and len(known) == 1
    assert list(known.values()) == [{"name": "reference_light", "digest": shipped.INPUTS_SHA256}]

    def load_target(*args, **kwargs):
        raise AssertionError("the fast path was not taken")

    monkeypatch.setattr("gearsym.derive.load_target", load_target)
    assert loaded("reference-light") == (shipped, [])  # mended: the fast path again


def test_the_shipped_models_load_from_the_package_and_nothing_of_them_enters_the_cache(
    tmp_path, monkeypatch, root
):
    import gearsym.generated.reference_light as shipped

    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    before = Path(shipped.__file__).read_bytes()
    for _ in range(2):  # the slow path, then the fast one
        assert loaded("reference-light") == (shipped, [])
    assert Path(shipped.__file__).read_bytes() == before
    assert Path(shipped.__file__).parent == root / "generated"
    assert [p.name for p in (tmp_path / "cache" / "models").iterdir()] == ["digests.json"]


def test_on_the_command_line_a_corrupted_model_is_one_warning_line_and_the_run_goes_on(
    cache, tmp_path
):
    scene, module, digest = cache
    module.write_bytes(b"")
    env = dict(os.environ, GEARSYM_CACHE=str(tmp_path / "cache"))
    argv = f"simulate {scene} --method RK45 --transient 0 --periods 1 --lyapunov-periods 0"
    done = subprocess.run(
        [sys.executable, "-m", "gearsym", *argv.split()],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    # one warning line (and the note on the polynomial backlash, issue 25)
    lines = [ln for ln in done.stderr.splitlines() if not ln.startswith("gearsym: note:")]
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("gearsym: warning: the cached model ")
    assert "deriving it again" in lines[0]
    assert "trust_light" in done.stdout


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX owners and modes")
def test_the_fallback_under_a_shared_temporary_folder_must_be_private(tmp_path):
    # When the cache root cannot be written, gearsym falls back to a folder under /tmp:
    # one that others may write (or a link someone planted) is passed over.
    from gearsym.solver.cache import _private

    assert _private(tmp_path / "new")  # made now, for this user only
    assert (tmp_path / "new").stat().st_mode & 0o777 == 0o700
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    assert not _private(shared)
    (tmp_path / "link").symlink_to(tmp_path / "new")
    assert not _private(tmp_path / "link")


_LIBRARY_RUN = """
import json, warnings
import numpy as np
from gearsym.resolve import load
from gearsym.solver.integrate import native
system = load("siso")
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    _, facts = native.library(system.module)
X0 = np.zeros((1, len(system.module.STATES)))
run = native.run_batch(system.module, system.p[None, :], X0, transient=2, periods=2)
print(json.dumps({"path": facts["path"], "compiled": facts["compiled"],
                  "warnings": [str(w.message) for w in caught], "x": run.x.tolist()}))
"""


@pytest.mark.parametrize("how", ["edited", "cut short", "digest missing"])
def test_a_compiled_library_that_does_not_match_its_digest_is_built_again(how, tmp_path):
    """The compiled libraries of the same cache are verified the same way: a library whose
    bytes do not hash to the digest written beside it when it was built is never loaded;
    it is built again with one warning, and the run gives the same numbers.  Each step is
    a process of its own, as a user's runs are (a loaded library is mapped in memory)."""
    env = {**os.environ, "GEARSYM_CACHE": str(tmp_path / "cache")}

    def run():
        done = subprocess.run(
            [sys.executable, "-c", _LIBRARY_RUN], env=env, capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)

    first = run()
    lib = Path(first["path"])
    digest = lib.with_suffix(".sha256")
    assert digest.read_text().strip() == hashlib.sha256(lib.read_bytes()).hexdigest()
    if how == "edited":
        lib.write_bytes(lib.read_bytes() + b"\0")
    elif how == "cut short":
        lib.write_bytes(lib.read_bytes()[:4096])
    else:
        digest.unlink()
    second = run()
    if how == "digest missing":  # a library built before digests: rebuilt, nothing said
        assert second["warnings"] == [], second["warnings"]
    else:
        assert len(second["warnings"]) == 1, second["warnings"]
        assert "does not match the digest" in second["warnings"][0]
    assert second["compiled"]
    assert second["x"] == first["x"]
    assert run()["warnings"] == []  # built anew with its digest: trusted next time


def test_a_bytecode_file_beside_a_cached_model_is_never_run(cache, tmp_path):
    """Python's import would run ``__pycache__/<name>.pyc`` when its header matches the
    source's time and size, without reading the source; a cached model is run from the
    bytes that were verified, so a planted bytecode file does nothing."""
    import importlib.util
    from importlib._bootstrap_external import _code_to_timestamp_pyc

    scene, module, _ = cache
    stat = module.stat()
    planted = tmp_path / "PLANTED"
    code = compile(f"open({str(planted)!r}, 'w').close()", str(module), "exec")
    pyc = Path(importlib.util.cache_from_source(str(module)))
    pyc.parent.mkdir(exist_ok=True)
    pyc.write_bytes(_code_to_timestamp_pyc(code, int(stat.st_mtime), stat.st_size))
    loaded_module, messages = loaded(scene)
    assert messages == []
    assert loaded_module.NAME == "trust_light"
    assert not planted.exists(), "the bytecode file ran"


def test_a_worker_that_loads_a_cached_model_by_path_verifies_it(cache):
    """Worker processes load a model by its file (``System.load(path)``): a file that no
    longer matches its digest is refused with the reason, never run."""
    from gearsym.solver.contract import load_generated

    _, module, _ = cache
    assert load_generated(module).NAME == "trust_light"
    module.write_text(module.read_text(encoding="utf-8") + "\nraise SystemExit(99)\n", "utf-8")
    with pytest.raises(ValueError, match="does not match the digest"):
        load_generated(module)


def test_a_variant_loaded_again_in_one_process_is_not_parsed_again(cache, monkeypatch):
    """A map over open values loads each variant once per value and task: the second
    load of the same variant, files unchanged, must not parse the scene again (the mesh
    stiffness it recomputes costs 0.1 s).  A module file changed since is checked again."""
    scene, _, _ = cache
    first = resolve.module_for(scene, {"load_reading": "both-driving"})
    calls = []
    monkeypatch.setattr(resolve, "_derived", lambda *a: calls.append(a) or first)
    assert resolve.module_for(scene, {"load_reading": "both-driving"}) is first and not calls
    path = Path(first.__file__)
    path.write_bytes(path.read_bytes() + b"\n")  # edited: the stamp differs
    assert resolve.module_for(scene, {"load_reading": "both-driving"}) is first and calls


def test_two_processes_that_need_the_same_library_at_once_build_it_once(tmp_path):
    """Workers that ask for one library at the same moment (a reproduce's first tasks)
    each compiled it; now the second waits on the first's lock and loads what it built,
    and both run the same numbers."""
    env = {**os.environ, "GEARSYM_CACHE": str(tmp_path / "cache")}
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", _LIBRARY_RUN],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    outs = []
    for p in procs:
        out, err = p.communicate(timeout=300)
        assert p.returncode == 0, err
        outs.append(json.loads(out))
    assert sorted(o["compiled"] for o in outs) == [False, True]
    assert outs[0]["path"] == outs[1]["path"]
    assert outs[0]["x"] == outs[1]["x"]


def test_a_cache_on_a_file_system_without_locks_builds_without_one(tmp_path, monkeypatch):
    """flock fails on some network file systems (ENOLCK): the build goes on unlocked, as
    on a platform without flock, instead of failing every compiled run."""
    import errno
    import fcntl

    from gearsym.solver.cache import locked

    def refuse(*_):
        raise OSError(errno.ENOLCK, "No locks available")

    monkeypatch.setattr(fcntl, "flock", refuse)
    ran = []
    with locked(tmp_path / "lib.so"):
        ran.append(True)
    assert ran == [True]
