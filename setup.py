"""Build step for the C extensions; all metadata lives in pyproject.toml.

Both are optional: without a C compiler the build skips them and robokin uses its
numba kernels instead (see the comment at the top of each source).

* ``robokin.kinematics._fk_single``: single-configuration FK from Python.
* ``robokin.kinematics.ik._lm_lanes``: batch numeric IK, several targets per
  vector register.
"""

import sys


import numpy
from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "robokin.kinematics._fk_single",
            ["src/robokin/kinematics/_fk_single.c"],
            depends=["src/robokin/kinematics/_sincos_consts.h"],
            include_dirs=[numpy.get_include()],
            # no fused multiply-add: the same roundings as the numba kernels
            extra_compile_args=["-O3", "-ffp-contract=off"],
            optional=True,
        ),
        Extension(
            "robokin.kinematics.ik._lm_lanes",
            ["src/robokin/kinematics/ik/_lm_lanes.c"],
            depends=["src/robokin/kinematics/ik/_lm_lanes_body.h",
                     "src/robokin/kinematics/_sincos_consts.h"],
            include_dirs=[numpy.get_include()],
            extra_compile_args=[] if sys.platform == "win32" else
            ["-O3", "-fno-math-errno", "-Wno-psabi"],
            libraries=[] if sys.platform == "win32" else ["pthread"],
            optional=True,
        ),
    ]
)
