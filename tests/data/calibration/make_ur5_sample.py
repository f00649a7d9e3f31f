"""How ur5_calibration.conf was made (kept for provenance; not run by the tests).

A UR5 whose identifiable parameters are off nominal by ~0.5 mm / 0.05 deg (seed
357), its standard DH table read off its joint axes (common normals, as
robokin.calibration._frames builds DH rows), and
the difference to the published UR5 table written as the controller's
calibration.conf writes it. Like real UR deltas, d2..d4 come out at hundreds of
metres: the calibrated axes 2-4 are a fraction of a milliradian from parallel.
"""

from pathlib import Path

import numpy as np

from robokin.calibration import synthetic
from robokin.calibration._frames import Row, joint_frames, row_matrix, rows_from_axes
from robokin.calibration.ur import ur_nominal
from robokin.spatial import invert


def main() -> None:
    nominal = ur_nominal("ur5")
    true = synthetic.perturb(nominal, np.random.default_rng(357)).robot
    W = joint_frames(true.chain)
    rows, D = rows_from_axes(W, parallel_tol=0.0)  # plain DH: every row a common normal
    # the frames are at zero joint motion; a DH theta is at q = 0: add the offsets
    rows = [Row("dh", r.theta + j.offset, r.d, r.a, r.alpha)
            for r, j in zip(rows, true.chain.joints)]
    flange = W[-1] @ true.chain.frame_offsets[-1] @ true.chain.link_offsets[-1]
    last = invert(D[-1]) @ flange  # on axis 6: Rz(theta6) Tz(d6)
    rows.append(Row("dh", float(np.arctan2(last[1, 0], last[0, 0])), float(last[2, 3]),
                    0.0, 0.0))
    assert np.allclose(row_matrix(rows[-1]), last, atol=1e-12)
    rows[-1] = Row("dh", rows[-1].theta + true.chain.joints[-1].offset, rows[-1].d, 0.0, 0.0)
    nom = [dict(theta=0.0, d=d, a=a, alpha=al) for d, a, al in zip(
        (0.089159, 0, 0, 0.10915, 0.09465, 0.0823), (0, -0.425, -0.39225, 0, 0, 0),
        (np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0))]
    lines = ["[mounting]"]
    for key in ("theta", "a", "d", "alpha"):
        deltas = [getattr(r, key) - n[key] for r, n in zip(rows, nom)]
        lines.append(f"delta_{key} = [ " + ", ".join(f"{v:.17g}" for v in deltas) + "]")
    lines.append("calibration_status = 2 # 0 == notInitialized / 1 == notLinearised / "
                 "2 == Linearised")
    out = Path(__file__).with_name("ur5_calibration.conf")
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
