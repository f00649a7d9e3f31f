"""Named coupling constructors: the ball-screw / ball-spline shaft, gears, screws,
mimic joints and the palletizer's parallelogram (issue 5)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import robokin
from robokin.exceptions import ModelError
from robokin.model.coupling import (
    AffineMap,
    BallScrewSpline,
    Dependency,
    actuator_map,
    ball_screw_spline,
    block_diagonal,
    coupling_from_dependencies,
    direct,
    gear,
    mimic,
    parallelogram,
    screw,
)
from robokin.spatial import roty, rotz, trans

DEG = math.pi / 180.0
T_PAPER = np.arange(0.0, 5.0 + 1e-9, 0.5)  # t = 0, 0.5 ... 5 s

# The tensor-method SCARA paper's three test motions: lift l4 [mm] with theta3 = 36 t
# [deg], and its equation (17) motor angles [deg] (i = 1, j = 15, lead 20 mm).
PAPER_MOTIONS = [
    ("l4 = t^2", lambda t: t**2, lambda t: 36 * t - 18 * t**2),
    ("l4 = 60 sin(pi t/10)", lambda t: 60 * np.sin(np.pi * t / 10),
     lambda t: 36 * t - 1080 * np.sin(np.pi * t / 10)),
    ("l4 = 10 t", lambda t: 10 * t, lambda t: -144 * t),
]


@pytest.mark.parametrize(("label", "lift_mm", "phi3_deg"), PAPER_MOTIONS,
                         ids=[m[0] for m in PAPER_MOTIONS])
def test_ball_screw_spline_reproduces_the_papers_equation_17(label, lift_mm, phi3_deg):
    shaft = BallScrewSpline(lead=0.020, i=1, j=15)
    theta3 = np.radians(36 * T_PAPER)
    phi = shaft.motors_from_shaft(theta3, lift_mm(T_PAPER) / 1000.0)
    assert phi.shape == (T_PAPER.size, 2)
    np.testing.assert_allclose(np.degrees(phi[:, 0]), phi3_deg(T_PAPER), atol=1e-9)
    np.testing.assert_allclose(np.degrees(phi[:, 1]), 540 * T_PAPER, atol=1e-9)
    # ... and back: the shaft's rotation and lift.
    back = shaft.shaft_from_motors(phi)
    np.testing.assert_allclose(back[:, 0], theta3, atol=1e-12)
    np.testing.assert_allclose(back[:, 1] * 1000.0, lift_mm(T_PAPER), atol=1e-9)


def test_ball_screw_spline_map_is_the_papers_inverse_formula(rng):
    # q = A phi: theta3 = phi4 / j, l4 = (phi4 / j - phi3 / i) * l / 360 (deg, mm).
    lead_mm, i, j = 20.0, 3.0, 15.0
    amap = ball_screw_spline(lead_mm / 1000, i, j)
    phi_deg = rng.uniform(-2000, 2000, (50, 2))
    q = amap.apply(np.radians(phi_deg))
    np.testing.assert_allclose(np.degrees(q[:, 0]), phi_deg[:, 1] / j, atol=1e-9)
    l4_mm = (phi_deg[:, 1] / j - phi_deg[:, 0] / i) * lead_mm / 360
    np.testing.assert_allclose(q[:, 1] * 1000, l4_mm, atol=1e-9)


def test_lift_sign_reverses_only_the_lift():
    a = BallScrewSpline(0.02, 1, 15)
    b = BallScrewSpline(0.02, 1, 15, lift_sign=-1)
    phi = np.radians([100.0, 300.0])
    qa, qb = a.shaft_from_motors(phi), b.shaft_from_motors(phi)
    assert qa[0] == qb[0] and qa[1] == -qb[1] != 0
    with pytest.raises(ModelError, match="lift_sign must be"):
        BallScrewSpline(0.02, lift_sign=2)
    with pytest.raises(ModelError, match="lead must not be zero"):
        BallScrewSpline(0.0)
    with pytest.raises(ModelError, match="j must not be zero"):
        ball_screw_spline(0.02, 1, 0)


def test_the_papers_motion_table_vertical_rotation_helix():
    """N1 (screw nut), N2 (spline nut): N2 = 0 lifts only, N1 = N2 turns only,
    N1 = 0 is a helix whose lead is the screw lead."""
    lead = 0.020
    shaft = BallScrewSpline(lead, i=1, j=15)
    turn = 2 * np.pi
    n1 = np.array([turn, 0.0, turn, 0.0, -0.5 * turn, 0.0])
    n2 = np.array([0.0, turn, turn, 0.0, 0.5 * turn, 0.5 * turn])
    mo = shaft.motion(n1, n2)
    assert mo.kind.tolist() == ["vertical", "helix", "rotation", "still", "combined", "helix"]
    # vertical only: no rotation, one lead down per screw-nut turn
    assert mo.rotation[0] == 0.0
    assert mo.lift[0] == pytest.approx(-lead)
    # helix with the screw's lead: one lead of lift per shaft turn
    assert mo.rotation[1] == pytest.approx(turn)
    assert mo.lift[1] == pytest.approx(lead)
    assert mo.lead[1] == pytest.approx(lead) and mo.lead[5] == pytest.approx(lead)
    # rotation only
    assert mo.rotation[2] == pytest.approx(turn) and mo.lift[2] == 0.0
    # the general case is a helix of another lead: lead (N2 - N1) / N2
    assert mo.lead[4] == pytest.approx(2 * lead)
    assert np.isnan(mo.lead[0])


def test_the_motion_table_holds_through_the_motor_reductions():
    # Motor angles: N1 = phi3 / i, N2 = phi4 / j. The same table through the 2x2 map.
    i, j, lead = 2.0, 15.0, 0.02
    amap = ball_screw_spline(lead, i, j)
    rot, lift = amap.apply(np.array([[i * 1.0, 0.0]]))[0]  # N1 = 1 rad, N2 = 0
    assert rot == 0.0 and lift == pytest.approx(-lead / (2 * np.pi))
    rot, lift = amap.apply(np.array([[i * 1.0, j * 1.0]]))[0]  # N1 = N2
    assert rot == pytest.approx(1.0) and lift == pytest.approx(0.0, abs=1e-15)
    rot, lift = amap.apply(np.array([[0.0, j * 2 * np.pi]]))[0]  # N1 = 0, one turn
    assert rot == pytest.approx(2 * np.pi) and lift == pytest.approx(lead)


def test_gear_and_screw_constructors():
    g = gear(100.0, offset=0.1)
    np.testing.assert_allclose(g.apply(np.array([2 * np.pi * 100])), [2 * np.pi + 0.1])
    s = screw(0.005, ratio=2.0)  # 5 mm/rev screw behind a 2:1 belt
    np.testing.assert_allclose(s.apply(np.array([4 * np.pi])), [0.005])  # 2 motor turns
    np.testing.assert_allclose(gear(-50).apply(np.array([50.0])), [-1.0])
    with pytest.raises(ModelError, match="ratio must not be zero"):
        gear(0)
    with pytest.raises(ModelError, match="lead must be finite"):
        screw(float("inf"))


def test_block_diagonal_and_compose_and_inverse_map(rng):
    m = block_diagonal(direct(2), gear(10.0, offset=0.3), ball_screw_spline(0.02, 1, 15))
    assert (m.n_out, m.n_in) == (5, 5)
    x = rng.normal(size=(7, 5))
    y = m.apply(x)
    np.testing.assert_allclose(y[:, :2], x[:, :2])
    np.testing.assert_allclose(y[:, 2], x[:, 2] / 10 + 0.3)
    np.testing.assert_allclose(m.inverse(y), x, atol=1e-12)
    np.testing.assert_allclose(m.inverse_map().apply(y), x, atol=1e-12)
    np.testing.assert_allclose(m.inverse_rate(m.apply_rate(x)), x, atol=1e-12)
    np.testing.assert_allclose(m.compose(m.inverse_map()).apply(y), y, atol=1e-12)
    with pytest.raises(ModelError, match="cannot compose"):
        m.compose(direct(2))


def test_affine_map_rank_deficient_inverse_names_the_map():
    m = AffineMap([[1.0, 2.0], [2.0, 4.0]], [0.0, 0.0])
    assert not m.is_invertible
    with pytest.raises(ModelError, match=r"the demo matrix .* rank 1 < 2"):
        m.inverse(np.zeros(2), what="demo")


def test_affine_map_residual_finds_joint_values_outside_the_range():
    # two joints follow one motor: q = (phi, 2 phi)
    m = AffineMap([[1.0], [2.0]], [0.0, 0.0])
    assert m.residual(np.array([1.0, 2.0])) == pytest.approx(0.0)
    assert m.residual(np.array([1.0, 0.0])) > 0.5


def test_actuator_map_assembles_drives_by_joint_name():
    names = ["j1", "rot", "lift", "j2"]
    amap = actuator_map(names, [("j2", gear(5.0)), (["rot", "lift"], ball_screw_spline(0.02)),
                                ("j1", direct())])
    # motors: m1 -> j2, (m2, m3) -> shaft, m4 -> j1
    q = amap.apply(np.array([5.0, 0.0, 0.0, 0.7]))
    np.testing.assert_allclose(q, [0.7, 0.0, 0.0, 1.0])
    with pytest.raises(ModelError, match=r"joint\(s\) \['j2'\] are driven by no actuator"):
        actuator_map(names, [("j1", direct()), (["rot", "lift"], ball_screw_spline(0.02))])
    with pytest.raises(ModelError, match="'j1' is already driven"):
        actuator_map(names, [("j1", direct()), ("j1", gear(2))])
    with pytest.raises(ModelError, match="unknown joint 'nope'"):
        actuator_map(names, [("nope", direct())])
    with pytest.raises(ModelError, match="its map has 2 output"):
        actuator_map(names, [("j1", direct(2))])


# ------------------------------------------------------------------ dependent joints
def test_mimic_is_urdf_multiplier_and_offset():
    dep = mimic("theta2", multiplier=-2.0, offset=0.25)
    assert dep == Dependency({"theta2": -2.0}, 0.25)
    c = coupling_from_dependencies(["theta1", "theta2", "follower"], ["theta1", "theta2"],
                                   {"follower": dep})
    np.testing.assert_allclose(c.apply(np.array([0.3, 0.5])), [0.3, 0.5, -0.75])
    assert dep.row_fields() == {"depends": {"theta2": -2.0}, "depends_offset": 0.25}


def test_coupling_from_dependencies_errors():
    with pytest.raises(ModelError, match="unknown coordinate 'x'"):
        coupling_from_dependencies(["a", "b"], ["a"], {"b": mimic("x")})
    with pytest.raises(ModelError, match="'b' is neither a coordinate nor dependent"):
        coupling_from_dependencies(["a", "b"], ["a"], {})
    with pytest.raises(ModelError, match=r"unknown joint\(s\) \['zz'\]"):
        coupling_from_dependencies(["a"], ["a"], {"zz": mimic("a")})


def _qfmd010_parallelogram():
    return parallelogram(["theta2", "theta3"], relative=["theta2", "forearm"], level="level")


def test_parallelogram_builds_the_qfmd010_coupling():
    robot = robokin.load("qfmd010")
    chain = robot.chain
    assert (robot.n, robot.n_chain) == (4, 5)
    deps = _qfmd010_parallelogram()
    assert set(deps) == {"forearm", "level"}
    built = coupling_from_dependencies([j.name for j in chain.joints],
                                       [c.name for c in chain.coordinates], deps)
    assert built.allclose(chain.coupling, atol=0.0)
    # forearm = theta3 - theta2, level = -theta3 (and the pitch sum is constant)
    np.testing.assert_array_equal(
        chain.coupling.matrix,
        [[1, 0, 0, 0], [0, 1, 0, 0], [0, -1, 1, 0], [0, 0, -1, 0], [0, 0, 0, 1]])


def _qfmd010_reference(q):
    """The QFMD010 paper's closed form (robot file's source): tool pose in metres."""
    q1, q2, q3, q4 = q
    r = 0.700 * np.cos(q2) + 0.650 * np.cos(q3)
    p3 = np.array([-np.sin(q1) * r, np.cos(q1) * r, -0.900 + 0.700 * np.sin(q2)
                   + 0.650 * np.sin(q3)])
    R = rotz(q1 + q4)[:3, :3]
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p3 + R @ np.array([0.0, 0.250, 0.0])
    return T


def test_palletizer_tool_stays_level_across_its_joint_ranges():
    robot = robokin.load("qfmd010")
    lim = robot.limits
    grids = [np.linspace(lo, hi, 7) for lo, hi in lim]
    q = np.stack(np.meshgrid(*grids, indexing="ij"), axis=-1).reshape(-1, 4)
    T = robot.fk(q)
    # the tool z axis is the world's vertical everywhere: the tool stays level
    np.testing.assert_allclose(T[:, :3, 2], np.broadcast_to([0, 0, 1], (len(q), 3)),
                               atol=1e-12)
    # its heading is theta1 + theta4 whatever the pitch angles
    np.testing.assert_allclose(T[:, :3, :3], rotz(q[:, 0] + q[:, 3])[:, :3, :3], atol=1e-12)
    for k in range(0, len(q), 97):
        np.testing.assert_allclose(T[k], _qfmd010_reference(q[k]), atol=1e-12)


def test_without_the_parallelogram_the_tool_would_tilt():
    # Control: replace the level joint's dependency by a mimic of nothing (held at 0):
    # the tool then tilts with theta3, so the level test above can fail.
    robot = robokin.load("qfmd010")
    chain = robot.chain
    deps = _qfmd010_parallelogram()
    deps["level"] = Dependency({}, 0.0)
    broken = robot.replace(chain=chain.replace(coupling=coupling_from_dependencies(
        [j.name for j in chain.joints], [c.name for c in chain.coordinates], deps)))
    T = broken.fk(np.array([0.0, 0.1, 0.3, 0.0]))
    assert abs(T[2, 2] - 1.0) > 1e-3


def test_qfmd010_is_expressible_with_the_named_constructor():
    deps = _qfmd010_parallelogram()
    mm = 1e-3

    def rz(name, dep=None):
        row = {"op": "rz", "joint": "revolute", "name": name}
        return row | (dep.row_fields() if dep is not None else {})

    ops = [
        rz("theta1"), {"op": "tz", "value": -900 * mm}, {"op": "ry", "value": 90 * DEG},
        rz("theta2"), {"op": "ty", "value": 700 * mm},
        rz("forearm", deps["forearm"]), {"op": "ty", "value": 650 * mm},
        rz("level", deps["level"]), {"op": "ry", "value": -90 * DEG},
        rz("theta4"), {"op": "ty", "value": 250 * mm},
    ]
    coords = [{"name": f"theta{k}", "joint": "revolute"} for k in range(1, 5)]
    built = robokin.Robot.from_elementary(ops, coordinates=coords)
    ref = robokin.load("qfmd010")
    q = np.random.default_rng(7).uniform(-1, 1, (40, 4))
    np.testing.assert_allclose(built.fk(q), ref.fk(q), atol=1e-12)
    # a hand-built chain with the same elementary operators
    for qq in q[:5]:
        q1, q2, q3, q4 = qq
        T = (rotz(q1) @ trans([0, 0, -0.9]) @ roty(np.pi / 2) @ rotz(q2) @ trans([0, 0.7, 0])
             @ rotz(q3 - q2) @ trans([0, 0.65, 0]) @ rotz(-q3) @ roty(-np.pi / 2) @ rotz(q4)
             @ trans([0, 0.25, 0]))
        np.testing.assert_allclose(built.fk(qq), T, atol=1e-12)


def test_parallelogram_options_and_errors():
    d = parallelogram(["a"], level="flange", level_offset=0.5)
    assert d == {"flange": Dependency({"a": -1.0}, 0.5)}
    three = parallelogram(["a1", "a2", "a3"], relative=["r1", "r2", "r3"], level=None)
    assert three["r1"] == Dependency({"a1": 1.0})
    assert three["r3"] == Dependency({"a3": 1.0, "a2": -1.0})
    assert "level" not in three
    with pytest.raises(ModelError, match="at least one pitch"):
        parallelogram([])
    with pytest.raises(ModelError, match="2 pitch coordinate"):
        parallelogram(["a", "b"], relative=["x"])


nonzero = st.floats(0.05, 50.0) | st.floats(-50.0, -0.05)


@settings(max_examples=60, deadline=None)
@given(lead=st.floats(0.001, 0.1), i=nonzero, j=nonzero, sign=st.sampled_from([1, -1]),
       phi=st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)))
def test_ball_screw_spline_round_trip_property(lead, i, j, sign, phi):
    shaft = BallScrewSpline(lead, i, j, lift_sign=sign)
    phi = np.array(phi)
    q = shaft.shaft_from_motors(phi)
    np.testing.assert_allclose(shaft.affine_map().apply(phi), q, rtol=1e-12, atol=1e-12)
    back = shaft.motors_from_shaft(q[0], q[1])
    np.testing.assert_allclose(back, phi, rtol=1e-9, atol=1e-9 * (1 + abs(phi).max()))
