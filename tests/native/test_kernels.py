"""robokin._native: the one compiled source, its copies per instruction set, threads.

Mirrors ``src/robokin/_native``: the packed chain layout parses back to the
ChainArrays fields, every copy this CPU can run computes the same kinematics (to
rounding: the copies differ in fused multiply-adds), results do not depend on the
thread count, and the pool survives a fork.
"""

from __future__ import annotations

import multiprocessing
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import robokin
from reference import kernel_copies, random_q
from robokin import _native

ARMS = robokin.robots.names()


@pytest.mark.parametrize("name", ARMS)
def test_the_packed_layout_parses_back_to_the_chain_arrays(name):
    arrays = robokin.load(name).chain.arrays
    parsed = _native.kernels.layout(arrays.packed)
    assert parsed.pop("n_chain") == arrays.n_chain and parsed.pop("n") == arrays.n
    assert parsed.pop("identity") == arrays.identity
    for key, value in parsed.items():
        np.testing.assert_array_equal(value, getattr(arrays, key), err_msg=key)


def test_a_corrupted_layout_is_refused_not_read():
    packed = robokin.load("panda").chain.arrays.packed
    bad = packed.copy()
    bad[1] = 40.0  # more joints than the buffer holds
    with pytest.raises(ValueError, match="packed"):
        _native.kernels.layout(bad)
    with pytest.raises(ValueError, match="packed"):
        _native.kernels.fk(bad, np.zeros((1, 7)), np.empty((1, 4, 4)))


def test_the_best_copy_the_cpu_runs_is_the_one_in_use():
    copies = kernel_copies()
    best = list(copies)[-1]
    assert _import_with({}).stdout.split()[0] == best  # (ROBOKIN_ISA unset there)
    if not os.environ.get("ROBOKIN_ISA"):  # (the suite run with a copy forced: that one)
        assert best == _native.ISA
    assert copies[best].LANES >= copies["baseline"].LANES


@pytest.mark.parametrize("isa", ["baseline", "avx2"])
def test_robokin_isa_forces_a_lesser_copy(isa):
    code = "import robokin._native as n; print(n.ISA)"
    env = dict(os.environ, ROBOKIN_ISA=isa)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True).stdout.strip()
    expect = {"baseline": "baseline",
              "avx2": "avx2+fma" if "avx2+fma" in kernel_copies() else "baseline"}[isa]
    assert out == expect


@pytest.mark.parametrize("name", ARMS)
def test_every_copy_computes_the_same_fk_and_jacobians(name, rng):
    robot = robokin.load(name)
    Q = np.ascontiguousarray(random_q(robot, rng, 257))  # not a multiple of any W
    packed = robot.chain.arrays.packed
    results = {}
    for isa, mod in kernel_copies().items():
        T = np.empty((257, 4, 4))
        J = np.empty((257, 6, robot.n))
        T2 = np.empty((257, 4, 4))
        assert mod.fk(packed, Q, T) and mod.jacobian(packed, Q, J, T2)
        results[isa] = (T, J)
        np.testing.assert_array_equal(T, T2)  # one chain walk for both
    ref_T, ref_J = results["baseline"]
    for T, J in results.values():
        np.testing.assert_allclose(T, ref_T, rtol=0, atol=1e-14)
        np.testing.assert_allclose(J, ref_J, rtol=0, atol=1e-13)


def test_thread_count_changes_no_bit():
    robot = robokin.load("panda")
    Q = random_q(robot, np.random.default_rng(5), 20_000)
    k = _native.kernels
    threads = k.num_threads()
    try:
        k.set_num_threads(1)
        one = robot.fk(Q), robot.jacobian(Q[:3000])
        k.set_num_threads(2)
        two = robot.fk(Q), robot.jacobian(Q[:3000])
    finally:
        k.set_num_threads(threads)
    np.testing.assert_array_equal(one[0], two[0])
    np.testing.assert_array_equal(one[1], two[1])


def _child_fk(conn):
    robot = robokin.load("ur5")
    Q = np.random.default_rng(0).uniform(-1, 1, (50_000, 6))
    conn.send(float(robot.fk(Q)[:, 0, 3].sum()))
    conn.close()


@pytest.mark.skipif(sys.platform == "win32", reason="fork")
def test_the_thread_pool_survives_a_fork():
    robot = robokin.load("ur5")
    Q = np.random.default_rng(0).uniform(-1, 1, (50_000, 6))
    expect = float(robot.fk(Q)[:, 0, 3].sum())  # the parent's pool has run
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe()
    proc = ctx.Process(target=_child_fk, args=(child,))
    proc.start()
    assert parent.poll(60), "the forked child did not finish its batch"
    assert parent.recv() == expect
    proc.join(10)
    assert proc.exitcode == 0


