"""Your own scene file: a copy of the light-load reference scene with another damping
ratio, loaded by path (derived once into the user cache, ``$GEARSYM_CACHE/models``) and
simulated.

Run: ``python docs/examples/own_scene.py [OUTDIR]`` (default: a temporary folder, where
the scene file is written).
"""

import sys
import tempfile
from pathlib import Path

import gearsym
from gearsym.derive.scene import builtin_root


def main(out: Path) -> None:
    scenes = builtin_root()
    text = (scenes / "reference-light.toml").read_text(encoding="utf-8")
    text = text.replace('name = "reference-light"', 'name = "my-light"')
    text = text.replace("damping_ratio = 0.03", "damping_ratio = 0.05")
    topology = (scenes / "topologies" / "diso.toml").as_posix()
    text = text.replace('topology = "topologies/diso.toml"', f'topology = "{topology}"')
    scene = out / "my-light.toml"
    scene.write_text(text, encoding="utf-8")

    system = gearsym.load(scene, **{"lambda": 0.8})
    print(f"{system.name}: derived into {system.module.__file__}")
    point = gearsym.analyse(system, transient=100, periods=16, lyapunov_periods=50)
    for c, verdict in point.classification.items():
        print(f"  {c}: {verdict.motion}")
    print("wrote", point.save(out / "point.mat"))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
