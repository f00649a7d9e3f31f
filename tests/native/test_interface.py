"""robokin._native._interface: the typed Protocol matches every built copy.

The type checker sees the compiled kernels only through
:class:`robokin._native.Kernels`; these tests keep that declaration and the C
method tables and constants the same: the same names, functions as functions,
constants of the declared type, and each function's parameters as its C docstring
names them.
"""

from __future__ import annotations

import inspect
import re

import pytest

import robokin
from reference import kernel_copies
from robokin._native._interface import Kernels

COPIES = kernel_copies()
FUNCTIONS = {
    name: value
    for name, value in vars(Kernels).items()
    if inspect.isfunction(value) and not name.startswith("_")
}
CONSTANTS = {
    name: {"int": int, "float": float, "str": str}[hint]
    for name, hint in Kernels.__annotations__.items()
}


def _public(module):
    return {name for name in dir(module) if not name.startswith("_")}


@pytest.mark.parametrize("isa", list(COPIES))
def test_every_export_of_a_copy_is_declared_and_every_declaration_exported(isa):
    module = COPIES[isa]
    declared = set(FUNCTIONS) | set(CONSTANTS)
    assert _public(module) == declared, (
        f"undeclared in Kernels: {sorted(_public(module) - declared)}; "
        f"declared but not exported: {sorted(declared - _public(module))}"
    )


@pytest.mark.parametrize("isa", list(COPIES))
def test_constants_have_the_declared_types_and_functions_are_callable(isa):
    module = COPIES[isa]
    for name, kind in CONSTANTS.items():
        assert type(getattr(module, name)) is kind, name
    for name in FUNCTIONS:
        assert callable(getattr(module, name)), name


def _c_parameters(doc):
    """Parameter names of a C docstring ``name(a, b (N, 3), c) -> ...``."""
    head = re.match(r"\w+\((.*?)\)(?: ->|:|$)", doc.replace("\n", " "))
    assert head is not None, doc
    inner = re.sub(r"\s*\([^()]*\)", "", head.group(1))  # drop shapes "(N, 3)"
    return [part.strip() for part in inner.split(",") if part.strip()]


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_each_function_takes_the_parameters_its_c_docstring_names(name):
    declared = list(inspect.signature(FUNCTIONS[name]).parameters)[1:]  # drop self
    for isa, module in COPIES.items():
        doc = getattr(module, name).__doc__
        assert _c_parameters(doc) == declared, (isa, doc)


def test_the_packed_layout_constants_match_every_compiled_copy():
    # model/ does not import the kernels (layers point one way): the constants it
    # writes into ChainArrays.packed must equal chain.h's in every built copy
    from robokin._native import _declare
    from robokin.model import chain_arrays

    packed_tag = robokin.load("ur5").chain.arrays.packed[0]
    for copy in kernel_copies().values():
        assert copy.LAYOUT_TAG == _declare.LAYOUT_TAG == packed_tag
        assert copy.MAX_JOINTS == chain_arrays.MAX_JOINTS
