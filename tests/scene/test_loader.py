"""Scene loading: presets, overrides, immutability and one test per class of bad input."""
from __future__ import annotations

import math
import tomllib

import pytest

from cvtfem.errors import InputError
from cvtfem.scene.loader import load_scene, preset_names, scene_from_dict
from cvtfem.scene.node import thaw

ROTOR = """
[[material]]
name = "steel"
E = 2.11e11
G = 8.12e10
rho = 7810.0

[[shaft]]
length = 0.25
outer_diameter = 0.05
material = "steel"
repeat = 6

[[bearing]]
node = 0
kxx = 1e6
kyy = 1e6
"""


def rotor(**changes):
    data = tomllib.loads(ROTOR)
    for path, value in changes.items():
        table, index, key = path.split("__")
        data[table][int(index)][key] = value
    return data


def reference_with(path: str, value):
    """The reference preset with one key (dotted path under `cvt`) replaced."""
    keys = path.split(".")
    override: dict = {}
    node = override
    for key in keys[:-1]:
        node = node.setdefault(key, {})
    node[keys[-1]] = value
    return scene_from_dict({"preset": "reference_cvt", **override})


def test_reference_preset_values():
    scene = load_scene("reference_cvt")
    assert scene.kind == "cvt"
    chain = scene.cvt.chain
    assert chain.n_pins == 84 and chain.n_pins % chain.lacing_period == 0
    assert math.isclose(scene.cvt.regime.input_speed * 30 / math.pi, 3500.0, rel_tol=1e-12)
    # spec section 9 derived geometry: mean pitch 9.0 mm gives a 0.756 m chain
    mean = chain.long_fraction * chain.pitch_long + (1 - chain.long_fraction) * chain.pitch_short
    assert math.isclose(chain.n_pins * mean, 0.756, rel_tol=1e-9)


def test_every_preset_loads():
    for name in preset_names():
        assert load_scene(name).data["preset"] == name


def test_preset_override_merges_tables():
    scene = reference_with("cvt.regime.torque", 150.0)
    assert scene.cvt.regime.torque == 150.0
    assert scene.cvt.regime.ratio == 2.4  # untouched keys of the same table survive
    assert scene.cvt.chain.n_pins == 84


def test_a_layer_naming_another_method_drops_the_method_options_below_it(tmp_path):
    """variant-e's solver options (strang-friction's scheme) do not reach a scene that names another method, in a file
    or through ``replace``; the same method keeps them, and options given with the new method are that method's."""
    e = load_scene("variant-e")
    assert e.solver.method == "strang-friction" and "scheme=multirate-rk4" in e.solver.options
    radau = tmp_path / "radau.toml"
    radau.write_text('preset = ["variant-e", "regime-stationary"]\n[solver]\nmethod = "Radau"\n')
    assert load_scene(radau).solver.options == ()
    assert e.replace({"solver": {"method": "dumka3"}}).solver.options == ()
    assert e.replace({"solver": {"method": "strang-friction", "rtol": 1e-2}}).solver.options == e.solver.options
    own = e.replace({"solver": {"method": "gbs", "options": ["stages=2"]}})
    assert own.solver.options == ("stages=2",)


def test_scene_is_immutable():
    scene = load_scene("reference_cvt")
    with pytest.raises(AttributeError):
        scene.cvt.chain.n_pins = 3
    with pytest.raises(TypeError):
        scene.cvt.chain["n_pins"] = 3  # type: ignore[index]


def test_toml_round_trip():
    scene = load_scene("reference_cvt")
    again = scene_from_dict(tomllib.loads(scene.to_toml()))
    assert thaw(again.data) == thaw(scene.data)


def test_rotor_scene_of_only_tables():
    scene = scene_from_dict(tomllib.loads(ROTOR))
    assert scene.kind == "rotor"
    assert scene.bearing[0].kyx == 0.0  # unspecified coefficients are zero


def _message(excinfo) -> str:
    return str(excinfo.value)


