"""The animation as one self-contained HTML file: no server, no network.

Live viewers need a running server, which breaks behind firewalls, in notebooks
and on remote machines. This writes a single ``.html`` file holding the data and
a small hand-written canvas renderer (capsules, cylinders, boxes, spheres,
meshes, lines; painter's algorithm), with play/pause, a time slider and mouse
orbit / pan / zoom. Open it in any browser, attach it to an e-mail, embed it in
a report.
"""

from __future__ import annotations

import base64
import html as _html
import json
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np
from typing_extensions import Unpack

from robokin.io.atomic import write_atomic
from robokin.viz._common import COLORS, drawing, scene_shapes, skeleton

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["NotebookView", "animation_html", "notebook_view", "write_html"]

_MAX_MESH_FACES = 20_000


def _b64(a: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype="<f4").tobytes()).decode(
        "ascii"
    )


def _frame_indices(m: int, max_frames: int, keep: list[int]) -> np.ndarray:
    if m <= max_frames:
        return np.arange(m)
    stride = int(np.ceil(m / max_frames))
    idx = np.r_[np.arange(0, m, stride), m - 1, [k for k in keep if 0 <= k < m]]
    return np.unique(idx.astype(np.int64))


def _red_bodies(idx: np.ndarray, bodies: list) -> dict[str, list[str]]:
    """Per shown frame, the names of the bodies in collision at its sample."""
    out: dict[str, list[str]] = {}
    for first, last, a, b in bodies:
        for f in np.nonzero((idx >= first) & (idx <= last))[0]:
            out.setdefault(str(int(f)), []).extend([a, b])
    return out


def _shape_json(s: Any, frame: int | None = None) -> dict[str, Any]:
    d: dict[str, Any] = {
        "name": s.name,
        "kind": s.kind,
        "size": [float(v) for v in s.size],
        "pose": np.asarray(s.pose, dtype=float).T.reshape(-1).round(6).tolist(),
        "color": list(s.color),
    }
    if frame is not None:
        d["frame"] = int(frame)
    if s.kind == "mesh" and s.vertices is not None and s.faces is not None:
        faces = np.asarray(s.faces, dtype=np.int64)[:_MAX_MESH_FACES]
        d["vertices"] = (
            np.asarray(s.vertices, dtype=float).round(5).reshape(-1).tolist()
        )
        d["faces"] = faces.reshape(-1).tolist()
    return d


class _PageKeywords(TypedDict, total=False):
    """The keywords of :func:`animation_html`, which :func:`write_html` passes on."""

    scene: Any
    report: Any
    title: str | None
    dt: float
    max_frames: int
    autoplay: bool


