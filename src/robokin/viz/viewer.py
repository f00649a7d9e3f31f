"""The live 3D web viewer (viser): robot, scene, tool frame, trajectory playback.

.. code-block:: python

    from robokin.viz.viewer import RobotViewer

    viewer = RobotViewer(robot, trajectory, scene=scene, report=report)
    print(viewer.url)        # open it in a browser
    viewer.wait()            # serve until Ctrl-C

It shows the robot from its geometry (or, without one, capsules along its chain),
the scene's objects, the tool frame, and:

* with a trajectory: a time slider and play/pause; with a collision report the
  closest-distance segment per sample and colliding samples in red;
* without one (a free robot): a slider per joint with the tool pose shown live,
  and a draggable tool target that snaps the arm to the nearest IK solution.

The server binds to 127.0.0.1 unless told otherwise: it has no authentication.
It refuses websocket connections from other web pages (an ``Origin`` other than
its own page: see :mod:`robokin.viz._origin_guard`), so a site open in the
browser cannot read the scene. Needs ``robokin[viewer]`` (viser).
"""

from __future__ import annotations

import math
import threading
import time
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np
from typing_extensions import Unpack

from robokin.exceptions import MissingExtraError
from robokin.viz._common import COLORS, drawing, scene_shapes, skeleton

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["RobotViewer", "view"]


def _viser():
    try:
        import viser
    except ImportError:  # pragma: no cover - the extra is installed in CI
        raise MissingExtraError("viser", "viewer") from None
    return viser


