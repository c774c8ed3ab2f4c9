"""The elastic shaft's element count is bounded in the schema: a scaled `shaft_elements` (found by the input fuzz
test: 8e12 elements asked scipy for a 349 TiB index array) is a clear error naming the key, not an allocation."""
import pytest

from cvtfem.errors import InputError
from cvtfem.scene.loader import load_scene, scene_from_dict


def test_shaft_elements_above_the_bound_name_the_key():
    with pytest.raises(InputError) as err:
        scene_from_dict({"preset": "reference_cvt", "cvt": {"driving": {"shaft_elements": 8 * 10 ** 12}}})
    assert "cvt.driving.shaft_elements" in str(err.value) and "500" in str(err.value)


def test_shaft_elements_at_the_bound_load():
    scene = scene_from_dict({"preset": "reference_cvt", "cvt": {"driven": {"shaft_elements": 500}}})
    assert scene.cvt.driven.shaft_elements == 500 and load_scene("reference_cvt").cvt.driven.shaft_elements == 8
