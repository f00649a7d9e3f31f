"""Headless Chromium for the viewer tests: load a page, dump its DOM, screenshot it.

Chromium comes from Debian's ``chromium`` package (``apt-get install -y chromium``);
tests that need it skip, saying so, when ``/usr/bin/chromium`` is absent.
"""

from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = Path("/usr/bin/chromium")


def require_chromium() -> Path:
    """The Chromium binary, or skip the test with the reason."""
    if not CHROMIUM.exists():
        pytest.skip(
            "headless Chromium is not installed: /usr/bin/chromium is missing "
            "(Debian: apt-get install -y chromium)"
        )
    return CHROMIUM


def run_chromium(
    url: str,
    profile: Path,
    *,
    screenshot: Path | None = None,
    size: tuple[int, int] = (900, 600),
    budget_ms: int = 3000,
    webgl: bool = False,
    timeout: float = 90.0,
) -> str:
    """Load ``url``; return the DOM after ``budget_ms`` of virtual time, or screenshot."""
    args = [
        str(require_chromium()),
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-extensions",
        "--hide-scrollbars",
        "--mute-audio",
        f"--user-data-dir={profile}",
        f"--window-size={size[0]},{size[1]}",
        f"--virtual-time-budget={budget_ms}",
    ]
    if webgl:
        args += [
            "--use-gl=angle",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--ignore-gpu-blocklist",
        ]
    args += [f"--screenshot={screenshot}"] if screenshot else ["--dump-dom"]
    # Headless Chromium with virtual time now and then never finishes (seen with a
    # live websocket page on a loaded machine): give each try a bounded wall time,
    # kill its whole process group, and retry with a fresh profile.
    tries = 3
    per_try = max(30.0, timeout / tries)
    for k in range(tries):
        run_args = [a if not a.startswith("--user-data-dir=")
                    else f"--user-data-dir={profile}-{k}" for a in args]
        proc = subprocess.Popen(run_args + [url], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True,
                                start_new_session=True)
        try:
            stdout, stderr = proc.communicate(timeout=per_try)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
            continue
        if screenshot is not None and not screenshot.exists():
            raise AssertionError(f"chromium wrote no screenshot; stderr:\n{stderr[-2000:]}")
        return stdout
    raise AssertionError(
        f"chromium did not finish loading {url} in {tries} tries of {per_try:.0f} s"
    )


def read_png(path: Path) -> np.ndarray:
    """RGB image as uint8 (H, W, 3)."""
    import matplotlib.image as mpimg

    img = mpimg.imread(str(path))
    if img.dtype != np.uint8:
        img = np.round(img * 255).astype(np.uint8)
    return img[..., :3]


def color_fraction(img: np.ndarray, rgb: tuple[int, int, int], tol: int = 40) -> float:
    """Fraction of pixels within ``tol`` (per channel) of ``rgb``."""
    d = np.abs(img.astype(int) - np.asarray(rgb, dtype=int)).max(axis=-1)
    return float((d <= tol).mean())


def orange_fraction(img: np.ndarray) -> float:
    """Fraction of orange pixels (the robot's links, any shade)."""
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return float(((r - b > 70) & (g - b > 30) & (r - g > 30)).mean())


def red_fraction(img: np.ndarray) -> float:
    """Fraction of saturated red pixels (collision highlight, any shade)."""
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return float(((r > 90) & (r - g > 70) & (np.abs(g - b) < 25)).mean())


def screenshot_until(
    url: str,
    profile: Path,
    done: Callable[[np.ndarray], bool],
    *,
    size: tuple[int, int] = (900, 600),
    timeout: float = 120.0,
    webgl: bool = False,
) -> np.ndarray:
    """Load ``url`` in headless Chromium and screenshot it until ``done(image)``.

    Polls in wall time through the DevTools protocol (Page.captureScreenshot every
    half second), so a page that waits for a server (the viewer's websocket scene)
    is captured once it has drawn, however loaded the machine is. Returns the last
    image (RGB uint8) when ``done`` never holds within ``timeout`` seconds.
    """
    import base64
    import io
    import json
    import re
    import time
    import urllib.request

    import matplotlib.image as mpimg
    from websockets.sync.client import connect

    args = [
        str(require_chromium()), "--headless", "--no-sandbox", "--disable-gpu",
        "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--disable-extensions",
        "--hide-scrollbars", "--mute-audio", f"--user-data-dir={profile}",
        f"--window-size={size[0]},{size[1]}", "--remote-debugging-address=127.0.0.1",
        "--remote-debugging-port=0",
    ]
    if webgl:
        args += ["--use-gl=angle", "--use-angle=swiftshader",
                 "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"]
    proc = subprocess.Popen(args + [url], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        port = None
        deadline = time.monotonic() + timeout
        assert proc.stderr is not None
        while port is None and time.monotonic() < deadline:
            line = proc.stderr.readline()
            m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
            if m:
                port = int(m.group(1))
            elif not line and proc.poll() is not None:
                raise AssertionError("chromium exited before its DevTools port opened")
        if port is None:
            raise AssertionError("chromium did not open its DevTools port")
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json", timeout=30) as r:
            pages = [t for t in json.load(r) if t.get("type") == "page"]
        image = np.zeros((size[1], size[0], 3), dtype=np.uint8)
        with connect(pages[0]["webSocketDebuggerUrl"], max_size=None) as ws:
            # the viewport itself is size (the window's includes what headless omits)
            ws.send(json.dumps({"id": -1, "method": "Emulation.setDeviceMetricsOverride",
                                "params": {"width": size[0], "height": size[1],
                                           "deviceScaleFactor": 1, "mobile": False}}))
            while json.loads(ws.recv(timeout=60)).get("id") != -1:
                pass
            for k in range(1_000_000):
                ws.send(json.dumps({"id": k, "method": "Page.captureScreenshot"}))
                while True:
                    reply = json.loads(ws.recv(timeout=60))
                    if reply.get("id") == k:
                        break
                data = base64.b64decode(reply["result"]["data"])
                rgba = mpimg.imread(io.BytesIO(data), format="png")
                image = np.round(rgba[..., :3] * 255).astype(np.uint8)
                if done(image) or time.monotonic() > deadline:
                    return image
                time.sleep(0.5)
        return image
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
