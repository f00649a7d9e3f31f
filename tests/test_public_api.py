"""The curated top-level API: every ``__all__`` name imports, the contract names exist."""

import importlib

import robokin


def test_every_all_name_imports():
    for name in robokin.__all__:
        assert getattr(robokin, name) is not None, name
    assert robokin.__all__ == sorted(robokin.__all__), "keep __all__ sorted"
    assert len(set(robokin.__all__)) == len(robokin.__all__), "no name twice"


def test_lazy_subpackages_resolve():
    assert robokin.ik is importlib.import_module("robokin.kinematics.ik")
    assert hasattr(robokin.ik, "family")


def test_errors_share_one_root():
    for exc in (
        robokin.ModelError,
        robokin.InputError,
        robokin.UnreachableError,
        robokin.MissingExtraError,
    ):
        assert issubclass(exc, robokin.RobokinError)
    assert issubclass(robokin.ModelError, ValueError)
    assert issubclass(robokin.MissingExtraError, ImportError)


def test_builtin_names_match_design():
    assert robokin.robots.names() == sorted(
        [
            "ur5",
            "aubo_i5",
            "puma560",
            "puma560_modified",
            "panda",
            "scara",
            "qfmd010",
            "improved_dh_arm",
        ]
    )


def test_actuator_limits_must_match_the_motors():
    import numpy as np
    import pytest

    scara = robokin.load("scara")
    with pytest.raises(robokin.InputError, match=r"actuator_limits.*\(4, 2\)"):
        scara.replace(actuator_limits=np.zeros((3, 2)))
    ur5 = robokin.load("ur5")
    with pytest.raises(robokin.InputError, match="without an actuator map"):
        ur5.replace(actuator_limits=np.zeros((6, 2)))
