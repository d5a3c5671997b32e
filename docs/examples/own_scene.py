"""Your own scene file: a copy of the light-load reference scene with another damping
ratio, loaded by path and analysed once.

A scene that is not shipped with gearsym is derived once into the derivation cache,
``$GEARSYM_CACHE/models`` (default ``~/.cache/gearsym/models``), keyed by the hash of its
inputs; the next load of the same file takes it from there.  The ``topology = ...`` line of
a scene is a path relative to the scene file (or a built-in topology name such as
``"diso"``); the copy names the built-in topology file by its absolute path.

Run: ``python docs/examples/own_scene.py [OUTDIR]`` (default: a temporary folder); the
scene file and the point's result (``point.mat``) are written there.
"""

import sys
import tempfile
from importlib.resources import files
from pathlib import Path

import gearsym


def main(out: Path) -> None:
    scenes = files("gearsym.scenes")  # the built-in scenes and topologies
    text = (scenes / "reference-light.toml").read_text(encoding="utf-8")
    text = text.replace('name = "reference-light"', 'name = "my-light"')
    text = text.replace("damping_ratio = 0.03", "damping_ratio = 0.05")
    topology = Path(str(scenes / "topologies" / "diso.toml")).as_posix()
    text = text.replace('topology = "topologies/diso.toml"', f'topology = "{topology}"')
    assert "0.05" in text and topology in text, "reference-light.toml has changed"
    scene = out / "my-light.toml"
    scene.write_text(text, encoding="utf-8")

    system = gearsym.load(scene, **{"lambda": 0.8})
    print(f"{system.name}: derived into {system.module.__file__}")
    point = gearsym.analyse(system, transient=100, periods=20, lyapunov_periods=50)
    for c, verdict in point.classification.items():
        print(f"  {c}: {verdict.motion}")
    print("wrote", point.save(out / "point.mat"))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
