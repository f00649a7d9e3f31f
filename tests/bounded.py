"""Run code in a fresh interpreter under a memory limit (issue 15 attack tests).

``run_bounded(code)`` starts ``python``, imports robokin and warms it up, then caps
the address space at what it uses plus ``extra_mb`` (``resource.setrlimit
(RLIMIT_AS)``) and runs ``code``. Code that allocates gigabytes dies with a
MemoryError instead of taking the machine down; the caller asserts on the exit
code and output. The ``timeout`` is a generous deadline against a hang, not a
measure of speed.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

PRELUDE = """
import re, resource, sys
import numpy, pydantic, yaml
import robokin, robokin.cli, robokin.io.robot_files, robokin.io.motion_files
import robokin.trajectory.motion_plan
from robokin import collision
robokin.load("ur5")
_vm = int(re.search(r"VmSize:\\s+(\\d+)", open("/proc/self/status").read()).group(1))
_cap = (_vm + {extra_mb} * 1024) * 1024
resource.setrlimit(resource.RLIMIT_AS, (_cap, _cap))
"""


def run_bounded(code: str, *, extra_mb: int = 400, timeout: float = 300.0,
                cwd: str | None = None) -> subprocess.CompletedProcess:
    """Run ``code`` after :data:`PRELUDE` under an address-space limit."""
    script = PRELUDE.format(extra_mb=extra_mb) + textwrap.dedent(code)
    return subprocess.run([sys.executable, "-c", script], capture_output=True,
                          text=True, timeout=timeout, cwd=cwd)


def alias_bomb(leaf: str = "lol", width: int = 9, depth: int = 9) -> tuple[str, str]:
    """YAML anchors ``&b0 .. &b{depth}``, each a list of ``width`` aliases of the one
    before: ``*b{depth}`` names width**depth leaves in a few hundred bytes.

    Returns:
        ``(anchor lines under a key 'bombs:', the alias to use)``.
    """
    lines = [f"  - &b0 [{', '.join([leaf] * width)}]"]
    for i in range(1, depth):
        lines.append(f"  - &b{i} [{', '.join([f'*b{i - 1}'] * width)}]")
    return "\n".join(lines), f"*b{depth - 1}"
