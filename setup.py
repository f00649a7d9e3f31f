"""Build step for the one C extension; all metadata lives in pyproject.toml.

``robokin.kinematics._fk_single`` (single-configuration FK from Python, see the
comment at the top of its source) is optional: without a C compiler the build
skips it and robokin uses its numba kernel instead.
"""

import numpy
from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "robokin.kinematics._fk_single",
            ["src/robokin/kinematics/_fk_single.c"],
            include_dirs=[numpy.get_include()],
            # no fused multiply-add: the same roundings as the numba kernels
            extra_compile_args=["-O3", "-ffp-contract=off"],
            optional=True,
        )
    ]
)