def _wxyz(R: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return np.array([w, x, y, z])


def _rotation_z_to(d: np.ndarray) -> np.ndarray:
    """A rotation matrix whose z axis is the unit vector ``d``."""
    z = d / max(np.linalg.norm(d), 1e-12)
    a = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(a, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _fmt_pose(T: np.ndarray) -> str:
    from robokin.spatial import rpy_from_matrix

    xyz = T[:3, 3] * 1000.0
    rpy = np.degrees(rpy_from_matrix(T))
    return (
        f"xyz [mm]: {xyz[0]:.1f}, {xyz[1]:.1f}, {xyz[2]:.1f}  \n"
        f"rpy [deg]: {rpy[0]:.2f}, {rpy[1]:.2f}, {rpy[2]:.2f}"
    )


def _pose_of(handle: Any) -> np.ndarray:
    """The pose (4, 4) [m] of a viser scene handle (its ``wxyz`` and ``position``)."""
    from scipy.spatial.transform import Rotation

    w, x, y, z = handle.wxyz
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat([x, y, z, w]).as_matrix()
    T[:3, 3] = handle.position
    return T


class RobotViewer:
    """A viser server showing one robot (see the module docstring).

    Args:
        robot: The robot, as placed in the world (for a scene with a base or a
            tool, pass ``scene.attach(robot)``).
        trajectory: Joint samples (m, n), an object with ``.t`` and ``.q``, a
            single configuration (n,), or None (a free robot at zero).
        scene: A ``robokin.collision.Scene`` whose objects are drawn, or None.
        report: The collision report of ``trajectory`` (``collision.check``).
        host: Interface to bind; 127.0.0.1 (this machine only) by default.
        port: TCP port; 0 picks a free one.
        dt: Sample period [s] when the trajectory has no times.
        verbose: Let viser print its banner.
        allowed_hosts: Host names whose pages may connect besides the loopback
            names and the bound address (e.g. this machine's name when bound
            to a LAN interface).

    Attributes:
        server: The ``viser.ViserServer``.
        q: The configuration shown now, (n,).
        frame: The trajectory sample shown now.
    """

    def __init__(
        self,
        robot: Robot,
        trajectory: Any = None,
        *,
        scene: Any = None,
        report: Any = None,
        host: str = "127.0.0.1",
        port: int = 8080,
        dt: float = 0.005,
        verbose: bool = False,
        allowed_hosts: tuple[str, ...] = (),
    ) -> None:
        """Start the viewer server and draw the robot (see the class docstring)."""
        viser = _viser()
        self.robot = robot
        traj = trajectory
        if traj is not None and not hasattr(traj, "q") and np.ndim(traj) == 1:
            traj = np.asarray(traj, dtype=float)[None, :]
        view = drawing(robot, traj, report, dt=dt)
        self.motion, self.report = view.motion, view.report
        self.free = trajectory is None or self.motion.q.shape[0] == 1
        m = self.motion.q.shape[0]
        if port == 0:
            port = _free_port(host)
        from robokin.viz._origin_guard import guarded_start

        with guarded_start(allowed_hosts):
            self.server = viser.ViserServer(host=host, port=port, verbose=verbose)
        self.host, self.port = host, int(self.server.get_port())
        self._lock = threading.RLock()
        self._busy = False
        self._playing = False
        self._stop = threading.Event()
        self.frame = 0
        self.q = self.motion.q[0].copy()
        self._shapes = view.shapes
        self._skeleton = view.skeleton_only
        self._red = False
        sk = skeleton(robot, self.motion.q[: min(m, 1)])
        self._radius = sk.radius
        self._scale = max(sk.scale, 0.3)
        self._build_scene(scene)
        self._build_robot(sk)
        self._build_gui()
        self.set_configuration(self.q)
        if not self.free:
            self._player = threading.Thread(target=self._play_loop, daemon=True)
            self._player.start()

    # ---------------------------------------------------------------- basics
    @property
    def url(self) -> str:
        """The page to open, e.g. ``http://127.0.0.1:8080``."""
        return f"http://{self.host}:{self.port}"

    def close(self) -> None:
        """Stop playback and the server."""
        self._stop.set()
        self.server.stop()

    def wait(self) -> None:
        """Serve until interrupted (Ctrl-C)."""
        try:
            while not self._stop.is_set():
                time.sleep(0.2)
        except KeyboardInterrupt:
            pass
        finally:
            self.close()

    def __enter__(self) -> RobotViewer:
        """The viewer itself."""
        return self

    def __exit__(self, *exc: object) -> None:
        """Close the viewer."""
        self.close()

    # ----------------------------------------------------------------- scene
    def _add_shape(
        self, name: str, s: Any, color: tuple[int, int, int], pose: np.ndarray
    ):
        sc = self.server.scene
        kw = {"wxyz": _wxyz(pose[:3, :3]), "position": pose[:3, 3]}
        if s.kind == "box":
            return sc.add_box(name, color=color, dimensions=tuple(s.size), **kw)
        if s.kind == "cylinder":
            return sc.add_cylinder(
                name, radius=s.size[0], height=s.size[1], color=color, **kw
            )
        if s.kind == "sphere":
            return sc.add_icosphere(name, radius=s.size[0], color=color, **kw)
        if s.kind == "capsule":
            import trimesh

            mesh = trimesh.creation.capsule(height=s.size[1], radius=s.size[0])
            return sc.add_mesh_simple(
                name, mesh.vertices, mesh.faces, color=color, **kw
            )
        if s.kind == "mesh" and s.vertices is not None:
            return sc.add_mesh_simple(name, s.vertices, s.faces, color=color, **kw)
        return None

    def _build_scene(self, scene: Any) -> None:
        sc = self.server.scene
        sc.set_up_direction("+z")
        size = 3.0 * self._scale
        step = 10 ** math.floor(math.log10(size / 8))
        sc.add_grid(
            "/grid", width=size, height=size, cell_size=step, section_size=5 * step
        )
        self._scene_nodes: dict[str, tuple[Any, tuple[int, int, int]]] = {}
        for s in scene_shapes(scene):
            h = self._add_shape(f"/scene/{s.name}", s, s.color, np.asarray(s.pose))
            if h is not None:
                self._scene_nodes[s.name] = (h, s.color)
        self.server.initial_camera.position = (
            0.75 * self._scale,
            -0.75 * self._scale,
            0.55 * self._scale,
        )
        self.server.initial_camera.look_at = (0.0, 0.0, 0.2 * self._scale)

    def _build_robot(self, sk: Any) -> None:
        sc = self.server.scene
        r = self._radius
        self._link_nodes: list[tuple[Any, tuple[int, int, int]]] = []
        self._frame_nodes: dict[int, Any] = {}
        for i, s in self._shapes:
            if i not in self._frame_nodes:
                self._frame_nodes[i] = sc.add_frame(f"/robot/frame{i}", show_axes=False)
            h = self._add_shape(
                f"/robot/frame{i}/{s.name}", s, s.color, np.asarray(s.pose)
            )
            if h is not None:
                self._link_nodes.append((h, s.color))
        self._segments: list[Any] = []
        self._balls: list[Any] = []
        self._joints: list[Any] = []
        if self._skeleton:
            for k, _ in enumerate(sk.links):
                h = sc.add_cylinder(
                    f"/robot/link{k}", radius=r, height=1.0, color=COLORS.link
                )
                self._segments.append(h)
                self._link_nodes.append((h, COLORS.link))
            used = sorted({int(v) for v in sk.links.reshape(-1)})
            self._ball_index = used
            for k in used:
                h = sc.add_icosphere(f"/robot/ball{k}", radius=r, color=COLORS.link)
                self._balls.append(h)
                self._link_nodes.append((h, COLORS.link))
            for k, kind in enumerate(sk.joint_kinds):
                if kind == "prismatic":
                    h = sc.add_box(
                        f"/robot/joint{k}",
                        color=COLORS.joint,
                        dimensions=(1.6 * r, 1.6 * r, 3.2 * r),
                    )
                else:
                    h = sc.add_cylinder(
                        f"/robot/joint{k}",
                        radius=1.3 * r,
                        height=2.5 * r,
                        color=COLORS.joint,
                    )
                self._joints.append(h)
            sc.add_cylinder(
                "/robot/pedestal",
                radius=2.2 * r,
                height=r,
                color=COLORS.joint,
                position=sk.base[0, :3, 3] - sk.base[0, :3, 2] * 0.5 * r,
                wxyz=_wxyz(sk.base[0, :3, :3]),
            )
        self._links = sk.links
        L = 0.12 * self._scale
        self._tool = sc.add_frame("/tool", axes_length=L, axes_radius=0.06 * L)
        self._closest = None
        if self.report.closest is not None or self.report.track is not None:
            self._closest = sc.add_line_segments(
                "/closest",
                points=np.zeros((1, 2, 3)),
                colors=COLORS.distance,
                thickness=0.25 * r,
            )

    # ------------------------------------------------------------------- gui
    def _build_gui(self) -> None:
        gui = self.server.gui
        robot = self.robot
        gui.add_markdown(f"**{robot.name}** — robokin viewer")
        self._pose_md = gui.add_markdown("")
        self._status = gui.add_markdown("")
        self._time_slider = None
        if not self.free:
            m = self.motion.q.shape[0]
            t = self.motion.t
            with gui.add_folder("Trajectory"):
                self._play_button = gui.add_button("Play")
                self._time_slider = slider = gui.add_slider(
                    "time [s]",
                    min=float(t[0]),
                    max=float(t[-1]),
                    step=float(max((t[-1] - t[0]) / max(m - 1, 1), 1e-4)),
                    initial_value=float(t[0]),
                )
                self._speed = gui.add_slider(
                    "speed", min=0.1, max=4.0, step=0.1, initial_value=1.0
                )

            @self._play_button.on_click
            def _(_: Any) -> None:
                self.set_playing(not self._playing)

            @slider.on_update
            def _(_: Any) -> None:
                if not self._busy:
                    self.show_time(slider.value)

        self._joint_sliders = []
        lim = robot.limits
        with gui.add_folder("Joints", expand_by_default=self.free):
            for i, name in enumerate(robot.joint_names):
                rev = bool(robot.is_revolute[i])
                lo, hi = lim[i]
                if rev:
                    lo = max(lo, -2 * math.pi) if math.isfinite(lo) else -2 * math.pi
                    hi = min(hi, 2 * math.pi) if math.isfinite(hi) else 2 * math.pi
                    s = gui.add_slider(
                        f"{name} [deg]",
                        min=math.degrees(lo),
                        max=math.degrees(hi),
                        step=0.1,
                        initial_value=math.degrees(self.q[i]),
                        disabled=not self.free,
                    )
                else:
                    lo = lo if math.isfinite(lo) else -1.0
                    hi = hi if math.isfinite(hi) else 1.0
                    s = gui.add_slider(
                        f"{name} [mm]",
                        min=lo * 1000,
                        max=hi * 1000,
                        step=0.1,
                        initial_value=self.q[i] * 1000,
                        disabled=not self.free,
                    )
                self._joint_sliders.append((s, rev))

                @s.on_update
                def _(_: Any) -> None:
                    if not self._busy and self.free:
                        self.set_configuration(self._slider_q(), move_target=True)

        self._target = None
        if self.free:
            T = robot.fk(self.q)
            self._target = target = self.server.scene.add_transform_controls(
                "/target",
                scale=0.15 * self._scale,
                wxyz=_wxyz(T[:3, :3]),
                position=T[:3, 3],
            )

            @target.on_update
            def _(_: Any) -> None:
                if not self._busy:
                    self.snap_to_target(_pose_of(target))

    def _slider_q(self) -> np.ndarray:
        return np.array(
            [
                math.radians(s.value) if rev else s.value / 1000.0
                for s, rev in self._joint_sliders
            ]
        )

    # --------------------------------------------------------------- drawing
    def set_configuration(self, q: Any, *, move_target: bool = False) -> None:
        """Show the robot at ``q`` (n,) [rad, m]; update sliders and tool pose."""
        q = np.asarray(q, dtype=float).reshape(self.robot.n)
        with self._lock:
            self.q = q.copy()
            sk = skeleton(self.robot, q[None, :])
            if self._frame_nodes:
                from robokin.kinematics.forward import link_frames

                F = link_frames(self.robot.chain, q)
                for i, h in self._frame_nodes.items():
                    h.wxyz = _wxyz(F[i, :3, :3])
                    h.position = F[i, :3, 3]
            if self._skeleton:
                pts = sk.points[0]
                for h, (a, b) in zip(self._segments, self._links):
                    d = pts[b] - pts[a]
                    h.height = max(float(np.linalg.norm(d)), 1e-6)
                    h.wxyz = _wxyz(_rotation_z_to(d))
                    h.position = 0.5 * (pts[a] + pts[b])
                for h, k in zip(self._balls, self._ball_index):
                    h.position = pts[k]
                for h, P in zip(self._joints, sk.joint_frames[0]):
                    h.wxyz = _wxyz(P[:3, :3])
                    h.position = P[:3, 3]
            T = sk.tool[0]
            self._tool.wxyz = _wxyz(T[:3, :3])
            self._tool.position = T[:3, 3]
            self._pose_md.content = "**tool pose**  \n" + _fmt_pose(T)
            self._busy = True
            try:
                for (s, rev), v in zip(self._joint_sliders, q):
                    s.value = math.degrees(v) if rev else v * 1000.0
                if move_target and self._target is not None:
                    self._target.wxyz = _wxyz(T[:3, :3])
                    self._target.position = T[:3, 3]
            finally:
                self._busy = False

    def _set_red(self, red: bool, bodies: set[str]) -> None:
        if red == self._red and not red:
            return
        self._red = red
        for h, color in self._link_nodes:
            h.color = COLORS.collision if red else color
        for name, (h, color) in self._scene_nodes.items():
            h.color = COLORS.collision if name in bodies else color

    def show_frame(self, i: int) -> None:
        """Show trajectory sample ``i``: robot, closest segment, collision colour."""
        m = self.motion.q.shape[0]
        i = int(np.clip(i, 0, m - 1))
        self.frame = i
        self.set_configuration(self.motion.q[i])
        rep = self.report
        red = bool(rep.colliding[i])
        bodies = {n for a, b, x, y in rep.bodies if a <= i <= b for n in (x, y)}
        self._set_red(red, bodies)
        dist = None if rep.distance is None else float(rep.distance[i])
        if self._closest is not None:
            found = rep.closest_at([i])
            self._closest.visible = found is not None
            if found is not None:
                dist = float(found[0][0])
                self._closest.points = found[1][:1]
                color = COLORS.collision if red else COLORS.distance
                self._closest.colors = np.tile(
                    np.array(color, dtype=np.uint8), (1, 2, 1)
                )
        parts = [f"t = {self.motion.t[i]:.3f} s (sample {i + 1}/{m})"]
        if dist is not None:
            parts.append(f"distance {dist * 1000:.1f} mm")
        if red:
            parts.append("**COLLISION** " + ", ".join(sorted(bodies)))
        self._status.content = "  \n".join(parts)
        if self._time_slider is not None:
            self._busy = True
            try:
                self._time_slider.value = float(self.motion.t[i])
            finally:
                self._busy = False

    def show_time(self, t: float) -> None:
        """Show the sample at time ``t`` [s] (the last one at or before it)."""
        i = int(np.searchsorted(self.motion.t, t, side="right")) - 1
        self.show_frame(max(i, 0))

    def set_playing(self, on: bool) -> None:
        """Start or pause playback."""
        self._playing = bool(on) and not self.free
        if not self.free:
            self._play_button.label = "Pause" if self._playing else "Play"

    def _play_loop(self) -> None:
        t = self.motion.t
        clock = float(t[0])
        last = time.perf_counter()
        while not self._stop.is_set():
            time.sleep(1 / 30)
            now = time.perf_counter()
            if self._playing:
                clock += (now - last) * float(self._speed.value)
                if clock > t[-1]:
                    clock = float(t[0])
                self.show_time(clock)
            else:
                clock = float(t[self.frame])
            last = now

    # -------------------------------------------------------------------- IK
    def snap_to_target(self, T: np.ndarray) -> bool:
        """Move the arm to the IK solution for ``T`` nearest the current q.

        Returns:
            True when a solution was found; otherwise the arm stays and the
            status line says why.
        """
        try:
            sols = self.robot.ik(T, q_near=self.q)
            if not np.any(sols.valid):
                status = getattr(sols, "status", None)
                why = str(np.ravel(status)[0]) if status is not None else "no solution"
                self._status.content = f"IK: {why}"
                return False
            q = np.asarray(sols.nearest(self.q), dtype=float).reshape(self.robot.n)
        except Exception as exc:  # the solver may not support this arm yet
            self._status.content = f"IK unavailable: {type(exc).__name__}: {exc}"
            return False
        self.set_configuration(q)
        self._status.content = "IK: snapped to the nearest solution"
        return True


def _free_port(host: str) -> int:
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


class _ViewerKeywords(TypedDict, total=False):
    """The keywords of :class:`RobotViewer` that :func:`view` passes on."""

    scene: Any
    report: Any
    host: str
    port: int
    dt: float
    verbose: bool
    allowed_hosts: tuple[str, ...]


def view(
    robot: Robot,
    trajectory: Any = None,
    *,
    block: bool = True,
    play: bool = True,
    **options: Unpack[_ViewerKeywords],
) -> RobotViewer:
    """Open the viewer (see :class:`RobotViewer`); with ``block`` serve until Ctrl-C.

    Args:
        robot: The robot.
        trajectory: As :class:`RobotViewer`'s.
        block: Serve until Ctrl-C before returning.
        play: Start playing the trajectory.
        **options: :class:`RobotViewer`'s keywords (``scene``, ``report``,
            ``host``, ``port``, ``dt``, ``verbose``, ``allowed_hosts``).
    """
    viewer = RobotViewer(robot, trajectory, **options)
    if play:
        viewer.set_playing(True)
    if block:
        print(f"robokin viewer: {viewer.url}  (Ctrl-C to stop)")
        viewer.wait()
    return viewer
