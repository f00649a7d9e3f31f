"""Freed memory reused during a task where Dask pinned glibc's thresholds (issue 25).

Oracle: the kernel's count of minor page faults (``getrusage``): an array that
comes from fresh ``mmap`` pages faults once per 4 KiB page; one that reuses heap
memory does not fault at all.
"""

import platform
import subprocess
import sys

import pytest

from robokin.cell._malloc import pinned_thresholds

CHILD = """
import resource
import numpy as np
from robokin.cell._malloc import reuse_freed_memory

def faults(rounds=40):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(rounds):
        a = np.ones(2**17)  # 1 MiB: below numpy's huge-page size, above 128 KiB
        del a
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

outside = faults()
with reuse_freed_memory():
    faults(1)  # the heap grows once
    inside = faults()
after = faults()
print(outside, inside, after)
"""


def run_child(env_extra):
    import os

    env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
    env.update(env_extra)
    out = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True,
                         text=True, check=True, timeout=60)
    return [int(x) for x in out.stdout.split()]


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="glibc's allocator")
def test_a_dask_worker_environment_gets_its_pages_reused_inside_a_task():
    # the environment Dask's nanny gives its workers
    outside, inside, after = run_child({"MALLOC_TRIM_THRESHOLD_": "65536"})
    assert outside >= 40 * 200  # ~256 fresh pages per MiB array
    assert inside < 200  # reused: (almost) no faults
    assert after >= 40 * 200  # restored: Dask's setting holds again between tasks


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="glibc's allocator")
def test_a_plain_process_is_left_alone():
    # no pinned threshold: glibc's dynamic threshold already reuses the memory,
    # and the block changes nothing
    outside, inside, after = run_child({})
    assert outside < 40 * 200 and inside < 200 and after < 40 * 200


def test_the_pinned_thresholds_are_read_from_the_environment():
    assert pinned_thresholds({}) is None
    assert pinned_thresholds({"MALLOC_TRIM_THRESHOLD_": "65536"}) == (65536, 131072)
    assert pinned_thresholds({"MALLOC_MMAP_THRESHOLD_": "1048576"}) == (131072, 1048576)
    assert pinned_thresholds({"MALLOC_TRIM_THRESHOLD_": "x"}) is None
