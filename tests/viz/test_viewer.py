"""The live viser viewer: scene contents, playback, IK snapping, and a real browser."""

from __future__ import annotations

import inspect
import urllib.request

import numpy as np
import pytest

import robokin
from browser_shots import orange_fraction, require_chromium, screenshot_until

pytest.importorskip("viser")  # the viewer extra; robokin's own module must import
from robokin.viz.viewer import RobotViewer  # noqa: E402


class _Report:
    """A collision report shaped like ``collision.check``'s, for 50 samples."""

    def __init__(self, tool: np.ndarray):
        self.min_distance = 0.0
        self.collides = True
        self.collisions = [(20, 29, "wrist_3", "table")]
        self.distances = np.linspace(0.2, 0.0, 50)
        self.closest_points = np.stack([tool, tool + [0.0, 0.0, -0.1]], axis=1)


def _motion(m: int = 50) -> np.ndarray:
    s = np.linspace(0.0, 1.0, m)[:, None]
    return np.array([0.0, -1.2, 1.4, -1.8, -1.57, 0.0]) + s * np.array(
        [1.2, 0.4, -0.4, 0.2, 0, 0.5]
    )


@pytest.fixture
def ur5():
    return robokin.load("ur5")


def test_binds_to_loopback_by_default(ur5):
    assert inspect.signature(RobotViewer).parameters["host"].default == "127.0.0.1"
    with RobotViewer(ur5, port=0) as v:
        assert v.url == f"http://127.0.0.1:{v.port}"
        page = urllib.request.urlopen(v.url, timeout=10).read()
        assert b"<html" in page.lower()


def test_free_robot_sliders_and_tool_pose(ur5):
    bare = ur5.replace(
        geometry=None
    )  # no shapes: links drawn as capsules along the chain
    with RobotViewer(bare, port=0) as v:
        assert v.free
        q = np.array([0.3, -1.0, 1.2, -0.5, 0.4, 0.2])
        v.set_configuration(q, move_target=True)
        T = ur5.fk(q)
        np.testing.assert_allclose(v._tool.position, T[:3, 3], atol=1e-9)
        np.testing.assert_allclose(v._target.position, T[:3, 3], atol=1e-9)
        slider_q = v._slider_q()
        np.testing.assert_allclose(slider_q, q, atol=1e-9)
        assert f"{T[0, 3] * 1000:.1f}" in v._pose_md.content
        # The drawn links end at the tool: the last capsule's far end is the tool point.
        seg = v._segments[-1]
        d = np.asarray(seg.position) - T[:3, 3]
        assert np.linalg.norm(d) == pytest.approx(0.5 * seg.height, abs=1e-9)


def test_geometry_shapes_follow_the_link_frames(ur5):
    assert ur5.geometry is not None
    q = np.array([0.3, -1.0, 1.2, -0.5, 0.4, 0.2])
    with RobotViewer(ur5, port=0) as v:
        v.set_configuration(q)
        assert v._segments == []  # drawn from the geometry, not the chain capsules
        frames = ur5.fk_all(q)
        for i, node in v._frame_nodes.items():
            if i < frames.shape[0]:
                np.testing.assert_allclose(node.position, frames[i, :3, 3], atol=1e-9)
        assert len(v._frame_nodes) >= ur5.n


def test_dragging_the_target_snaps_to_the_nearest_ik_solution(ur5):
    q_goal = np.array([0.5, -1.1, 1.3, -0.9, 0.7, 0.3])
    T = ur5.fk(q_goal)
    sols = ur5.ik(T)
    assert np.any(sols.valid)
    with RobotViewer(ur5, port=0) as v:
        v.set_configuration(q_goal + 0.05)
        assert v.snap_to_target(T)
        np.testing.assert_allclose(ur5.fk(v.q), T, atol=1e-8)
        # Nearest to where the arm was: the branch it started on.
        np.testing.assert_allclose(v.q, q_goal, atol=1e-6)
        far = np.eye(4)
        far[:3, 3] = [5.0, 0.0, 0.0]
        q_before = v.q.copy()
        assert not v.snap_to_target(far)
        np.testing.assert_array_equal(v.q, q_before)
        assert "IK" in v._status.content


def test_playback_shows_collisions_and_closest_segment(ur5):
    q = _motion(50)
    rep = _Report(ur5.fk(q)[:, :3, 3])
    with RobotViewer(ur5, q, report=rep, port=0) as v:
        assert not v.free
        v.show_frame(10)
        np.testing.assert_allclose(v.q, q[10])
        assert tuple(v._link_nodes[0][0].color) != (225, 30, 30)
        np.testing.assert_allclose(v._closest.points[0], rep.closest_points[10])
        assert f"distance {rep.distances[10] * 1000:.1f} mm" in v._status.content
        v.show_frame(25)
        assert all(tuple(h.color) == (225, 30, 30) for h, _ in v._link_nodes)
        assert "COLLISION" in v._status.content and "table" in v._status.content
        v.show_time(0.005 * 40 + 1e-9)
        assert v.frame == 40
        assert tuple(v._link_nodes[0][0].color) != (225, 30, 30)


def test_viewer_page_renders_the_robot_in_chromium(ur5, tmp_path):
    require_chromium()
    with RobotViewer(ur5, _motion(50), port=0) as v:
        v.show_frame(25)
        clients = []
        v.server.on_client_connect(lambda client: clients.append(client.client_id))
        # Screenshots in wall time until the links are drawn (software WebGL and a
        # busy machine can take a while to receive and draw the scene).
        img = screenshot_until(
            v.url, tmp_path / "profile",
            lambda im: orange_fraction(im[150:700, 0:650]) > 5e-4,
            size=(1000, 700), webgl=True, timeout=150.0,
        )
        view3d = img[150:700, 0:650]  # left of the GUI panel, below the notices
    # The page loaded its script and connected back over the websocket.
    assert len(clients) >= 1
    assert img.shape == (700, 1000, 3)
    assert view3d.std() > 8.0  # not a blank canvas
    assert orange_fraction(view3d) > 5e-4  # the arm's links


