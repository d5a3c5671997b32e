"""The 0-1 test for chaos against series whose nature is known.

References: Gottwald and Melbourne, Proc. R. Soc. A 460 (2004) 603 (logistic map, K near 1
in chaos and near 0 in its periodic windows; quasi-periodic data, K near 0) and SIAM J.
Appl. Dyn. Syst. 8 (2009) 129 (the implementation followed here); Henon, Commun. Math.
Phys. 50 (1976) 69 (the map with a = 1.4, b = 0.3 is chaotic).
"""

import json

import numpy as np
import pytest
from gearsym.solver.analysis.zero_one import displacement, zero_one

N = 5000


def logistic(r, n, x0=0.3, transient=1000):
    x, out = x0, np.empty(n)
    for i in range(transient + n):
        x = r * x * (1.0 - x)
        if i >= transient:
            out[i - transient] = x
    return out


def henon(n, a=1.4, b=0.3, transient=1000):
    x, y, out = 0.1, 0.1, np.empty(n)
    for i in range(transient + n):
        x, y = 1.0 - a * x * x + y, b * x
        if i >= transient:
            out[i - transient] = x
    return out


@pytest.mark.parametrize(
    "name, series",
    [
        ("logistic r=4", logistic(4.0, N)),
        ("logistic r=3.97", logistic(3.97, N)),
        ("Henon a=1.4 b=0.3", henon(N)),
    ],
)
def test_chaotic_maps_read_near_one(name, series):
    result = zero_one(series)
    assert result.K > 0.9, name
    assert result.K_c_quartiles[0] > 0.9, name  # not a median of a wide spread
    assert result.reading == "chaotic"


k = np.arange(N)
REGULAR = [
    ("logistic r=3.5, period 4", logistic(3.5, N)),
    ("sin(2 pi 0.3 k), periodic", np.sin(2 * np.pi * 0.3 * k)),
    (
        "sin(2 pi a k) + 0.5 sin(2 pi b k), a = sqrt 2 - 1, b = (sqrt 5 - 1)/4",
        np.sin(2 * np.pi * (np.sqrt(2) - 1) * k)
        + 0.5 * np.sin(2 * np.pi * (np.sqrt(5) - 1) / 4 * k),
    ),
    # an offset far above the fluctuation (a Poincare coordinate's static deflection)
    ("1e3 + sin(2 pi 0.3 k)", 1e3 + np.sin(2 * np.pi * 0.3 * k)),
]


@pytest.mark.parametrize("name, series", REGULAR, ids=[r[0] for r in REGULAR])
def test_regular_series_read_near_zero(name, series):
    result = zero_one(series)
    assert abs(result.K) < 0.1, name
    assert result.reading == "regular"


def test_displacement_by_fft_equals_the_definition():
    # D_c(n) = 1/(N - n) sum_{j=1}^{N-n} |z(j + n) - z(j)|^2, z(n) = sum_{j<=n} psi_j e^{ijc}
    phi = logistic(3.9, 600)
    c = np.array([0.7, 1.3, 2.2])
    n_cut = 60
    got = displacement(phi, c, n_cut)
    psi = phi - phi.mean()
    j = np.arange(1, phi.size + 1)
    for row, cc in enumerate(c):
        z = np.cumsum(psi * np.exp(1j * cc * j))
        want = [np.mean(np.abs(z[n:] - z[:-n]) ** 2) for n in range(1, n_cut + 1)]
        np.testing.assert_allclose(got[row], want, rtol=1e-10)


def test_mean_removal_is_the_oscillatory_correction():
    # the mean's own displacement is E[phi]^2 (1 - cos nc)/(1 - cos c) for every j, the
    # V_osc of the 2009 paper: removing the mean leaves nothing of a constant offset
    phi = logistic(3.9, 800)
    c = np.array([0.9, 2.0])
    np.testing.assert_allclose(displacement(phi + 50.0, c, 80), displacement(phi, c, 80), rtol=1e-9)


def test_same_seed_same_answer_and_describe_is_json():
    series = logistic(3.8, 2000)
    a, b = zero_one(series, seed=3), zero_one(series, seed=3)
    assert a == b
    assert zero_one(series, seed=4).K != a.K  # the seed does draw the c values
    d = json.loads(json.dumps(a.describe()))
    assert d["samples"] == 2000 and d["n_cut"] == 200 and d["n_c"] == 100
    assert d["K"] == a.K and d["reading"] in ("chaotic", "regular", "undetermined")


@pytest.mark.parametrize(
    "series, words",
    [
        (np.ones(500), "constant"),
        (np.arange(99.0), "at least 100"),
        (np.zeros((2, 200)), "1-D"),
        (np.r_[np.arange(200.0), np.nan], "nan"),
    ],
)
def test_bad_series_fail_in_one_line(series, words):
    with pytest.raises(ValueError, match=words) as info:
        zero_one(series)
    assert "\n" not in str(info.value)


def test_n_c_must_be_positive():
    with pytest.raises(ValueError, match="n_c"):
        zero_one(logistic(4.0, 200), n_c=0)
