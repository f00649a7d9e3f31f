"""Build step for robokin's compiled kernels; all metadata lives in pyproject.toml.

One C source (``src/robokin/_native/csrc``) is compiled once per instruction set,
as separate extension modules: ``robokin._native._base`` for the compiler's
baseline target and, on x86-64 with GCC or clang, ``_avx2`` (AVX2 + FMA) and
``_avx512`` (AVX-512 F/DQ/VL). At import ``robokin._native`` picks the copy the CPU
runs. Nothing is compiled at run time.

Before compiling, ``src/robokin/_native/_generate.py`` writes the kernels' entry
points (``csrc/kernels_*.gen.h``) and their typed Protocol (``_interface.py``) from
the declarations in ``_declare.py`` (files that did not change are left alone).

Building from source needs a C compiler and the Python headers (the wheels need
neither). Before compiling, the build checks both with a two-line test file and
stops with one line saying what is missing, instead of the compiler's or
setuptools' own error.
"""

import importlib.util
import os
import platform
import shutil
import sys
import tempfile

import numpy
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.errors import CompileError, PlatformError

CSRC = "src/robokin/_native/csrc"
HEADERS = [f"{CSRC}/{h}" for h in (
    "lanes.h", "chain.h", "vec3.h", "subproblems.h", "ik_outputs.h", "args.h", "kernels_args.gen.h",
    "kernels_entry.gen.h", "pool.h", "pool.c", "fk.c", "lm.c", "nearest.c", "six_r.c",
    "broadphase.c", "general6r.c", "process.c", "manipulability.c", "pieper.c",
    "pieper_srs.c", "plan_geom.c", "plan_check.c", "plan_rrtc.c", "plan_path.c", "self_motion.c", "held_margins.c", "held_row.h", "held_closed.c", "held_manifold.c", "held_outputs.h", "brent.h", "linalg6.h",
    "near_coincident.c", "module.c")]
UNIX = sys.platform != "win32"
# -fno-math-errno: sqrt inlines (and vectorises); no other fast-math licence
# -Wall -Wextra -Wshadow: the unity build compiles without a warning (keep it so)
FLAGS = (["-O3", "-fno-math-errno", "-Wno-psabi", "-Wall", "-Wextra", "-Wshadow"] if UNIX
         else ["/O2"])
LIBS = ["pthread"] if UNIX else []
HOW = ("README.md, 'Installing', says what a source build needs; a wheel (built "
       "by .ci/wheel) installs without either")
PROBE = "#include <Python.h>\nint robokin_probe(void) { return 0; }\n"


def extension(name: str, source: str, extra: list[str]) -> Extension:
    """One instruction-set copy of the kernels: ``robokin._native.<name>``."""
    return Extension(
        f"robokin._native.{name}",
        [f"{CSRC}/{source}"],
        depends=HEADERS,
        include_dirs=[numpy.get_include(), CSRC],
        extra_compile_args=FLAGS + extra,
        libraries=LIBS,
    )


class BuildExt(build_ext):
    """``build_ext`` that first checks for a C compiler and the Python headers.

    The instruction-set copies compile side by side, one per core (``--parallel`` /
    ``-j`` still chooses): each is the whole unity source, about a minute of one core.
    """

    def finalize_options(self) -> None:
        """Default ``parallel`` to the cores, at most one per copy."""
        super().finalize_options()
        if not self.parallel:
            self.parallel = max(1, min(len(self.extensions or []), os.cpu_count() or 1))

    def build_extensions(self) -> None:
        """Check the toolchain (unix compilers), then compile every extension."""
        if self.compiler.compiler_type == "unix":
            self._check_toolchain()
        super().build_extensions()

    def _check_toolchain(self) -> None:
        cc = self.compiler.compiler_so[0]
        if shutil.which(cc) is None:
            origin = "named by CC" if os.environ.get("CC") else "Python's default"
            raise PlatformError(
                f"robokin: no C compiler: {cc!r} ({origin}) was not found; install "
                f"one (Debian/Ubuntu: apt-get install gcc python3-dev) or set CC; {HOW}")
        dirs = list(self.include_dirs or [])
        if not any(os.path.isfile(os.path.join(d, "Python.h")) for d in dirs):
            raise PlatformError(
                f"robokin: no Python headers (Python.h is not in "
                f"{', '.join(dirs) or 'any include folder'}); install them (Debian/Ubuntu: apt-get install python3-dev, Fedora: "
                f"dnf install python3-devel); {HOW}")
        with tempfile.TemporaryDirectory() as tmp:
            probe = os.path.join(tmp, "probe.c")
            with open(probe, "w") as fh:
                fh.write(PROBE)
            try:
                self.compiler.compile([probe], output_dir=tmp, include_dirs=dirs)
            except CompileError as exc:
                raise PlatformError(
                    f"robokin: the C compiler {cc!r} cannot build a Python extension "
                    f"here ({exc}); {HOW}") from None


def generate() -> None:
    """Write the entry points and the Protocol from _declare.py (_generate.py)."""
    spec = importlib.util.spec_from_file_location(
        "robokin_native_generate", "src/robokin/_native/_generate.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    module.write()


generate()
modules = [extension("_base", "build_base.c", [])]
if UNIX and platform.machine().lower() in ("x86_64", "amd64"):
    modules.append(extension("_avx2", "build_avx2.c", ["-mavx2", "-mfma"]))
    modules.append(extension("_avx512", "build_avx512.c",
                             ["-mavx512f", "-mavx512dq", "-mavx512vl", "-mavx2", "-mfma"]))

setup(ext_modules=modules, cmdclass={"build_ext": BuildExt})
