"""The post processor's records and formatting (issue 27 item 4).

Oracles: scipy's from_euler rebuilding the rotation from the written angles (at the
special values: 0, +-90 gimbal lock, 180), the sign conventions stated in the
docstrings, the records' refusals.
"""

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from post_golden import GOLDEN, render_all
from robokin.exceptions import InputError
from robokin.trajectory.posts import KukaKrl, Move, ProgramJob, Target
from robokin.trajectory.posts.base import euler_deg, quaternion_wxyz

SPECIAL = [0.0, 90.0, -90.0, 180.0, -180.0, 45.0, 1e-9]


@pytest.mark.parametrize("seq", ["ZYX", "XYZ", "ZYZ"])
def test_euler_angles_rebuild_the_rotation(seq):
    rng = np.random.default_rng(5)
    triples = [(a, b, c) for a in SPECIAL for b in SPECIAL for c in (0.0, 30.0, -170.0)]
    R = Rotation.from_euler(seq, triples, degrees=True).as_matrix()
    R = np.concatenate([R, Rotation.random(50, random_state=rng).as_matrix()])
    angles = euler_deg(R, seq)
    back = Rotation.from_euler(seq, angles, degrees=True).as_matrix()
    # 1e-10: scipy's Euler angles 1e-9 deg from a gimbal lock carry ~3e-11 of error,
    # five orders below the 1e-4 deg the programs write
    np.testing.assert_allclose(back, R, atol=1e-10)
    assert euler_deg(R[0], seq).shape == (3,)


def test_euler_and_quaternion_text_have_one_sign_per_rotation():
    post = KukaKrl()
    assert post.euler(-180.0) == post.euler(180.0) == "180.0000"
    assert post.euler(-179.99996) == "180.0000" and post.euler(-179.9) == "-179.9000"
    assert post.angle(-1e-9) == "0.0000" and post.length(-4e-4) == "0.000"
    # half turns about z: w = 0 up to noise; the text is the same whatever the noise
    for noise in (1e-17, -1e-17, 0.0):
        R = Rotation.from_rotvec([0, 0, np.pi + noise]).as_matrix()
        q = quaternion_wxyz(R)
        assert post.quaternion(q, 8) == ["0.00000000", "0.00000000", "0.00000000",
                                         "1.00000000"]
        assert post.quaternion(-q, 8) == post.quaternion(q, 8)
    q = quaternion_wxyz(Rotation.random(20, random_state=1).as_matrix())
    assert (q[:, 0] >= 0).all()
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0)


def test_target_orientations_given_or_computed_agree():
    R = Rotation.from_euler("xyz", [10, -80, 170], degrees=True).as_matrix()
    plain = Target(1, np.zeros(6), np.zeros(3), R)
    given = Target(1, np.zeros(6), np.zeros(3), R, orientations={
        s: euler_deg(R, s) for s in ("ZYX", "XYZ", "ZYZ")} | {"wxyz": quaternion_wxyz(R)})
    for seq in ("ZYX", "XYZ", "ZYZ"):
        np.testing.assert_allclose(plain.euler(seq), given.euler(seq), atol=1e-12)
    np.testing.assert_allclose(plain.quaternion(), given.quaternion(), atol=1e-15)
    assert not given.orientations["ZYX"].flags.writeable


def test_records_refuse_bad_values():
    t = Target(1, np.zeros(6), np.zeros(3), np.eye(3))
    assert not t.joints.flags.writeable
    with pytest.raises(InputError, match="kind"):
        Move("circular", t, 0.5)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"fraction of the maximum speed in \(0, 1\]"):
        Move("joint", t, 20.0)
    with pytest.raises(InputError, match="speed"):
        Move("linear", t, 0.0)
    with pytest.raises(InputError, match="zone"):
        Move("linear", t, 100.0, zone=-1.0)
    with pytest.raises(InputError, match="position"):
        Target(1, np.zeros(6), [0, 0, np.nan], np.eye(3))
    with pytest.raises(InputError, match="at least one move"):
        ProgramJob("p", ())
    with pytest.raises(InputError, match="integer 0..9"):
        KukaKrl(angle_decimals=10)


def test_render_refuses_an_illegal_name_or_the_wrong_axis_count():
    t = Target(1, np.zeros(6), np.zeros(3), np.eye(3))
    with pytest.raises(InputError, match="not a legal KUKA KRL name"):
        KukaKrl().render(ProgramJob("two words", (Move("joint", t, 0.5),)))
    t7 = Target(1, np.zeros(7), np.zeros(3), np.eye(3))
    with pytest.raises(InputError, match="drive 6 axes; target 1 has 7"):
        KukaKrl().render(ProgramJob("p", (Move("joint", t7, 0.5),)))


def test_every_dialect_writes_the_golden_programs():
    """Oracle: tests/data/posts/golden.json, the programs the six dialects wrote before
    their shared skeleton moved into base.py (issue 24): byte for byte, so a refactor
    of the dialect classes cannot change a program a controller loads."""
    want = json.loads(GOLDEN.read_text())
    got = render_all()
    assert sorted(got) == sorted(want)
    for key in want:
        assert got[key] == want[key], key
