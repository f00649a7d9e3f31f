"""The Robot is immutable (issue 14, item 4): assignment and deletion raise."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import robokin
from robokin.exceptions import FrozenError, InputError


@pytest.fixture
def ur5():
    return robokin.load("ur5")


@pytest.mark.parametrize("name", ["name", "chain", "geometry", "meta", "source",
                                  "actuators", "path", "new_attribute"])
def test_assigning_or_deleting_any_attribute_raises(ur5, name):
    with pytest.raises(FrozenError, match=rf"Robot is immutable: cannot change "
                                          rf"'{name}'; .*replace"):
        setattr(ur5, name, "x")
    with pytest.raises(AttributeError):  # FrozenError is an AttributeError too
        delattr(ur5, name)
    assert ur5.name == "ur5"


def test_meta_and_arrays_are_read_only(ur5):
    with pytest.raises(TypeError):
        ur5.meta["document"] = {}
    scara = robokin.load("scara")
    with pytest.raises(ValueError):
        scara.actuator_limits[0, 0] = 0.0
    with pytest.raises(ValueError):
        ur5.limits[0, 0] = 0.0


def test_changes_go_through_copies(ur5):
    T = np.eye(4)
    T[2, 3] = 0.1
    moved = ur5.with_tool(T)
    renamed = ur5.replace(name="ur5-cell-3")
    assert renamed.name == "ur5-cell-3" and ur5.name == "ur5"
    np.testing.assert_allclose(moved.fk(np.zeros(6))[:3, 3] - ur5.fk(np.zeros(6))[:3, 3],
                               ur5.fk(np.zeros(6))[:3, 2] * 0.1, atol=1e-15)
    assert renamed.chain is ur5.chain  # nothing copied that did not change
    with pytest.raises(InputError, match="not a Robot attribute"):
        ur5.replace(nmae="typo")


def test_pickle_and_copy_rebuild_an_equal_robot(ur5):
    for other in (pickle.loads(pickle.dumps(ur5)), copy.deepcopy(ur5), copy.copy(ur5)):
        assert other.name == ur5.name and dict(other.meta).keys() == ur5.meta.keys()
        q = np.array([0.1, -0.5, 0.7, 0.2, -0.3, 0.4])
        np.testing.assert_array_equal(other.fk(q), ur5.fk(q))
        with pytest.raises(FrozenError):
            other.name = "x"


def test_no_class_in_the_mro_hooks_attribute_lookup():
    """No ``__getattr__`` on Robot or its bases (issue 24 re-measure, robot.fk speed).

    Oracle: CPython routes every attribute read of a class with ``__getattr__``
    through ``slot_tp_getattr_hook`` and never specialises its loads, which added
    ~0.07 us to each one-configuration ``robot.fk(q)`` (0.30 against 0.23 us).
    The removed-method hint (``robot.plot``) is a descriptor instead.
    """
    hooked = [c.__name__ for c in robokin.Robot.__mro__ if "__getattr__" in vars(c)]
    assert hooked == []


def test_removed_plot_names_its_replacement(ur5):
    with pytest.raises(AttributeError, match=r"'plot'.*robokin\.viz\.plot_robot"):
        ur5.plot  # noqa: B018
    assert not hasattr(ur5, "plot")
    with pytest.raises(AttributeError, match="'no_such_thing'$"):
        ur5.no_such_thing  # noqa: B018


@pytest.mark.parametrize("q, reason", [
    (np.zeros(5), r"shape"), (np.array([0, 0, 0, np.nan, 0, 0]), r"finite"),
    ([[0.0] * 6, "abc"], r""), ("abc", r""),
])
def test_fk_of_bad_input_names_q(ur5, q, reason):
    """The one-configuration fast path keeps every check: the error names ``q``."""
    with pytest.raises(InputError, match=rf"\bq\b.*{reason}"):
        ur5.fk(q)
