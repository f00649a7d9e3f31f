"""Build step for robokin's compiled kernels; all metadata lives in pyproject.toml.

One C source (``src/robokin/_native/csrc``) is compiled once per instruction set,
as separate extension modules: ``robokin._native._base`` for the compiler's
baseline target and, on x86-64 with GCC or clang, ``_avx2`` (AVX2 + FMA) and
``_avx512`` (AVX-512 F/DQ/VL). At import ``robokin._native`` picks the copy the CPU
runs. Nothing is compiled at run time.
"""

import platform
import sys

import numpy
from setuptools import Extension, setup

CSRC = "src/robokin/_native/csrc"
HEADERS = [f"{CSRC}/{h}" for h in ("lanes.h", "chain.h", "pool.h", "pool.c", "fk.c",
                                     "lm.c", "nearest.c", "six_r.c", "broadphase.c",
                                     "plan_geom.c", "plan_check.c", "plan_rrtc.c",
                                     "plan_path.c", "general6r.c", "module.c")]
UNIX = sys.platform != "win32"
# -fno-math-errno: sqrt inlines (and vectorises); no other fast-math licence
FLAGS = ["-O3", "-fno-math-errno", "-Wno-psabi"] if UNIX else ["/O2"]
LIBS = ["pthread"] if UNIX else []


def extension(name: str, source: str, extra: list[str]) -> Extension:
    return Extension(
        f"robokin._native.{name}",
        [f"{CSRC}/{source}"],
        depends=HEADERS,
        include_dirs=[numpy.get_include(), CSRC],
        extra_compile_args=FLAGS + extra,
        libraries=LIBS,
    )


modules = [extension("_base", "build_base.c", [])]
if UNIX and platform.machine().lower() in ("x86_64", "amd64"):
    modules.append(extension("_avx2", "build_avx2.c", ["-mavx2", "-mfma"]))
    modules.append(extension("_avx512", "build_avx512.c",
                             ["-mavx512f", "-mavx512dq", "-mavx512vl", "-mavx2", "-mfma"]))

setup(ext_modules=modules)
