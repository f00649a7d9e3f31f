"""Physics co-simulation with MuJoCo (needs ``robokin[sim]``).

.. code-block:: python

    from robokin import sim

    xml = sim.to_mjcf(robot, scene=None)          # MJCF text, same FK as robokin
    res = sim.simulate(robot, traj, scene=None)   # .t .q .qd .tau .contacts ...
    inv = sim.inverse_dynamics(robot, traj)       # torques and power the plan needs

See ``docs/simulation.md``.
"""

from __future__ import annotations

from robokin.sim.mjcf import JointMap, MjcfExport, build_mjcf, to_mjcf, write_mjcf
from robokin.sim.servo import ServoGains, servo_gains

__all__ = [
    "JointMap",
    "MjcfExport",
    "ServoGains",
    "build_mjcf",
    "servo_gains",
    "to_mjcf",
    "write_mjcf",
]