BALL_SCENE_YAML = """
name: ball cell
units: {length: mm, angle: deg}
tool:
  tcp: {xyz: [0, 0, 100]}
  shapes:
    - {name: tip, type: sphere, radius: 20, xyz: [0, 0, 100]}
objects:
  - {name: ball, type: sphere, radius: 10, xyz: [%f, %f, %f]}
"""


def test_playback_draws_the_real_reports_closest_segment(ur5, tmp_path):
    # Tool sphere (r 20 mm) at the TCP, a ball (r 10 mm) 60 mm beyond it along
    # the tool axis: the closest segment is 30 mm long and ends on the ball.
    pytest.importorskip("coal")
    from robokin import collision

    q = _motion(5)
    flange = ur5.fk(q[2])
    c = flange[:3, 3] + 0.16 * flange[:3, 2]
    (tmp_path / "cell.yaml").write_text(BALL_SCENE_YAML % tuple(1000 * c))
    sc = collision.Scene.load(tmp_path / "cell.yaml")
    rep = collision.check(ur5, sc, q)
    with RobotViewer(sc.attach(ur5), q, scene=sc, report=rep, port=0) as v:
        v.show_frame(2)
        a, b = np.asarray(v._closest.points[0], dtype=float)
        assert np.linalg.norm(b - a) == pytest.approx(0.03, abs=1e-5)
        assert np.linalg.norm(b - c) == pytest.approx(0.01, abs=1e-5)
        assert "distance 30.0 mm" in v._status.content
    with pytest.raises(robokin.InputError, match="report"):
        RobotViewer(sc.attach(ur5), q[:3], scene=sc, report=rep, port=0)


# ---------------------------------------------------- issue 15: the websocket Origin
def _connect(url: str, origin: str | None):
    """Open the viewer's websocket as a browser page at ``origin`` would."""
    import viser
    from websockets.sync.client import connect

    return connect(url.replace("http://", "ws://"), origin=origin, open_timeout=10,
                   subprotocols=[f"viser-v{viser.__version__}"], proxy=None)


def test_a_page_from_another_origin_cannot_connect(ur5):
    from websockets.exceptions import InvalidStatus

    with RobotViewer(ur5, port=0) as v:
        for origin in ("http://evil.example", f"http://evil.example:{v.port}",
                       f"http://127.0.0.1:{v.port + 1}", "null",
                       f"https://attacker.test:{v.port}"):
            with pytest.raises(InvalidStatus) as exc:
                _connect(v.url, origin)
            assert exc.value.response.status_code == 403, origin


def test_the_viewers_own_page_and_local_programs_connect_and_receive_the_scene(ur5):
    with RobotViewer(ur5, port=0) as v:
        for origin in (v.url, f"http://localhost:{v.port}", None):
            with _connect(v.url, origin) as ws:
                assert len(ws.recv(timeout=10)) > 0  # the scene starts streaming


def test_origin_rule():
    from robokin.viz._origin_guard import origin_allowed

    assert origin_allowed(None, "127.0.0.1", 8080)
    assert origin_allowed("http://127.0.0.1:8080", "127.0.0.1", 8080)
    assert origin_allowed("http://[::1]:8080", "::1", 8080)
    assert origin_allowed("http://192.168.1.5:8080", "192.168.1.5", 8080)
    assert origin_allowed("http://cell-pc:8080", "192.168.1.5", 8080, ["cell-pc"])
    for bad in ("http://evil.example:8080", "http://127.0.0.1:8081", "null",
                "file://", "http://127.0.0.1.evil.example:8080", "ws://127.0.0.1:8080",
                "http://127.0.0.1:99999"):
        assert not origin_allowed(bad, "127.0.0.1", 8080), bad


def test_other_viser_servers_in_the_process_are_left_alone(ur5):
    # While a viewer (with its origin guard) runs, a plain viser server of the same
    # process still accepts a page from any origin and streams it the scene; the
    # viewer itself refuses that origin (403).
    import viser
    from websockets.exceptions import InvalidStatus

    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        with RobotViewer(ur5, port=0) as v:
            with pytest.raises(InvalidStatus) as exc:
                _connect(v.url, "http://elsewhere.test")
            assert exc.value.response.status_code == 403
            with _connect(f"http://127.0.0.1:{server.get_port()}",
                          "http://elsewhere.test") as ws:
                assert len(ws.recv(timeout=10)) > 0
    finally:
        server.stop()


def test_view_passes_every_viewer_keyword(ur5):
    """``view`` takes RobotViewer's keywords (declared once, issue 24); before,
    ``dt``, ``verbose`` and ``allowed_hosts`` were refused. Oracle: the viewer's
    timing follows ``dt`` (50 samples without times span 49 * dt) and the
    served page is the viewer's."""
    from robokin.viz import viewer as viewer_mod

    q = _motion()
    with viewer_mod.view(ur5, q, block=False, play=False, port=0, dt=0.02,
                         verbose=False, allowed_hosts=("robot-cell",)) as v:
        assert v.motion.t[-1] == pytest.approx(49 * 0.02)
        assert not v.free
        assert b"<html" in urllib.request.urlopen(v.url, timeout=10).read().lower()
    with pytest.raises(TypeError, match="frame_rate"):
        viewer_mod.view(ur5, q, block=False, frame_rate=30)  # type: ignore[call-arg]
