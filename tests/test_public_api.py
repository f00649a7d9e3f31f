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


_IMPORT_PROBE = """
import json, sys
import robokin
print(json.dumps(sorted(sys.modules)))
"""
#: What ``import robokin`` must leave unloaded: the file readers (and PyYAML under
#: them), the IK solvers, the kernels' declarations, and every heavy dependency.
_NOT_ON_IMPORT = ("yaml", "scipy", "pydantic", "matplotlib", "typer", "rich",
                  "typing_extensions", "robokin.io", "robokin.kinematics.ik",
                  "robokin.robots", "robokin._native._declare", "robokin.model.dh",
                  "robokin.trajectory", "robokin.collision", "robokin.viz")


def test_import_robokin_loads_only_the_core():
    """``import robokin`` stays light (issue 24 re-measure: 0.22-0.26 s, was 0.10-0.12).

    Oracle: the module table of a fresh interpreter after ``import robokin`` holds
    none of :data:`_NOT_ON_IMPORT` (nor their submodules); before the fix it held
    PyYAML, the io readers and the IK solvers (71 robokin modules; now 20). The public
    names still resolve afterwards.
    """
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", _IMPORT_PROBE], capture_output=True,
                         text=True, check=True, timeout=120)
    loaded = json.loads(out.stdout)
    heavy = [m for m in loaded
             if any(m == p or m.startswith(p + ".") for p in _NOT_ON_IMPORT)]
    assert heavy == []
    assert "robokin.robot" in loaded and "robokin.kinematics.forward" in loaded


_FIRST_CALLS_PROBE = """
import json, sys
import numpy as np, robokin
panda = robokin.load("panda")
q = np.array([0.0, np.pi / 6, 0.0, -np.pi / 2, 0.0, np.pi / 3, 0.0])
sm = panda.self_motion(panda.fk(q))
near = np.abs(sm.sample(np.array([0.0]))[0] - q).max(axis=-1)
ur5 = robokin.load("ur5")
sols = ur5.ik(ur5.fk(np.array([0.1, -0.4, 0.5, -0.2, 0.3, 0.6])))
print(json.dumps([float(np.nanmin(near)), len(sols), sorted(sys.modules)]))
"""


def test_first_self_motion_and_ik_calls_do_not_import_scipy():
    """A first ``self_motion`` on a 7R arm (the Panda's ready pose) and a first 6R
    ``ik`` stay off scipy (session 23: the Pieper set-up's held-joint rotation went
    through ``scipy.spatial``, 175 modules and ~0.16 s of the first call's 0.19 s;
    now Rodrigues' formula in ``robokin.spatial``). Oracle: the fresh interpreter's
    module table, and the ready pose among the manifold's rows at q7 = 0.
    """
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", _FIRST_CALLS_PROBE], capture_output=True,
                         text=True, check=True, timeout=120)
    near, n_ik, loaded = json.loads(out.stdout)
    assert near < 1e-12 and n_ik >= 1
    assert [m for m in loaded if m == "scipy" or m.startswith("scipy.")] == []


def test_public_names_resolve_after_a_bare_import():
    """Every ``__all__`` name and lazy subpackage works from a fresh interpreter."""
    import subprocess
    import sys

    probe = ("import numpy as np, robokin\n"
             "from robokin import (InputError, MissingExtraError, ModelError, RobokinError,\n"
             "                     Robot, UnreachableError, load, save, __version__)\n"
             "for m in ('trajectory', 'collision', 'robots', 'spatial', 'kinematics',\n"
             "          'model', 'io'):\n"
             "    assert getattr(robokin, m).__name__ == 'robokin.' + m\n"
             "SolutionSet = robokin.kinematics.ik.solutions.SolutionSet\n"
             "r = robokin.load('ur5')\n"
             "q = np.array([0.1, -0.4, 0.5, -0.2, 0.3, 0.6])\n"
             "s = r.ik(r.fk(q))\n"
             "assert type(s) is SolutionSet\n"
             "assert np.abs(s.nearest(q) - q).max() < 1e-9\n"
             "assert robokin.ik.family(r).name\n"
             "print('ok')\n")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=120)
    assert out.stdout.strip() == "ok", out.stderr
