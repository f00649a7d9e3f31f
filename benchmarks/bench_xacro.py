"""xacro expansion in a limited child process: the overhead on real files, the cost of bombs.

Run: ``python benchmarks/bench_xacro.py [--rounds 7]``.

1. **Correctness.** Each file's URDF from the child equals the in-process one
   (``robokin.io.xacro._expand``, the expansion itself) character for character.
2. **Overhead, in alternating rounds** (medians and ranges; the box is shared,
   so each round times both variants back to back): ``expand_xacro`` (fork a
   child, set its limits, expand, send the URDF back) against ``_expand`` in this
   process, on the test data's arm (three includes) and the rtb-data vendor
   xacros (ABB IRB 140, KUKA KR6 R700 sixx, Puma 560) when rtbdata is installed.
   Measured twice: in a small process (robokin and xacro imported) and after
   importing the heavy extras (MuJoCo, Dask, yourdfpy: a fork copies the page
   tables of a larger process).
3. **Bombs.** ``${9**9**9}``, ``${'a'*(2*10**8)}`` and a 1.6 KB chain of
   doubling string properties, each in a fresh interpreter: the time of the
   ``expand_xacro`` call, its error, and the child's peak RSS
   (``getrusage(RUSAGE_CHILDREN)``).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
DEMO = HERE.parent / "tests" / "data" / "xacro" / "demo_description"
HEAD = ('<?xml version="1.0"?>\n'
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n')


def files() -> list[tuple[str, Path, dict[str, Path]]]:
    """(label, xacro, package map) of every real file timed."""
    out = [("test data arm (3 files)", DEMO / "urdf" / "arm.urdf.xacro",
            {"demo_description": DEMO})]
    try:
        import rtbdata
    except ImportError:
        return out
    root = Path(rtbdata.__file__).parent / "xacro"
    out += [
        ("ABB IRB 140", root / "abb_irb140_description/urdf/irb140.xacro",
         {"abb_irb140": root / "abb_irb140_description"}),
        ("KUKA KR6 R700", root / "kuka_description/kuka_kr6/urdf/kr6r700sixx.xacro",
         {"kuka_kr6_support": root / "kuka_description/kuka_kr6",
          "kuka_resources": root / "kuka_description/kuka_resources"}),
        ("Puma 560", root / "unimation_puma560_description/urdf/puma560_robot.urdf.xacro",
         {"unimation_puma560_description": root / "unimation_puma560_description"}),
    ]
    return [f for f in out if f[1].is_file()]


def time_files(rounds: int) -> None:
    import warnings

    from robokin.io.ros_packages import PackageFinder
    from robokin.io.xacro import _expand, expand_xacro

    for label, path, pmap in files():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            child = expand_xacro(path, package_map=pmap).urdf
            here = _expand(path, {}, PackageFinder(pmap, near=path))[0]
        assert child == here, label
        a, b = [], []
        for _ in range(rounds):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t = time.perf_counter()
                expand_xacro(path, package_map=pmap)
                a.append(time.perf_counter() - t)
                t = time.perf_counter()
                _expand(path, {}, PackageFinder(pmap, near=path))
                b.append(time.perf_counter() - t)
        ma, mb = statistics.median(a) * 1e3, statistics.median(b) * 1e3
        print(f"  {label:26s} child {ma:7.1f} ms [{min(a) * 1e3:.1f}-{max(a) * 1e3:.1f}]"
              f"  in-process {mb:7.1f} ms [{min(b) * 1e3:.1f}-{max(b) * 1e3:.1f}]"
              f"  overhead {ma - mb:+6.1f} ms  ({len(child):,} characters, identical)")


BOMBS = {
    "${9**9**9} (CPU)": HEAD + '  <link name="${9**9**9}"/>\n</robot>\n',
    "${'a'*(2*10**8)} (memory)": HEAD + "  <link name=\"${'a'*(2*10**8)}\"/>\n</robot>\n",
    "28 doubling properties": HEAD + '  <xacro:property name="p0" value="aaaaaaaaaaaaaaaa"/>\n'
    + "".join(f'  <xacro:property name="p{i}" value="${{p{i - 1}}}${{p{i - 1}}}"/>\n'
              for i in range(1, 29)) + '  <link name="${p28}"/>\n</robot>\n',
}

BOMB_RUN = textwrap.dedent("""
    import resource, sys, time
    from robokin.io.xacro import expand_xacro
    t = time.monotonic()
    try:
        expand_xacro(sys.argv[1])
        what = "expanded"
    except Exception as exc:
        what = str(exc).split("expanding this file ")[-1].split(";")[0]
    dt = time.monotonic() - t
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"{dt:.2f} s, child peak RSS {peak:.0f} MB: {what}")
""")


def bombs() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        for label, text in BOMBS.items():
            f = Path(tmp) / "bomb.urdf.xacro"
            f.write_text(text)
            out = subprocess.run([sys.executable, "-c", BOMB_RUN, str(f)],
                                 capture_output=True, text=True, timeout=120)
            print(f"  {label:28s} ({len(text):,} bytes): "
                  f"{out.stdout.strip() or out.stderr.strip()[-300:]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    opts = parser.parse_args()
    print("overhead, small process (robokin + xacro):")
    time_files(opts.rounds)
    heavy = []
    for mod in ("mujoco", "distributed", "yourdfpy", "coal"):
        try:
            __import__(mod)
            heavy.append(mod)
        except ImportError:
            pass
    import resource

    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"overhead, after importing {', '.join(heavy)} (peak RSS {rss:.0f} MB):")
    time_files(opts.rounds)
    print("bombs (each in a fresh interpreter):")
    bombs()


if __name__ == "__main__":
    main()
