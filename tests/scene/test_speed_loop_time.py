"""The driven-speed loop's time constant is at least two filter constants (spec 1.6.4): a fuzzed `control.tau` of
4.5e-30 s (loop gains ~ 1/tau^2) made a BDF run of band-4dof crawl past the fuzz test's 60 s; now it is a clear
error naming the key, checked when the scene is read."""
import pytest

from cvtfem.errors import InputError
from cvtfem.scene.loader import load_scene


@pytest.mark.parametrize("control", [{"tau": 4.49e-30}, {"tau_omega": 0.006}])
def test_a_loop_faster_than_its_filter_names_the_key(control):
    with pytest.raises(InputError) as err:
        load_scene("band-4dof").replace({"cvt": {"control": control}})
    assert "cvt.control.tau" in str(err.value) and "tau_omega" in str(err.value) and "1.6.4" in str(err.value)


def test_two_filter_constants_are_enough():
    scene = load_scene("band-4dof").replace({"cvt": {"control": {"tau": 0.004, "tau_omega": 0.002}}})
    assert scene.cvt.control.tau == 2 * scene.cvt.control.tau_omega
