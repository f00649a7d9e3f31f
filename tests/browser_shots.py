"""Headless Chromium for the viewer tests: load a page, dump its DOM, screenshot it.

Chromium comes from Debian's ``chromium`` package (``apt-get install -y chromium``);
tests that need it skip, saying so, when ``/usr/bin/chromium`` is absent.
"""

from __future__ import annotations

import os
import signal
import subprocess
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