def test_unknown_key_suggests():
    with pytest.raises(InputError) as e:
        reference_with("cvt.chain.n_pin", 84)
    assert "`cvt.chain.n_pin`" in _message(e) and "did you mean `n_pins`" in _message(e)


def test_wrong_type():
    with pytest.raises(InputError) as e:
        reference_with("cvt.chain.n_pins", 84.5)
    assert "`cvt.chain.n_pins`" in _message(e) and "integer" in _message(e) and "84.5" in _message(e)
    with pytest.raises(InputError, match="must be a number"):
        reference_with("cvt.chain.mass", "heavy")
    with pytest.raises(InputError, match="true or false"):
        reference_with("cvt.effects.friction", 1)


def test_non_physical_values():
    with pytest.raises(InputError) as e:
        reference_with("cvt.chain.mass", -1.5)
    assert "`cvt.chain.mass`" in _message(e) and "> 0" in _message(e) and "-1.5" in _message(e)
    with pytest.raises(InputError, match=r"`shaft\[0\].length` must be >= 1e-06 m"):   # 1 um .. 100 m (issue 18)
        scene_from_dict(rotor(shaft__0__length=0.0))


def test_choice_suggests():
    with pytest.raises(InputError) as e:
        reference_with("cvt.geometry.sheave_profile", "toroidl")
    assert "one of 'conical', 'toroidal'" in _message(e) and "did you mean `toroidal`" in _message(e)


def test_missing_required_key():
    data = tomllib.loads(ROTOR)
    del data["material"][0]["rho"]
    with pytest.raises(InputError) as e:
        scene_from_dict(data)
    assert "`material[0].rho` is required" in _message(e)


@pytest.mark.parametrize("path, value, fragment", [
    ("cvt.geometry.r_min", 0.09, "`cvt.geometry.r_max` must be greater than `r_min`"),
    ("cvt.chain.n_pins", 85, "multiple of `lacing_period`"),
    ("cvt.chain.n_pins", 150, "closes on the pulleys"),
    ("cvt.control.i_max", 0.05, "`cvt.control.i_max` must be greater than `i_min`"),
    ("cvt.geometry.torus_radius", 0.05, "`cvt.geometry.torus_radius` must exceed |r + torus_offset| over r_min..r_max"),
])
def test_inconsistent_geometry(path, value, fragment):
    with pytest.raises(InputError) as e:
        reference_with(path, value)
    assert fragment in _message(e)


def test_cross_table_rotor_checks():
    with pytest.raises(InputError, match=r"`shaft\[0\].inner_diameter` must be smaller"):
        scene_from_dict(rotor(shaft__0__inner_diameter=0.06))
    with pytest.raises(InputError, match=r"`bearing\[0\].node` must be a shaft node, 0..6"):
        scene_from_dict(rotor(bearing__0__node=7))
    with pytest.raises(InputError, match=r"did you mean `steel`"):
        scene_from_dict(rotor(shaft__0__material="stel"))


def test_effect_needs_model():
    with pytest.raises(InputError, match="pin_bending"):
        scene_from_dict({"preset": "reference_cvt", "cvt": {"model": "band-4dof", "effects": {
            "shaft_elasticity": False}}})


def test_unknown_preset_and_cycles():
    with pytest.raises(InputError, match="did you mean `reference_cvt`"):
        scene_from_dict({"preset": "reference_cv"})
    with pytest.raises(InputError, match="exactly one machine"):
        scene_from_dict({"title": "empty"})


def test_replace_on_every_kind():
    rotor_scene = scene_from_dict(tomllib.loads(ROTOR))
    assert rotor_scene.replace({"solver": {"t_end": 2.0}}).solver.t_end == 2.0
    cvt = load_scene("reference_cvt").replace({"cvt": {"regime": {"torque": 100.0}}})
    assert cvt.cvt.regime.torque == 100.0 and cvt.cvt.chain.n_pins == 84