def test_set_num_threads_clamps_and_reports():
    k = _native.kernels
    threads = k.num_threads()
    try:
        assert _native.set_num_threads(0) == 1
        assert _native.set_num_threads(1000) == 64
        assert _native.set_num_threads(2) == 2 == _native.num_threads()
    finally:
        k.set_num_threads(threads)


def _import_with(env: dict[str, str]) -> subprocess.CompletedProcess:
    """robokin._native imported in a fresh process with ``env`` over this one's
    environment less ``ROBOKIN_ISA`` (the suite may run with a copy forced)."""
    code = ("import robokin._native as n; "
            "print(n.ISA, n.num_threads(), n.single.num_threads())")
    base = {k: v for k, v in os.environ.items() if k != "ROBOKIN_ISA"}
    return subprocess.run([sys.executable, "-W", "always", "-c", code],
                          env=dict(base, **env), capture_output=True, text=True,
                          check=True)


@pytest.mark.parametrize(("value", "threads", "message"), [
    # atoi read 1e3 as one thread, and 0, -1, abc fell back without a word
    ("1e3", "default", "ROBOKIN_NUM_THREADS='1e3' is not a whole number from 1 to 64; "
                       "using {k} threads (the CPUs this process may use)"),
    ("0", "default", "ROBOKIN_NUM_THREADS='0' is not a whole number"),
    ("-1", "default", "ROBOKIN_NUM_THREADS='-1' is not a whole number"),
    ("abc", "default", "ROBOKIN_NUM_THREADS='abc' is not a whole number"),
    ("2.5", "default", "ROBOKIN_NUM_THREADS='2.5' is not a whole number"),
    ("1000", 64, "ROBOKIN_NUM_THREADS='1000' is more than 64; using 64 threads"),
    ("3", 3, None),
    (" 1 ", 1, None),
])
def test_robokin_num_threads_bad_values_warn_naming_the_value_used(value, threads,
                                                                   message):
    """Issue 25: bad values fell back silently; each is a warning naming the
    variable, its value and the count used (the oracle: num_threads() of every copy
    in use)."""
    default = min(len(os.sched_getaffinity(0)), 64)
    k = default if threads == "default" else threads
    res = _import_with({"ROBOKIN_NUM_THREADS": value})
    isa, n_kernels, n_single = res.stdout.split()
    assert int(n_kernels) == int(n_single) == k
    if message is None:
        assert "ROBOKIN_NUM_THREADS" not in res.stderr
    else:
        assert "RuntimeWarning: " + message.format(k=k) in res.stderr


@pytest.mark.parametrize("value", ["bogus", "sse9", ""])
def test_robokin_isa_unknown_values_warn_and_use_the_best_copy(value):
    best = _import_with({}).stdout.split()[0]
    res = _import_with({"ROBOKIN_ISA": value})
    assert res.stdout.split()[0] == best
    if value:
        assert (f"RuntimeWarning: ROBOKIN_ISA='{value}' is not one of baseline, avx2, "
                f"avx512; using {best} (the best copy this CPU runs)") in res.stderr
    else:
        assert "ROBOKIN_ISA" not in res.stderr


def test_robokin_isa_beyond_this_cpu_warns():
    best = _import_with({}).stdout.split()[0]
    res = _import_with({"ROBOKIN_ISA": "avx512"})
    assert res.stdout.split()[0] == best
    if best == "avx512":
        assert "ROBOKIN_ISA" not in res.stderr
    else:  # pragma: no cover - depends on the CPU
        assert f"has no avx512 copy; using {best}" in res.stderr


@pytest.mark.parametrize("module, runs", [("_avx2", "cpu_has_avx2_fma"),
                                          ("_avx512", "cpu_has_avx512")])
def test_a_copy_this_cpu_cannot_run_refuses_to_import_and_does_not_crash(module, runs):
    # A documentation tool (mkdocs' griffe) imports every submodule; the AVX-512 copy's
    # init once ran zmm moves before any check and killed it with SIGILL on a CPU
    # without AVX-512. Now: it imports where the CPU runs it, else an ImportError
    # naming the copy; in a fresh process, so a crash fails the test instead of pytest.
    code = (f"import robokin._native._base as b, robokin._native.{module} as m; "
            "print(m.ISA, m.cpu_has_avx2_fma())")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=False)
    isa = {"_avx2": "avx2+fma", "_avx512": "avx512"}[module]
    built = any(p.name.startswith(module + ".")
                for p in Path(_native.__file__).parent.iterdir())
    if not built:  # pragma: no cover - an install without that copy
        assert res.returncode == 1 and "ModuleNotFoundError" in res.stderr
    elif getattr(_native.kernels, runs)():
        assert res.returncode == 0, res.stderr
        assert res.stdout.split() == [isa, "True"]
    else:
        assert res.returncode == 1, (res.returncode, res.stderr)
        assert (f"ImportError: robokin._native.{module} is the {isa} copy of robokin's "
                "kernels and this CPU does not run it") in res.stderr
