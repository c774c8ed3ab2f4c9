"""Units at the CLI boundary: speeds with an explicit unit to rad/s, clear errors otherwise."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.units import parse_speed, parse_speeds


def test_speed_parsing():
    assert parse_speed("4000rpm") == pytest.approx(4000 * np.pi / 30)
    assert parse_speed("10 rad/s") == 10.0
    assert parse_speeds("0:4000rpm:51")[-1] == pytest.approx(4000 * np.pi / 30)
    for bad in ("4000", "fast", "12furlongs"):
        with pytest.raises(InputError, match="--speed"):
            parse_speed(bad)
    with pytest.raises(InputError, match="--speeds"):
        parse_speeds("100:0rpm:5")