def animation_html(
    robot: Robot,
    trajectory: Any = None,
    *,
    scene: Any = None,
    report: Any = None,
    title: str | None = None,
    dt: float = 0.005,
    max_frames: int = 2500,
    autoplay: bool = True,
) -> str:
    """The animation page as a string (see :func:`write_html`)."""
    view = drawing(robot, trajectory, report, dt=dt)
    motion, rep, shapes = view.motion, view.report, view.shapes
    m = motion.q.shape[0]
    keep = []
    if rep.distance is not None:
        keep.append(int(np.argmin(rep.distance)))
    closest = getattr(report, "closest", None)
    if closest is not None and hasattr(closest, "index"):
        keep.append(int(closest.index))
    for first, last, *_ in rep.bodies:
        keep += [first, last]
    idx = _frame_indices(m, max(2, int(max_frames)), keep)
    q = motion.q[idx]
    sk = skeleton(robot, q)
    track: tuple[np.ndarray, np.ndarray | None] | None = rep.closest_at(idx)
    if track is None and rep.distance is not None:
        track = (rep.distance[idx], None)
    F = idx.size
    nc = robot.chain.n_chain
    data: dict[str, Any] = {
        "title": title or robot.name,
        "robot": robot.name,
        "autoplay": bool(autoplay) and F > 1,
        "t": motion.t[idx].round(6).tolist(),
        "nPoints": int(sk.points.shape[1]),
        "points": _b64(sk.points),
        "links": sk.links.tolist(),
        "radius": sk.radius,
        "jointOrigins": [1 + 3 * k for k in range(nc)],
        "jointAxes": _b64(sk.joint_frames[:, :, :3, 2]),
        "jointKinds": list(sk.joint_kinds),
        "tool": _b64(
            np.concatenate(
                [
                    sk.tool[:, :3, 3],
                    np.swapaxes(sk.tool[:, :3, :3], -1, -2).reshape(F, 9),
                ],
                axis=1,
            )
        ),
        "scale": sk.scale,
        "scene": [_shape_json(s) for s in scene_shapes(scene)],
        "colors": asdict(COLORS),
        "colliding": rep.colliding[idx].astype(int).tolist(),
        "collisions": [[int(a), int(b), x, y] for a, b, x, y in rep.bodies],
        "redBodies": _red_bodies(idx, rep.bodies),
        "distance": None if track is None else np.round(track[0], 7).tolist(),
        "closest": None if track is None or track[1] is None else _b64(track[1]),
        "minDistance": rep.min_distance,
    }
    data["skeleton"] = view.skeleton_only
    if shapes:
        from robokin.kinematics.forward import link_frames

        frames = link_frames(robot.chain, q)  # (F, nc + 2, 4, 4)
        data["frames"] = _b64(frames[:, :, :3, :].transpose(0, 1, 3, 2).reshape(F, -1))
        data["nFrames"] = nc + 2
        data["robotShapes"] = [_shape_json(s, frame=i) for i, s in shapes]
    payload = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    page_title = _html.escape(data["title"])
    return (
        _TEMPLATE.replace("%%TITLE%%", page_title)
        .replace("%%DATA%%", payload)
        .replace("%%SCRIPT%%", _SCRIPT)
    )


class NotebookView:
    """The animation page shown in a Jupyter cell (an ``<iframe srcdoc>``).

    Why the standalone page and not viser's embedding: the page is the whole
    viewer in the cell's output (data and renderer), so it works in any notebook
    front end (JupyterLab, classic Notebook, VS Code), on a remote kernel or
    behind a firewall, when the notebook is executed headless in CI, and after it
    is saved and reopened with the kernel gone. Viser's embedding needs its
    server running in the kernel and a port the browser can reach, and shows
    nothing once the kernel stops. The iframe is sandboxed (``allow-scripts``
    only): the page cannot reach the notebook.

    Attributes:
        page: The HTML page (:func:`animation_html`).
        height: The cell's height [px].
    """

    def __init__(self, page: str, height: int = 480) -> None:
        """Hold ``page`` for display at ``height`` pixels."""
        self.page = page
        self.height = int(height)

    def _repr_html_(self) -> str:
        """The iframe holding the page (escaped into ``srcdoc``)."""
        doc = _html.escape(self.page, quote=True)
        return (f'<iframe srcdoc="{doc}" sandbox="allow-scripts" width="100%" '
                f'height="{self.height}" style="border: 1px solid #ddd"></iframe>')

    def __repr__(self) -> str:
        """A short summary (outside notebooks)."""
        return f"NotebookView({len(self.page):,} characters, height={self.height})"


def notebook_view(
    robot: Robot,
    trajectory: Any = None,
    *,
    scene: Any = None,
    report: Any = None,
    title: str | None = None,
    height: int = 480,
    max_frames: int = 400,
) -> NotebookView:
    """The 3D animation for a notebook cell: make it the cell's last expression.

    Args:
        robot: The robot.
        trajectory: As for :func:`write_html`.
        scene: A scene to draw, or None.
        report: A collision report for the same samples, or None.
        title: The title (default: the robot's name).
        height: The cell's height [px].
        max_frames: Longer motions are thinned to about this many frames (the
            cell's output stays a few hundred kilobytes).

    Returns:
        A :class:`NotebookView` (Jupyter shows it through ``_repr_html_``).
    """
    page = animation_html(robot, trajectory, scene=scene, report=report, title=title,
                          max_frames=max_frames)
    return NotebookView(page, height)


