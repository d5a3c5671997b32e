"""The model's contract: what a solver needs to know, stated as plain data.

Each test names its reference: a shipped scene's set-up (its backlash model and fit
range), the first-order form of the equations, or the emitted module itself.
"""

import ast
import importlib
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from gearsym.derive import DeadZone, LinearContact, SmoothDeadZone, derive_model, load_target
from gearsym.derive.build import shipped_targets
from gearsym.derive.mesh.backlash import BACKLASH_MODELS, fit_dead_zone
from gearsym.derive.model import CONTRACT_FORMAT

KEYS = (
    "format",
    "states",
    "coordinates",
    "velocities",
    "parameters",
    "forcing_frequency",
    "loads",
    "contact",
    "force_sign",
    "piecewise",
    "switching_surfaces",
    "valid_range",
    "functions",
)


# the shipped targets whose derivation (SymPy) the tests below read; the others' contracts
# are read from their generated modules, which `gearsym derive --check` (run by .ci/run)
# holds byte for byte to a fresh derivation.  Deriving all fourteen cost each xdist
# worker about 30 s.
DERIVED = ("reference_light", "reference_dead_zone", "reference_linear", "siso", "diso", "tiso")


@pytest.fixture(scope="module")
def models():
    paths = [p for p in shipped_targets() if p.stem.replace("-", "_") in DERIVED]
    return {m.name: m for m in (derive_model(load_target(p)) for p in paths)}


def _contracts() -> dict:
    """Every shipped target's contract as its generated module states it."""
    names = [p.stem.replace("-", "_") for p in shipped_targets()]
    return {n: importlib.import_module(f"gearsym.generated.{n}").CONTRACT for n in names}


def test_reference_dead_zone_is_piecewise_with_the_four_edges_in_order(models):
    # Reference: scenes/reference-dead-zone.toml, backlash = "dead-zone": kinks at u = +-1
    # and v = +-1, per coordinate the upper edge first; valid everywhere.
    c = models["reference_dead_zone"].contract
    assert c["piecewise"] is True
    assert c["switching_surfaces"] == ((0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0))
    assert c["valid_range"] is None
    assert c["contact"] == {"u": (-1.0, 1.0), "v": (-1.0, 1.0)}


def test_reference_light_is_smooth_and_valid_on_its_fit_range(models):
    # Reference: scenes/reference-light.toml, the 7th-order polynomial fitted on [-3, 3].
    model = models["reference_light"]
    assert model.features.backlash.order == 7
    c = model.contract
    assert c["piecewise"] is False
    assert c["switching_surfaces"] == ()
    assert c["valid_range"] == {"u": 3.0, "v": 3.0}


@pytest.mark.parametrize("name", ["reference_linear", "siso", "diso", "tiso"])
def test_smooth_models_have_no_switching_surfaces(models, name):
    # Reference: linear contact and the polynomial fit are smooth (no Piecewise).
    c = models[name].contract
    assert not any(e.has(sp.Piecewise) for e in models[name].rhs)
    assert c["piecewise"] is False and c["switching_surfaces"] == ()


def test_every_contract_has_the_format_and_the_model_order(models):
    for model in models.values():
        c = model.contract
        assert c["states"] == model.states and c["coordinates"] == model.coordinates
        assert c["parameters"] == model.parameter_names
    for c in [*_contracts().values(), *(m.contract for m in models.values())]:
        assert tuple(c) == KEYS
        assert c["format"] == CONTRACT_FORMAT == 2
        assert c["forcing_frequency"] == "omega" == c["parameters"][0]


def test_loads_name_parameters_that_exist():
    # Reference: derive_model makes one static load f_<coordinate> per mesh coordinate.
    for c in _contracts().values():
        assert set(c["loads"]) == set(c["coordinates"])
        for coordinate, name in c["loads"].items():
            assert name in c["parameters"]
            assert name == f"f_{coordinate}"


def test_velocities_point_at_the_derivative_states(models):
    # Reference: the first-order form X = (u, du): the right-hand side of u is du.
    for c in _contracts().values():
        assert set(c["velocities"]) == set(c["coordinates"])
        for coordinate, i in c["velocities"].items():
            assert c["states"][i] == "d" + coordinate
    for model in models.values():
        for coordinate, i in model.contract["velocities"].items():
            k = model.contract["states"].index(coordinate)
            assert model.rhs[k] == model.state_symbols[i]


