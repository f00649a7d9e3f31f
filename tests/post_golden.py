"""The golden programs: every dialect, several option sets, one seam and one sweep.

``python tests/post_golden.py`` rewrites tests/data/posts/golden.json from
the current code (do it only when a change to the output is intended, and say so).
"""

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from robokin import trajectory  # noqa: E402
from robokin.spatial import pose_from_xyz_rpy  # noqa: E402
from robokin.trajectory.posts import render_program  # noqa: E402
from vendor_arms import CREATED, PROFILES, PathResult, kuka_like  # noqa: E402

GOLDEN = Path(__file__).resolve().parent / "data" / "posts" / "golden.json"
PPD = (1000.0, 1200.0, 900.0, 700.0, 800.0, 500.0)
_PROFILE = {"kuka_krl": "kuka", "abb_rapid": "abb", "fanuc_tp": "fanuc",
            "yaskawa_inform": "yaskawa", "staubli_val3": "staubli", "kawasaki_as": "kuka"}
#: (dialect, options, program_job keywords, which motion)
VARIANTS = {
    "abb_rapid": ("abb_rapid", {}, {}, "seam"),
    "abb_rapid_sweep": ("abb_rapid", {"tool_mass": 2.5}, {}, "sweep"),
    "fanuc_tp": ("fanuc_tp", {}, {}, "seam"),
    "fanuc_tp_frames": ("fanuc_tp", {"set_frames": True, "cnt": 20}, {"cartesian": True},
                        "sweep"),
    "kawasaki_as": ("kawasaki_as", {}, {}, "seam"),
    "kawasaki_as_sweep": ("kawasaki_as", {}, {"cartesian": True}, "sweep"),
    "kuka_krl": ("kuka_krl", {}, {}, "seam"),
    "kuka_krl_sweep": ("kuka_krl", {"ptp_approximation": 30.0}, {"cartesian": True},
                       "sweep"),
    "staubli_val3": ("staubli_val3", {}, {}, "seam"),
    "staubli_val3_sweep": ("staubli_val3", {"rotation_speed": 90.0}, {}, "sweep"),
    "yaskawa_inform": ("yaskawa_inform", {}, {}, "seam"),
    "yaskawa_inform_pulses": ("yaskawa_inform", {"pulses_per_degree": PPD}, {}, "sweep"),
    "yaskawa_inform_rectan": ("yaskawa_inform", {"pl": 5}, {"cartesian": True}, "sweep"),
}


def motions():
    """The seam (a process path in a work object) and a sampled joint sweep."""
    arm = kuka_like()
    start = np.radians([5, -70, 95, 10, 60, -20])
    T1 = arm.fk(start).copy()
    T1[:3, 3] += [0.05, 0.18, -0.06]
    tr = trajectory.cartesian_line(arm, start, T1, 2.0, dt=0.1)
    wobj = pose_from_xyz_rpy([0.3, -0.1, 0.2], np.radians([5, -3, 30]))
    sweep = trajectory.quintic(np.radians([10, -80, 100, 20, 40, -30]),
                               np.radians([-35, -60, 80, -40, 70, 120]), 0.8, 0.004)
    seam = PathResult(tr.q, free_angle=np.zeros(len(tr.q)))
    return arm, {"seam": (seam, {"work_object": wobj, "stride": 2}),
                 "sweep": (sweep, {"tolerance": 2e-3})}


def render_all():
    """``{variant: {file: text}}`` from the current code."""
    arm, motion = motions()
    out = {}
    for key, (dialect, options, kw, which) in VARIANTS.items():
        m, extra = motion[which]
        prog = render_program(arm, m, dialect, options=options, name="golden",
                              profile=PROFILES[_PROFILE[dialect]], created=CREATED,
                              **kw, **extra)
        out[key] = dict(prog.texts)
    return out


if __name__ == "__main__":
    GOLDEN.write_text(json.dumps(render_all(), indent=1, sort_keys=True) + "\n")
