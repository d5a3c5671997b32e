"""Bifurcations that harmonic balance flags on the dead zone, confirmed and typed by the
monodromy of a located time integration (issue 27, point 5)."""

import numpy as np
import pytest
from gearsym.solver.periodic import shoot
from gearsym.solver.periodic.hb_confirm import screen
from gearsym.solver.periodic.hb_continuation import continue_hb
from gearsym.solver.system import System


def _nearest_minus_one(orbit) -> complex:
    mu = orbit.floquet.multipliers
    return complex(mu[np.argmin(np.abs(mu + 1.0))])


def test_period_doubling_flagged_as_neimark_sacker_is_typed_by_the_monodromy():
    # Reference model with the exact dead zone (f1 = 0.1, lambda = 0.1): shooting
    # continuation (located monodromy, an independent route) puts a period doubling at
    # omega = 1.2593.  Hill's multipliers (H = 15) see the multiplier through -1 as a
    # complex pair (-1 +- 1.7e-5 i) and flag a Neimark-Sacker point at 1.2632; the
    # screening retypes it, and shooting at the two ends of its bracket finds the
    # period-1 orbit's real multiplier on either side of -1.
    system = System.load("reference_dead_zone")
    branch = continue_hb(system, "omega", 1.30, 1.22, harmonics=15, ds=0.002, dlam_max=0.002)
    events = branch.bifurcations
    assert [b.kind for b in events] == ["period-doubling"], events
    pd = events[0]
    ev = pd.evidence
    assert ev["monodromy_confirmed"] == 1.0 and ev["hill_retyped"] == 1.0
    assert abs(pd.multiplier.imag) < 1e-9 and abs(pd.multiplier + 1) < 0.05
    lo, hi = ev["monodromy_bracket_low"], ev["monodromy_bracket_high"]
    assert lo < pd.value < hi and hi - lo < 0.02
    sides = []
    for value in (lo, hi):
        k = int(np.argmin(np.abs(branch.values - value)))
        orbit = shoot(system.with_values(omega=value), branch.points[k].x0, 1, tol=1e-10)
        assert orbit.minimal_period == 1
        mu = _nearest_minus_one(orbit)
        assert abs(mu.imag) < 1e-9
        sides.append(mu.real + 1.0)
    assert sides[0] * sides[1] < 0, sides  # a real multiplier crosses -1 in the bracket
    assert any("confirmed 1 (1 retyped) and dropped 0;" in note for note in branch.notes)


def test_unconfirmed_flags_are_dropped_and_counted():
    # Hill's flags of a branch are screened one by one: a flag whose bracket shows no
    # sign change of any monodromy test function is dropped and counted.  A made-up
    # period-doubling flag at omega = 1.29, 0.03 from the only crossing (shooting's 1.2593),
    # is dropped beside the true one.
    from dataclasses import replace

    system = System.load("reference_dead_zone")
    branch = continue_hb(
        system, "omega", 1.30, 1.22, harmonics=15, ds=0.002, dlam_max=0.002, confirm=False
    )
    (flag,) = branch.bifurcations
    k = int(np.argmin(np.abs(branch.values - 1.29)))
    fake = replace(flag, kind="period-doubling", value=float(branch.values[k]), index=k + 1)
    fake = replace(fake, x0=branch.points[k].x0, evidence={})
    result = screen(system, replace(branch, bifurcations=(fake, flag)))
    assert result.flagged == 2 and len(result.confirmed) == 1 and len(result.dropped) == 1
    assert result.dropped[0].value == fake.value
    assert result.dropped[0].evidence["monodromy_confirmed"] == 0.0
    assert result.confirmed[0].kind == "period-doubling" and result.retyped == 1
    d = result.describe()
    assert (d["flagged"], d["confirmed"], d["dropped"]) == (2, 1, 1)
    assert len(d["dropped_events"]) == 1


@pytest.mark.slow
def test_dead_zone_response_keeps_only_confirmed_events():
    # The whole period-1 response from omega = 1.5 down to 0.3 (H = 15): every event kept
    # is confirmed by a sign change of the located monodromy's test function across its
    # bracket; the counts are in the branch's notes.
    system = System.load("reference_dead_zone")
    branch = continue_hb(
        system, "omega", 1.5, 0.3, harmonics=15, ds=1.2 / 400, dlam_max=1.2 / 400, confirm=False
    )
    result = screen(system, branch)
    # the folds where the branch turns are kept as located (no monodromy verdict)
    turns = [b for b in result.branch.bifurcations if "monodromy_confirmed" not in b.evidence]
    assert all(b.kind == "fold" for b in turns)
    assert result.flagged + len(turns) == len(branch.bifurcations) and result.flagged >= 1
    assert len(result.confirmed) + len(result.dropped) == result.flagged
    assert all(b.evidence["monodromy_confirmed"] == 1.0 for b in result.confirmed)
    assert [b.kind for b in result.confirmed].count("period-doubling") == 1
    assert "neimark-sacker" not in [b.kind for b in result.confirmed]
