"""The dispatcher checks options against each closed form's declared names.

Oracles: a family's declared ``options`` are exactly the keyword-only parameters of
its solver's ``__call__`` (read with ``inspect``, so a new parameter without a
declaration fails here); an undeclared option is an ``InputError`` naming it and
the accepted ones; a declared option reaches the solver (``compute_error`` fills
``error``, which agrees with FK); a ``TypeError`` raised inside a solver is not
turned into an option error.
"""

import inspect

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError
from robokin.kinematics.ik.analytic import detect as detect_mod

ARMS = ["ur5", "puma560", "scara", "qfmd010", "panda_j7_held", "generic_6r"]


def _robot(name):
    if name == "panda_j7_held":  # a Pieper arm: the Panda with joint 7 at 0
        panda = robokin.load("panda")
        return robokin.Robot(panda.chain.with_fixed({6: 0.0}), name=name)
    if name == "generic_6r":  # the general 6R elimination
        rows = [{"a": 0.1 * (k + 1), "alpha": 0.3 + 0.2 * k, "d": 0.05 * k, "theta": 0}
                for k in range(6)]
        return robokin.Robot.from_dh(rows, name=name)
    return robokin.load(name)


def _keyword_only(fn):
    return {p.name for p in inspect.signature(fn).parameters.values()
            if p.kind is inspect.Parameter.KEYWORD_ONLY}


@pytest.mark.parametrize("name", ARMS)
def test_declared_options_are_the_solvers_keyword_parameters(name):
    fam = robokin.ik.family(_robot(name))
    assert fam.solver is not None, fam.reason
    assert fam.options == _keyword_only(type(fam.solver).__call__)
    assert "compute_error" in fam.options


@pytest.mark.parametrize("name", ARMS)
def test_an_undeclared_option_is_an_input_error_naming_it(name):
    robot = _robot(name)
    T = robot.fk(np.full(robot.n, 0.3))
    fam = robokin.ik.family(robot)
    with pytest.raises(InputError, match=r"'max_restarts'.*compute_error") as info:
        robot.ik(T, max_restarts=3)
    assert info.value.argument == "options" and fam.name in str(info.value)
    # a declared option reaches the solver: the error column agrees with FK
    sols = robot.ik(T, compute_error=True)
    assert sols.error is not None and sols.valid.any()
    ok = sols.valid
    dp = np.linalg.norm(robot.fk(sols.q[ok])[..., :3, 3] - T[:3, 3], axis=-1)
    assert np.all(sols.error[ok] >= dp - 1e-12) and np.all(sols.error[ok] < 1e-8)
    # the numeric solver's options go with method="numeric"
    assert robot.ik(T, method="numeric", max_restarts=3, n_seeds=2).method == "numeric"


def test_a_type_error_inside_a_solver_propagates(monkeypatch):
    robot = robokin.load("ur5")
    T = robot.fk(np.full(6, 0.3))
    fam = robokin.ik.family(robot)

    def broken(self, *args, **kwargs):
        raise TypeError("unexpected keyword argument 'x' (a bug inside the solver)")

    monkeypatch.setattr(detect_mod.SixRSolver, "__call__", broken)
    assert isinstance(fam.solver, detect_mod.SixRSolver)
    with pytest.raises(TypeError, match="a bug inside the solver"):
        robot.ik(np.stack([T, T]), compute_error=True)
