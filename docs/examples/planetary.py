"""A planetary set from the API alone: its modes typed as Lin and Parker (1999) prove them,
its modes against the carrier's speed with the mesh harmonics (a Campbell diagram), the
parametric instabilities its meshes' stiffness variation drives, and its nonlinear model
(backlash in every mesh): a run with each mesh's contact and the meshes' frequency
response with the band where teeth separate; with their figures and JSON.

Run: ``python docs/examples/planetary.py [OUTDIR]`` (default: a temporary folder).
"""

import json
import sys
import tempfile
from pathlib import Path

import gearsym


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    # the marine stage: the reference study's gear data in a planetary stage (its file
    # says where each number comes from)
    modal = gearsym.planetary.modes("marine-stage-3")
    print(modal.summary())
    counts = {}
    for mode in modal.modes:
        counts[mode.label] = counts.get(mode.label, 0) + 1
    print("mode types:", ", ".join(f"{n} {label}" for label, n in counts.items()))

    # its modes against the carrier's speed: the ring is held and has 100 teeth, so the
    # mesh frequency is 100 x carrier rpm / 60 and its meetings with the modes are found
    sweep = gearsym.planetary.carrier_sweep("marine-stage-3", 0.0, 1500.0, num=31)
    first = [c for c in sweep["crossings"] if c["harmonic"] == 1][0]
    print(
        f"the mesh frequency first meets mode {first['mode']} ({first['label']}) at "
        f"{first['speed_rpm']:.0f} rpm of the carrier, {first['frequency_hz']:.0f} Hz"
    )
    gearsym.plot.save(gearsym.plot.carrier(sweep), out / "campbell.png")
    (out / "carrier_sweep.json").write_text(json.dumps(sweep, indent=1), encoding="utf-8")

    # the parametric instabilities of a set with a stiffness variation and tooth counts
    table = gearsym.planetary.parametric_instabilities("lin-parker-1999-3-phased")
    kept = [b for b in table["bands"] if not b["suppressed"]]
    print(
        f"{len(table['bands'])} primary bands, {len(table['bands']) - len(kept)} suppressed "
        "by the planets' phasing"
    )
    gearsym.plot.save(gearsym.plot.parametric(table), out / "parametric.png")

    # the same set with backlash in every mesh: one run from its loaded equilibrium, each
    # mesh's share of samples with its teeth apart, and the meshes' frequency response
    system = gearsym.planetary.dynamics("lin-parker-1999-3-backlash", mesh_frequency_hz=3500)
    run = gearsym.simulate(system, gearsym.planetary.loaded_state(system), periods=50)
    apart = {m: round(c["apart"], 3) for m, c in gearsym.planetary.contact(run).items()}
    print("teeth apart at 3500 Hz:", apart)
    resp = gearsym.planetary.mesh_response("lin-parker-1999-3-backlash", 2000.0, 4000.0, 41)
    print("teeth separate between", resp["band_hz"], "Hz of mesh frequency")
    gearsym.plot.save(gearsym.plot.mesh_response(resp), out / "mesh_response.png")
    (out / "mesh_response.json").write_text(json.dumps(resp, indent=1), encoding="utf-8")
    print("wrote", *(out / f for f in ("campbell.png", "carrier_sweep.json", "parametric.png")))
    print("wrote", out / "mesh_response.png", out / "mesh_response.json")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