def test_tiso_three_meshes_give_three_consistent_coordinates(models):
    # Reference: scenes/topologies/tiso.toml has three meshes (coordinates u, v, w).
    c = models["tiso"].contract
    assert c["coordinates"] == ("u", "v", "w")
    assert c["states"] == ("u", "v", "w", "du", "dv", "dw")
    assert c["velocities"] == {"u": 3, "v": 4, "w": 5}
    assert c["loads"] == {"u": "f_u", "v": "f_v", "w": "f_w"}
    assert c["contact"] == {q: (-1.0, 1.0) for q in "uvw"}
    assert c["valid_range"] == {q: 3.0 for q in "uvw"}
    assert c["switching_surfaces"] == () and c["piecewise"] is False


def _plain(value) -> bool:
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    if isinstance(value, tuple):
        return all(_plain(v) for v in value)
    return value is None or type(value) in (str, float, bool, int)


def test_contract_is_plain_literals_that_print_back_to_themselves(models):
    for c in [*_contracts().values(), *(m.contract for m in models.values())]:
        assert _plain(c)
        assert ast.literal_eval(repr(c)) == c
        assert all(type(v) is float for _, v in c["switching_surfaces"])
        assert all(type(a) is float and type(b) is float for a, b in c["contact"].values())


@pytest.mark.parametrize("name", [p.stem.replace("-", "_") for p in shipped_targets()])
def test_generated_module_states_the_derived_contract(models, name):
    # Reference: the module emitted by `gearsym derive` (checked byte for byte in CI by
    # `gearsym derive --check`; derived here again for the DERIVED targets).
    module = importlib.import_module(f"gearsym.generated.{name}")
    if name in DERIVED:
        assert module.CONTRACT == models[name].contract
    assert module.CONTRACT["states"] == module.STATES
    assert module.CONTRACT["parameters"] == module.PARAMETERS
    assert module.CONTRACT["coordinates"] == module.COORDINATES
    valid = module.CONTRACT["valid_range"]
    assert (valid is None) == (module.VALID_RANGE is None)
    if valid is not None:
        assert set(valid.values()) == {module.VALID_RANGE}
    assert "CONTRACT" in module.__doc__


def test_switching_surfaces_are_where_the_generated_jacobian_jumps():
    # Reference: the exact dead zone's stiffness is 0 inside |u| < 1 and kappa outside,
    # so d(u'')/du jumps across each surface and nowhere between them.
    module = importlib.import_module("gearsym.generated.reference_dead_zone")
    p = np.array(module.DEFAULTS)
    n = len(module.STATES)
    for i, edge in module.CONTRACT["switching_surfaces"]:
        row = module.CONTRACT["velocities"][module.STATES[i]]  # u'' is the rhs of du
        x_in, x_out = np.zeros(n), np.zeros(n)
        x_in[i], x_out[i] = 0.99 * edge, 1.01 * edge
        inside = module.jacobian(0.3, x_in, p)[row, i]
        outside = module.jacobian(0.3, x_out, p)[row, i]
        assert inside == 0.0 and outside < -0.5
        x_mid = np.zeros(n)
        x_mid[i] = 0.5 * edge
        assert module.jacobian(0.3, x_mid, p)[row, i] == 0.0


def _condition_edges(expr) -> set:
    """The numbers c in the relational conditions x > c, x < c of a Piecewise."""
    edges = set()
    for piece in expr.atoms(sp.Piecewise):
        for _, cond in piece.args:
            for rel in cond.atoms(sp.core.relational.Relational):
                edges.add(float(rel.rhs))
    return edges


@pytest.mark.parametrize(
    "model", [LinearContact(), DeadZone(), SmoothDeadZone(0.05), fit_dead_zone()]
)
def test_backlash_kinks_are_the_edges_of_its_piecewise_expression(model):
    # Reference: each model's own SymPy expression; the dead zone's edges are +-1.
    x = sp.Symbol("x", real=True)
    assert set(model.kinks) == _condition_edges(model.expression(x))
    assert list(model.kinks) == sorted(model.kinks, reverse=True)  # upper edge first
    assert type(model) in BACKLASH_MODELS.values()
    if isinstance(model, DeadZone):
        assert model.kinks == (1.0, -1.0)
    else:
        assert model.kinks == ()


def test_the_contract_names_the_functions_the_module_defines(tmp_path):
    # Reference: emit/python.py writes these six functions into every module; a solver
    # asks the contract (Contract.provides), and a contract that lists a function the
    # module lacks is refused in one line.
    from gearsym.solver.contract import Contract, load_generated

    module = load_generated("reference_light")
    contract = Contract.of(module)
    assert contract.provides("mesh_force", "static_mesh_force")
    assert not contract.provides("no_such_function")
    for name in contract.functions:
        assert callable(getattr(module, name))
    path = tmp_path / "lacking.py"
    text = Path(module.__file__).read_text().replace("def mesh_force(", "def _gone(")
    path.write_text(text)
    with pytest.raises(ValueError, match="lists mesh_force, which the module does not define"):
        Contract.of(load_generated(path))