def write_html(
    path: str | Path,
    robot: Robot,
    trajectory: Any = None,
    **options: Unpack[_PageKeywords],
) -> Path:
    """Write the animation of ``robot`` as one self-contained HTML file.

    Args:
        path: Output file (``.html``).
        robot: The robot.
        trajectory: Joint samples (m, n), a configuration (n,), an object with
            ``.t`` (m,) and ``.q`` (m, n), or None (the zero configuration).
        scene: A ``robokin.collision.Scene`` to draw, or None.
        report: A collision report for the same samples (``collision.check``):
            colliding samples are drawn red, the closest-distance segment per
            sample in blue when the report carries closest points.
        title: Page title (default: the robot's name).
        dt: Sample period [s] when ``trajectory`` has no times.
        max_frames: Longer motions are thinned to about this many frames
            (keeping the minimum-distance and collision samples).
        autoplay: Start playing when the page opens.

    Returns:
        The path written (atomically: a temporary file in the same folder,
        renamed; see :func:`robokin.io.atomic.write_atomic`).

    Raises:
        InputError: the folder is missing or read-only, or ``path`` is a folder.
    """
    path = Path(path)
    return write_atomic(path, animation_html(robot, trajectory, **options))


_TEMPLATE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>%%TITLE%% - robokin</title>
<style>
  html, body { margin: 0; height: 100%; background: #f4f5f7; overflow: hidden;
    font: 13px/1.3 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: #222; }
  #view { display: block; width: 100%; cursor: grab; touch-action: none; }
  #bar { position: absolute; left: 0; right: 0; bottom: 0; height: 44px; display: flex;
    align-items: center; gap: 10px; padding: 0 12px; background: #fff;
    border-top: 1px solid #d8dbe0; box-sizing: border-box; }
  #play { width: 64px; height: 28px; border: 1px solid #9aa3b0; border-radius: 4px;
    background: #eef1f5; cursor: pointer; font: inherit; }
  #slider { flex: 1; }
  #time, #dist { font-variant-numeric: tabular-nums; white-space: nowrap; }
  #head { position: absolute; left: 12px; top: 8px; pointer-events: none; }
  #head b { font-size: 15px; }
  #head .hint { color: #667; }
  #status { display: none; }
</style>
</head>
<body>
<canvas id="view"></canvas>
<div id="head"><b>%%TITLE%%</b><br><span class="hint">drag: orbit &middot; shift/right-drag:
pan &middot; wheel: zoom &middot; space: play/pause</span><br><span id="alert"></span></div>
<div id="bar">
  <button id="play" type="button">Play</button>
  <input id="slider" type="range" min="0" max="0" value="0" step="1">
  <span id="time"></span><span id="dist"></span>
</div>
<pre id="status"></pre>
<script id="robokin-data" type="application/json">%%DATA%%</script>
<script>
%%SCRIPT%%
</script>
</body>
</html>
"""

_SCRIPT = r"""
"use strict";
(function () {
  const D = JSON.parse(document.getElementById("robokin-data").textContent);
  function f32(s) {
    const bin = atob(s), u = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) u[i] = bin.charCodeAt(i);
    return new Float32Array(u.buffer);
  }
  const T = D.t, NF = T.length, NP = D.nPoints;
  const P = f32(D.points), AX = f32(D.jointAxes), TOOL = f32(D.tool);
  const CL = D.closest ? f32(D.closest) : null;
  const FR = D.frames ? f32(D.frames) : null;
  const NJ = D.jointOrigins.length;
  const canvas = document.getElementById("view"), ctx = canvas.getContext("2d");
  const bar = document.getElementById("bar"), slider = document.getElementById("slider");
  const playBtn = document.getElementById("play");
  const timeEl = document.getElementById("time"), distEl = document.getElementById("dist");
  slider.max = String(NF - 1);

  // ---- small vector helpers
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                           a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => Math.hypot(a[0], a[1], a[2]);
  const unit = (a) => { const n = norm(a) || 1; return [a[0] / n, a[1] / n, a[2] / n]; };
  // pose: column-major 4x4 (16 numbers)
  const xform = (M, p) => [M[0] * p[0] + M[4] * p[1] + M[8] * p[2] + M[12],
                           M[1] * p[0] + M[5] * p[1] + M[9] * p[2] + M[13],
                           M[2] * p[0] + M[6] * p[1] + M[10] * p[2] + M[14]];
  const rot = (M, v) => [M[0] * v[0] + M[4] * v[1] + M[8] * v[2],
                         M[1] * v[0] + M[5] * v[1] + M[9] * v[2],
                         M[2] * v[0] + M[6] * v[1] + M[10] * v[2]];
  function compose(A, B) {  // A*B, both column-major
    const C = new Array(16);
    for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += A[k * 4 + r] * B[c * 4 + k];
      C[c * 4 + r] = s;
    }
    return C;
  }
  const pt = (f, i) => { const o = (f * NP + i) * 3; return [P[o], P[o + 1], P[o + 2]]; };

  // ---- camera (z up), framed on everything that moves plus the scene
  let lo = [1e9, 1e9, 1e9], hi = [-1e9, -1e9, -1e9];
  const grow = (p) => { for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]);
                                                      hi[k] = Math.max(hi[k], p[k]); } };
  for (let f = 0; f < NF; f += Math.max(1, Math.floor(NF / 200)))
    for (let i = 0; i < NP; i++) grow(pt(f, i));
  for (let i = 0; i < NP; i++) grow(pt(NF - 1, i));
  for (const s of D.scene) {
    const h = s.kind === "box" ? s.size.map((v) => v / 2) : [s.size[0], s.size[0], s.size[1] || s.size[0]];
    for (const sx of [-1, 1]) for (const sy of [-1, 1]) for (const sz of [-1, 1])
      grow(xform(s.pose, [sx * h[0], sy * h[1], sz * h[2]]));
  }
  const cam = { target: mul(add(lo, hi), 0.5), az: -0.9, el: 0.42,
                dist: 1.25 * Math.max(norm(sub(hi, lo)), 0.2), fov: 0.75, pan: [0, 0, 0] };
  let eye, right, up, fwd, focal, W = 1, H = 1, DPR = 1;
  function setupCamera() {
    const tg = add(cam.target, cam.pan);
    eye = add(tg, mul([Math.cos(cam.el) * Math.cos(cam.az), Math.cos(cam.el) * Math.sin(cam.az),
                       Math.sin(cam.el)], cam.dist));
    fwd = unit(sub(tg, eye));
    right = unit(cross(fwd, [0, 0, 1]));
    up = cross(right, fwd);
    focal = 0.5 * H / Math.tan(cam.fov / 2);
  }
  function project(p) {
    const d = sub(p, eye), z = dot(d, fwd);
    return [W / 2 + focal * dot(d, right) / z, H / 2 - focal * dot(d, up) / z, z];
  }
  const light = () => unit(add(mul(fwd, -1), add(mul(up, 0.6), mul(right, -0.3))));
  const rgb = (c, s, a) => "rgba(" + Math.min(255, Math.round(c[0] * s)) + "," +
    Math.min(255, Math.round(c[1] * s)) + "," + Math.min(255, Math.round(c[2] * s)) + "," +
    (a === undefined ? 1 : a) + ")";

  // ---- drawables: {z, draw()} sorted far to near
  let items = [];
  function capsule(a, b, r, color, cap) {
    const A = project(a), B = project(b);
    if (A[2] <= 1e-3 || B[2] <= 1e-3) return;
    const z = (A[2] + B[2]) / 2, w = 2 * r * focal / z;
    items.push({ z: z, draw() {
      ctx.lineCap = cap || "round";
      const L = light(), dir = unit(sub(b, a));
      const shade = 0.55 + 0.45 * Math.sqrt(Math.max(0, 1 - dot(dir, L) ** 2));
      ctx.strokeStyle = rgb(color, 0.55 * shade); ctx.lineWidth = w;
      ctx.beginPath(); ctx.moveTo(A[0], A[1]); ctx.lineTo(B[0], B[1]); ctx.stroke();
      const o = -0.16 * w;
      ctx.strokeStyle = rgb(color, 0.95 * shade); ctx.lineWidth = 0.62 * w;
      ctx.beginPath(); ctx.moveTo(A[0], A[1] + o); ctx.lineTo(B[0], B[1] + o); ctx.stroke();
      ctx.strokeStyle = rgb(color, 1.25 * shade, 0.8); ctx.lineWidth = 0.18 * w;
      ctx.beginPath(); ctx.moveTo(A[0], A[1] + 2 * o); ctx.lineTo(B[0], B[1] + 2 * o);
      ctx.stroke();
    } });
  }
  function sphere(c, r, color) {
    const C = project(c);
    if (C[2] <= 1e-3) return;
    const R = r * focal / C[2];
    items.push({ z: C[2], draw() {
      const g = ctx.createRadialGradient(C[0] - R / 3, C[1] - R / 3, R / 10, C[0], C[1], R);
      g.addColorStop(0, rgb(color, 1.3)); g.addColorStop(1, rgb(color, 0.5));
      ctx.fillStyle = g; ctx.beginPath(); ctx.arc(C[0], C[1], R, 0, 2 * Math.PI); ctx.fill();
    } });
  }
  function line(a, b, color, width, onTop) {
    const A = project(a), B = project(b);
    if (A[2] <= 1e-3 || B[2] <= 1e-3) return;
    items.push({ z: onTop ? -1 : (A[2] + B[2]) / 2, draw() {
      ctx.lineCap = "round"; ctx.strokeStyle = rgb(color, 1); ctx.lineWidth = width * DPR;
      ctx.beginPath(); ctx.moveTo(A[0], A[1]); ctx.lineTo(B[0], B[1]); ctx.stroke();
    } });
  }
  function face(poly, normal, color, alpha, seam) {  // poly, normal: world
    const c = poly.reduce((s, p) => add(s, p), [0, 0, 0]).map((v) => v / poly.length);
    if (dot(normal, sub(c, eye)) >= 0) return;  // back face
    const Q = poly.map(project);
    if (Q.some((q) => q[2] <= 1e-3)) return;
    const z = project(c)[2];
    const s = 0.45 + 0.6 * Math.max(0, dot(normal, light()));
    items.push({ z: z, draw() {
      ctx.fillStyle = rgb(color, s, alpha);
      ctx.strokeStyle = seam ? rgb(color, s, alpha) : rgb(color, 0.5 * s, alpha);
      ctx.lineWidth = 0.7 * DPR; ctx.lineJoin = "round";
      ctx.beginPath(); ctx.moveTo(Q[0][0], Q[0][1]);
      for (let i = 1; i < Q.length; i++) ctx.lineTo(Q[i][0], Q[i][1]);
      ctx.closePath(); ctx.fill(); ctx.stroke();
    } });
  }
  function box(M, size, color, alpha) {
    const h = size.map((v) => v / 2);
    const corner = (sx, sy, sz) => xform(M, [sx * h[0], sy * h[1], sz * h[2]]);
    for (let ax = 0; ax < 3; ax++) for (const sg of [-1, 1]) {
      const n = [0, 0, 0]; n[ax] = sg;
      const a1 = (ax + 1) % 3, a2 = (ax + 2) % 3, poly = [];
      for (const [u, v] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
        const s = [0, 0, 0]; s[ax] = sg; s[a1] = u; s[a2] = v * sg;
        poly.push(corner(s[0], s[1], s[2]));
      }
      face(poly, rot(M, n), color, alpha);
    }
  }
  function cylinder(M, r, len, color, alpha) {
    const N = 20, top = [], bot = [];
    for (let i = 0; i < N; i++) {
      const a = 2 * Math.PI * i / N, x = r * Math.cos(a), y = r * Math.sin(a);
      top.push(xform(M, [x, y, len / 2])); bot.push(xform(M, [x, y, -len / 2]));
    }
    for (let i = 0; i < N; i++) {
      const j = (i + 1) % N, a = 2 * Math.PI * (i + 0.5) / N;
      face([bot[i], bot[j], top[j], top[i]], rot(M, [Math.cos(a), Math.sin(a), 0]), color, alpha,
           true);
    }
    face(top, rot(M, [0, 0, 1]), color, alpha);
    face(bot.slice().reverse(), rot(M, [0, 0, -1]), color, alpha);
  }
  function mesh(M, s, color, alpha) {
    const V = s.vertices, Fc = s.faces;
    for (let i = 0; i + 2 < Fc.length; i += 3) {
      const p = [0, 1, 2].map((k) => xform(M, [V[3 * Fc[i + k]], V[3 * Fc[i + k] + 1],
                                                V[3 * Fc[i + k] + 2]]));
      face(p, unit(cross(sub(p[1], p[0]), sub(p[2], p[0]))), color, alpha);
    }
  }
  function shape(s, M, color, alpha) {
    if (s.kind === "box") box(M, s.size, color, alpha);
    else if (s.kind === "cylinder") cylinder(M, s.size[0], s.size[1], color, alpha);
    else if (s.kind === "capsule") {
      capsule(xform(M, [0, 0, -s.size[1] / 2]), xform(M, [0, 0, s.size[1] / 2]), s.size[0], color);
    } else if (s.kind === "sphere") sphere(xform(M, [0, 0, 0]), s.size[0], color);
    else if (s.kind === "mesh" && s.vertices) mesh(M, s, color, alpha);
  }
  function grid() {
    const span = Math.max(hi[0] - lo[0], hi[1] - lo[1], 0.5) * 1.2;
    const step = Math.pow(10, Math.floor(Math.log10(span / 4)));
    const n = Math.ceil(span / step / 2), c = cam.target, z0 = Math.min(0, lo[2]);
    const x0 = Math.round(c[0] / step) * step, y0 = Math.round(c[1] / step) * step;
    ctx.lineWidth = DPR; ctx.strokeStyle = "rgba(120,130,145,0.35)";
    ctx.beginPath();
    for (let i = -n; i <= n; i++) {
      const segs = [[[x0 + i * step, y0 - n * step, z0], [x0 + i * step, y0 + n * step, z0]],
                    [[x0 - n * step, y0 + i * step, z0], [x0 + n * step, y0 + i * step, z0]]];
      for (const [a, b] of segs) {
        const A = project(a), B = project(b);
        if (A[2] > 1e-3 && B[2] > 1e-3) { ctx.moveTo(A[0], A[1]); ctx.lineTo(B[0], B[1]); }
      }
    }
    ctx.stroke();
  }

  // ---- one frame
  let frame = 0;
  const sceneRed = (name) => {
    const names = D.redBodies[frame];
    return names !== undefined && names.indexOf(name) >= 0;
  };
  function render() {
    setupCamera();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = "#f4f5f7"; ctx.fillRect(0, 0, W, H);
    grid();
    items = [];
    const red = D.colliding[frame] === 1;
    const C = D.colors, linkC = red ? C.collision : C.link;
    for (const s of D.scene) shape(s, s.pose, sceneRed(s.name) ? C.collision : s.color, 0.92);
    const r = D.radius;
    if (D.robotShapes && FR) {
      for (const s of D.robotShapes) {
        const o = (frame * D.nFrames + s.frame) * 12, f = Array.from(FR.slice(o, o + 12));
        const M = [f[0], f[1], f[2], 0, f[3], f[4], f[5], 0, f[6], f[7], f[8], 0,
                   f[9], f[10], f[11], 1];
        shape(s, compose(M, s.pose), red ? C.collision : s.color, 1);
      }
    }
    if (D.skeleton) {
      for (const [i, j] of D.links) capsule(pt(frame, i), pt(frame, j), r, linkC);
      for (let k = 0; k < NJ; k++) {
        const o = pt(frame, D.jointOrigins[k]), a = (frame * NJ + k) * 3;
        const z = [AX[a], AX[a + 1], AX[a + 2]];
        if (D.jointKinds[k] === "prismatic") capsule(sub(o, mul(z, 1.6 * r)), add(o, mul(z, 1.6 * r)),
                                                    0.8 * r, C.joint, "square");
        else capsule(sub(o, mul(z, 1.25 * r)), add(o, mul(z, 1.25 * r)), 1.3 * r, C.joint, "butt");
      }
      const b = pt(frame, 0);
      cylinder([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, b[0], b[1], b[2] - 0.5 * r],
               2.2 * r, r, C.joint, 1);
    }
    // tool frame
    const to = frame * 12, p0 = [TOOL[to], TOOL[to + 1], TOOL[to + 2]];
    const L = 0.12 * Math.max(D.scale, 0.3);
    const axc = [[230, 40, 40], [40, 170, 40], [40, 80, 230]];
    for (let k = 0; k < 3; k++) {
      const d = [TOOL[to + 3 + 3 * k], TOOL[to + 4 + 3 * k], TOOL[to + 5 + 3 * k]];
      line(p0, add(p0, mul(d, L)), axc[k], 3, true);
    }
    if (CL) {
      const o = frame * 6, a = [CL[o], CL[o + 1], CL[o + 2]], b = [CL[o + 3], CL[o + 4], CL[o + 5]];
      line(a, b, red ? C.collision : C.distance, 3, true);
      sphere(a, 0.25 * r, C.distance); sphere(b, 0.25 * r, C.distance);
    }
    items.sort((u, v) => v.z - u.z);
    for (const it of items) it.draw();
    slider.value = String(frame);
    timeEl.textContent = "t = " + T[frame].toFixed(3) + " s / " + T[NF - 1].toFixed(3) + " s";
    let msg = "";
    if (D.distance) msg = "distance " + (1000 * D.distance[frame]).toFixed(1) + " mm";
    if (red) msg += (msg ? " · " : "") + "COLLISION";
    distEl.textContent = msg;
    distEl.style.color = red ? "#d01818" : "#222";
  }

  // ---- layout, playback, interaction
  function resize() {
    DPR = window.devicePixelRatio || 1;
    const w = window.innerWidth, h = Math.max(50, window.innerHeight - bar.offsetHeight);
    canvas.style.height = h + "px";
    canvas.width = Math.round(w * DPR); canvas.height = Math.round(h * DPR);
    W = canvas.width; H = canvas.height;
    render();
  }
  let playing = false, tPlay = T[0], last = null;
  function setPlaying(on) {
    playing = on && NF > 1; playBtn.textContent = playing ? "Pause" : "Play"; last = null;
    if (playing) requestAnimationFrame(tick);
  }
  function seek(t) {
    let a = 0, b = NF - 1;
    while (a < b) { const c = (a + b + 1) >> 1; if (T[c] <= t) a = c; else b = c - 1; }
    frame = a;
  }
  function tick(now) {
    if (!playing) return;
    if (last !== null) {
      tPlay += (now - last) / 1000;
      if (tPlay > T[NF - 1]) tPlay = T[0];
      seek(tPlay); render();
    }
    last = now;
    requestAnimationFrame(tick);
  }
  playBtn.addEventListener("click", () => setPlaying(!playing));
  slider.addEventListener("input", () => { frame = +slider.value; tPlay = T[frame]; render(); });
  window.addEventListener("keydown", (e) => {
    if (e.code === "Space") { e.preventDefault(); setPlaying(!playing); }
  });
  let drag = null;
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("pointerdown", (e) => {
    drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener("pointerup", () => { drag = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      const s = cam.dist / (focal / DPR);
      cam.pan = add(cam.pan, add(mul(right, -dx * s), mul(up, dy * s)));
    } else {
      cam.az -= dx * 0.008;
      cam.el = Math.max(-1.5, Math.min(1.5, cam.el + dy * 0.008));
    }
    render();
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault(); cam.dist *= Math.exp(e.deltaY * 0.001); render();
  }, { passive: false });
  window.addEventListener("resize", resize);
  if (D.collisions.length) {
    const el = document.getElementById("alert");
    el.style.color = "#d01818";
    el.textContent = D.collisions.length + " collision interval(s): " +
      D.collisions.map((c) => c[2] + " / " + c[3]).join(", ");
  }
  resize();
  document.body.setAttribute("data-rendered", String(NF));
  document.getElementById("status").textContent = "robokin-rendered frames=" + NF;
  setPlaying(D.autoplay);
})();
"""
