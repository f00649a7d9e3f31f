"""figaroh (>= 1.0) wired to bench_calibration's synthetic data (learned from its API docs).

figaroh needs a URDF (written by robokin's ``to_urdf``), a unified YAML config, a
measurement CSV in its column layout (``x1 y1 z1 [phix1 ...]`` and one column per
joint) and a ``BaseCalibration`` subclass with a cost function; the base frame
and the marker offset are estimated (``full_params``). Used by
``bench_calibration.py`` only.
"""

from __future__ import annotations

import contextlib
import io
import logging
import tempfile
import time
from pathlib import Path

import figaroh  # noqa: F401  (ImportError here: not installed)
import numpy as np
import yaml


def calibrate_figaroh(d, kind: str, runs: int):
    """Calibrate with figaroh; returns (predict(q) -> (N, 3) points, t_min, t_max)."""
    from figaroh.calibration.base_calibration import BaseCalibration
    from figaroh.calibration.calibration_tools import calc_updated_fkm
    from figaroh.tools.load_robot import load_robot

    from robokin.spatial import rpy_from_matrix

    logging.getLogger("figaroh").setLevel(logging.ERROR)
    folder = Path(tempfile.mkdtemp(prefix="figaroh-bench-"))
    urdf = folder / "robot.urdf"
    urdf.write_text(d.nominal.to_urdf())
    robot = load_robot(str(urdf), load_by_urdf=True)
    model = robot.model
    joints = [n for n in model.names[1:]]
    tool_frame = model.frames[len(model.frames) - 1].name
    pose = kind == "pose"
    cols = {"x1": d.m[:, 0, 3] if pose else d.m[:, 0],
            "y1": d.m[:, 1, 3] if pose else d.m[:, 1],
            "z1": d.m[:, 2, 3] if pose else d.m[:, 2]}
    if pose:
        rpy = rpy_from_matrix(d.m)  # figaroh's phi: roll, pitch, yaw (pinocchio rpy)
        cols |= {"phix1": rpy[:, 0], "phiy1": rpy[:, 1], "phiz1": rpy[:, 2]}
    for k, name in enumerate(joints):
        cols[name] = d.q[:, k]
    lines = [",".join(cols)] + [",".join(repr(float(cols[c][i])) for c in cols)
                                for i in range(len(d.q))]
    (folder / "data.csv").write_text("\n".join(lines) + "\n")
    config = {
        "robot": {"name": d.nominal.name},
        "tasks": {"calibration": {
            "type": "calibration",
            "kinematics": {"base_frame": "universe", "tool_frame": tool_frame},
            "measurements": {"markers": [{"measurable_dof": [True] * 3 + [pose] * 3}],
                             "poses": {"base_pose": None, "tool_pose": None}},
            "parameters": {"calibration_level": "full_params"},
            "data": {"source_file": str(folder / "data.csv"),
                     "number_of_samples": len(d.q)},
        }},
    }
    (folder / "config.yaml").write_text(yaml.safe_dump(config))

    class Calibration(BaseCalibration):
        def __init__(self, *args):
            super().__init__(*args)
            # set by figaroh's own robot subclasses, not by the config reader
            self.calib_config["known_baseframe"] = False
            self.calib_config["known_tipframe"] = False

        def cost_function(self, var):
            est = calc_updated_fkm(self.model, self.data, var, self.q_measured,
                                   self.calib_config)
            if not pose:
                return est - self.PEE_measured
            # its documented pose residual: the SE3 log map, world-frame positions
            return self._compute_logmap_residuals(self.PEE_measured, est,
                                                  position_frame="world")

    def solve():
        cal = Calibration(robot, str(folder / "config.yaml"))
        with contextlib.redirect_stdout(io.StringIO()):
            cal.initialize()
            cal.solve(enable_logging=False)
        return cal

    times = []
    cal = None
    for _ in range(runs):
        t = time.perf_counter()
        cal = solve()
        times.append(time.perf_counter() - t)
    assert cal is not None

    def predict(q):
        cfg = dict(cal.calib_config)
        cfg["NbSample"] = len(q)
        est = calc_updated_fkm(cal.model, cal.data, cal.var_, q, cfg)
        return np.asarray(est)[: 3 * len(q)].reshape(3, len(q)).T

    return predict, min(times), max(times)
