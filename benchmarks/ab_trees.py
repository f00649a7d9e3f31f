"""Shared pieces of the two-tree A/B scripts (``self_motion_api_ab.py``,
``self_motion_srs_ab.py``): the same child program run in fresh processes against two
source trees, alternated over rounds, and exact equality of what the children saved.
"""

from __future__ import annotations

import os
import pathlib
import pickle
import subprocess
import sys
from collections.abc import Callable
from typing import Any

import numpy as np


def same(x: object, y: object) -> bool:
    """Exact equality (arrays: equal with NaN equal to NaN; dicts by key; lists and tuples
    elementwise unless they hold records, which compare by ``==``)."""
    if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
        xa, ya = np.asarray(x), np.asarray(y)
        return xa.dtype == ya.dtype and xa.shape == ya.shape and bool(
            np.array_equal(xa, ya, equal_nan=xa.dtype.kind == "f"))
    if isinstance(x, dict) and isinstance(y, dict):
        return x.keys() == y.keys() and all(same(x[k], y[k]) for k in x)
    if isinstance(x, list | tuple) and isinstance(y, list | tuple) and not (
            x and hasattr(x[0], "t")):
        return type(x) is type(y) and len(x) == len(y) and all(
            same(u, v) for u, v in zip(x, y, strict=True))
    return type(x) is type(y) and bool(x == y)


def run_rounds(trees: list[str], rounds: int, tmp: pathlib.Path,
               code_of: Callable[[str, int, pathlib.Path], str]) -> list[Any]:
    """Run ``code_of(tree, round, out)`` for trees A and B alternately, ``rounds`` times.

    Each child runs in a fresh interpreter with ``PYTHONPATH=<tree>/src`` and prints one
    line (echoed with the round and tree); ``out`` is ``tmp / "A.pkl"`` or ``"B.pkl"``,
    which the round-0 children are expected to write. Returns the two unpickled outputs.
    """
    print("load", pathlib.Path("/proc/loadavg").read_text().split()[:3])
    for r in range(rounds):
        for name, tree in zip("AB", trees, strict=True):
            root = pathlib.Path(tree).resolve()
            env = dict(os.environ, PYTHONPATH=str(root / "src"))
            res = subprocess.run([sys.executable, "-c", code_of(str(root), r, tmp / f"{name}.pkl")],
                                 env=env, check=True, capture_output=True, text=True)
            print(f"round {r} {name} {tree}: {res.stdout.strip()}", flush=True)
    print("load", pathlib.Path("/proc/loadavg").read_text().split()[:3])
    out = []
    for name in "AB":
        with open(tmp / f"{name}.pkl", "rb") as f:
            out.append(pickle.load(f))
    return out
