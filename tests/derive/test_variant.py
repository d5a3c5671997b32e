"""Scene variants: [features] changed in memory, checked like a file, with their own hash."""

import pytest
from gearsym.derive import InputError, derive_model, load_target, variant
from gearsym.derive.input.scene import builtin_root
from gearsym.derive.model import inputs_hash


@pytest.fixture(scope="module")
def light():
    return load_target(builtin_root() / "reference-light.toml")


def test_a_variant_changes_only_what_it_names_and_gets_its_own_hash(light):
    v = variant(light, "light-no-harmonics", stiffness_harmonics=0)
    assert v.features.stiffness_harmonics == 0 and light.features.stiffness_harmonics == 3
    assert v.features.backlash == light.features.backlash
    assert v.parameters == light.parameters
    assert inputs_hash(v) != inputs_hash(light)
    # the same change under the same name is the same model
    again = variant(light, "light-no-harmonics", stiffness_harmonics=0)
    assert inputs_hash(v) == inputs_hash(again)
    model = derive_model(v)
    assert model.name == "light_no_harmonics"
    assert not any(p.startswith(("kc_", "ks_")) for p in model.parameter_names)


def test_changing_the_backlash_kind_drops_the_other_kinds_keys(light):
    # reference-light.toml sets backlash_order etc. for its polynomial; a dead zone has none
    v = variant(light, "light-dead-zone", backlash="dead-zone")
    assert v.features.backlash.kind == "dead-zone"
    assert variant(light, "light-p5", backlash_order=5).features.backlash.order == 5


@pytest.mark.parametrize(
    "changes, fragment",
    [
        ({"stiffnes_harmonics": 2}, "did you mean 'stiffness_harmonics'"),
        ({"backlash_order": 4}, "must be odd"),
        ({"backlash": "cubic"}, "backlash"),
    ],
)
def test_bad_variants_are_refused_like_bad_files(light, changes, fragment):
    with pytest.raises(InputError, match=fragment):
        variant(light, "bad", **changes)
