"""A planetary set's natural frequencies against its carrier's speed
(``gearsym.planetary.carrier_sweep``, ``gearsym modes SET --speeds LO:HI[:NUM]``): every
speed against the hand assembly of M, G and K written for the turning-carrier tests, the
mesh harmonics' meetings against their closed form, and the command's files and refusals."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from gearsym.derive.equations.planetary import derive_planetary
from gearsym.derive.equations.planetary_frame import at_speed
from gearsym.planetary import carrier_sweep

from .test_planetary import example
from .test_planetary_speed import DOFS, by_hand_at_speed, first_order, refused, run, variant


def test_each_speed_equals_the_hand_assembly():
    ps = example(4)
    sweep = carrier_sweep(derive_planetary(ps), 0.0, 24000.0, num=5)
    for i, rpm in enumerate(sweep["speeds_rpm"]):
        if rpm == 0.0:
            continue
        M, C, K, _ = by_hand_at_speed(replace(ps, carrier_speed_rpm=rpm), rpm)
        lam = first_order(M, C, K)
        hand = np.sort(lam.imag[lam.imag > 1e-6 * np.abs(lam).max()]) / (2 * math.pi)
        ours = [m["frequency_hz"][i] for m in sweep["modes"]]
        assert ours == pytest.approx(list(hand), rel=1e-9)


def test_at_speed_is_the_derivation_at_that_speed():
    # the sweep puts a set derived once at each speed: the same matrices as deriving the
    # file with that carrier speed
    ps = example(3)
    once = at_speed(derive_planetary(ps), 7000.0)
    again = derive_planetary(replace(ps, carrier_speed_rpm=7000.0))
    assert once.carrier_speed_rad_s == again.carrier_speed_rad_s
    np.testing.assert_array_equal(once.gyroscopic, again.gyroscopic)
    np.testing.assert_array_equal(once.centripetal, again.centripetal)
    back = at_speed(once, 0.0)
    assert back.gyroscopic is None and back.as_structure() == derive_planetary(ps).as_structure()


def test_the_mesh_harmonics_meet_the_torsional_modes_where_the_closed_form_says(tmp_path):
    # a torsional model does not depend on the speed: the h-th harmonic of the mesh
    # frequency z_r n / 60 meets a mode of f Hz at n = 60 f / (h z_r) exactly
    path = variant(
        tmp_path, "torsional", "lin-parker-1999-3-phased", DOFS, 'degrees_of_freedom = "torsional"'
    )
    sweep = carrier_sweep(path, 0.0, 3000.0, num=31)
    z = sweep["mesh"]["ring_teeth"]
    assert z == 89 and sweep["frame"].startswith("none")
    flat = {m["index"]: m["frequency_hz"][0] for m in sweep["modes"]}
    assert all(len(set(m["frequency_hz"])) == 1 for m in sweep["modes"])
    expected = sorted(
        (60 * f / (h * z), h, k)
        for k, f in flat.items()
        for h in (1, 2, 3)
        if 60 * f / (h * z) < 3000.0
    )
    got = [(c["speed_rpm"], c["harmonic"], c["mode"]) for c in sweep["crossings"]]
    assert [(h, k) for _, h, k in got] == [(h, k) for _, h, k in expected]
    assert [n for n, _, _ in got] == pytest.approx([n for n, _, _ in expected], rel=1e-12)


def test_speeds_without_modes_are_given_with_the_reason():
    # the lowest translational pair softens to zero (Lin and Parker's divergence): no
    # modes past it, each such speed listed with why, the frequencies None there
    sweep = carrier_sweep("lin-parker-1999-4", 0.0, 100000.0, num=41)
    gone = [u["speed_rpm"] for u in sweep["unstable"]]
    assert gone and min(gone) > 20000.0 and "indefinite" in sweep["unstable"][0]["why"]
    i = sweep["speeds_rpm"].index(gone[0])
    assert all(m["frequency_hz"][i] is None for m in sweep["modes"])
    lowest = [f for f in sweep["modes"][0]["frequency_hz"][:i]]
    assert lowest[-1] < 0.1 * lowest[0]  # falling towards zero before it
    assert sweep["mesh"] is None and "ring_teeth" in sweep["mesh_why_not"]


def test_the_command_writes_its_files_and_refuses_in_one_line(tmp_path):
    png, out = tmp_path / "campbell.png", tmp_path / "out"
    done = run(
        "modes", "lin-parker-1999-3-phased", "--speeds", "0:3000:7", "--plot", str(png),
        "--out", str(out), "--json",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    sweep = json.loads(done.stdout)
    assert sweep["speeds_rpm"] == [0.0, 500.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    saved = json.loads((out / "carrier_sweep.json").read_text(encoding="utf-8"))
    assert saved["modes"] == sweep["modes"]
    rows = (out / "carrier_sweep.csv").read_text(encoding="utf-8").splitlines()
    assert sum(not r.startswith("#") for r in rows) == 1 + 7 * len(sweep["modes"])
    refused(run("modes", "lin-parker-1999-3", "--speeds", "0:200000"), "keep the speeds below")
    refused(run("modes", "lin-parker-1999-3", "--speeds", "9:1"), "0 <= LO < HI")
    refused(run("modes", "lin-parker-1999-3", "--speeds", "0:1:x"), "LO:HI:NUM")
    refused(
        run("modes", "lin-parker-1999-3-phased", "--speeds", "0:100", "--parametric"),
        "one at a time",
    )


def test_the_api_draws_it():
    import gearsym
    from matplotlib.figure import Figure

    sweep = gearsym.planetary.carrier_sweep("lin-parker-1999-3-turning", 0.0, 6000.0, num=7)
    assert sweep["scene_speed_rpm"] == 3000.0
    fig = gearsym.plot.carrier(sweep)
    assert isinstance(fig, Figure)
    labels = fig.legends[0].get_texts()
    assert {t.get_text() for t in labels} >= {
        "translational",
        "rotational",
        "the file's carrier speed",
    }


def test_a_meeting_on_the_last_speed_is_found_once(tmp_path):
    path = variant(
        tmp_path, "torsional", "lin-parker-1999-3-phased", DOFS, 'degrees_of_freedom = "torsional"'
    )
    f = carrier_sweep(path, 0.0, 1000.0, num=3)["modes"][0]["frequency_hz"][0]
    for h in (1, 2, 3):
        top = 60 * f / (h * 89)  # the h-th harmonic meets mode 1 exactly at HI
        for num in (3, 4):
            meets = [
                c
                for c in carrier_sweep(path, 0.0, top, num=num)["crossings"]
                if c["mode"] == 1 and c["harmonic"] == h
            ]
            assert len(meets) == 1 and meets[0]["speed_rpm"] == pytest.approx(top, rel=1e-12)


def test_a_planetary_sets_modes_read_without_a_mesh_frequency():
    # its file states none: the API's summary, repr, dict and table say so, with no NaN
    # and no division by its zero tooth count
    import gearsym

    modal = gearsym.planetary.modes("lin-parker-1999-4")
    text = modal.summary() + repr(modal)
    assert "nan" not in text.lower() and "no mesh frequency stated" in text
    data = modal.to_dict()
    json.dumps(data, allow_nan=False)
    assert data["mesh_frequency_hz"] is None and data["resonances"] == []
    assert modal.resonances((0.0, 1000.0)) == []
    assert all(row[2] is None for row in modal.to_table()[1])
