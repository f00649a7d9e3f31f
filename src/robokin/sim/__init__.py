"""Physics co-simulation with MuJoCo (needs ``robokin[sim]``).

.. code-block:: python

    from robokin import sim

    xml = sim.to_mjcf(robot, scene=None)          # MJCF text, same FK as robokin
    res = sim.simulate(robot, traj, scene=None)   # .t .q .qd .tau .contacts ...
    inv = sim.inverse_dynamics(robot, traj)       # torques and power the plan needs

See ``docs/simulation.md``.
"""

from __future__ import annotations

from robokin.sim.decoupling import DecouplingCheck, check_decoupling
from robokin.sim.inverse import InverseDynamics, inverse_dynamics
from robokin.sim.mjcf import JointMap, MjcfExport, build_mjcf, to_mjcf, write_mjcf
from robokin.sim.servo import ServoGains, servo_gains
from robokin.sim.simulate import Contact, SimResult, simulate

__all__ = [
    "Contact",
    "DecouplingCheck",
    "InverseDynamics",
    "JointMap",
    "MjcfExport",
    "ServoGains",
    "SimResult",
    "build_mjcf",
    "check_decoupling",
    "inverse_dynamics",
    "servo_gains",
    "simulate",
    "to_mjcf",
    "write_mjcf",
]
