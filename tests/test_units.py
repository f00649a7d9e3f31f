"""The one table of file units (``robokin/_units.py``, issue 24: it was copied into
eight readers).

Oracles: the definitions (1 mm = 1e-3 m, 1 deg = pi/180 rad, math.radians) and the
table being read-only (a reader cannot change another's units).
"""

import math

import pytest

from robokin._units import ANGLE_UNITS, LENGTH_UNITS


def test_factors_are_the_definitions():
    assert dict(LENGTH_UNITS) == {"m": 1.0, "mm": 1e-3}
    assert ANGLE_UNITS["rad"] == 1.0 and ANGLE_UNITS["deg"] == math.radians(1.0)
    assert list(ANGLE_UNITS) == ["rad", "deg"]  # error messages list them in this order


def test_the_table_cannot_be_changed_by_a_reader():
    with pytest.raises(TypeError):
        LENGTH_UNITS["km"] = 1e3  # type: ignore[index]
    with pytest.raises(TypeError):
        ANGLE_UNITS["deg"] = 1.0  # type: ignore[index]
