"""The generated entry points (``_native/_generate.py`` from ``_declare.py``).

Oracles: the generator's own output (the files on disk must equal it); the ranges
written in ``_declare.py`` (a value just inside passes, just outside is refused
with a message naming the kernel and the argument); numpy's own alignment flag.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

import robokin
from robokin._native import kernels as K
from robokin.kinematics.ik import restart_seeds
from robokin.kinematics.ik.lm_options import option_vector
from robokin.kinematics.ik.restart_seeds import NO_TABLE

# The sources the generator writes (an installed wheel holds no csrc/ to compare).
NATIVE = Path(__file__).resolve().parents[2] / "src" / "robokin" / "_native"


def _generator():
    spec = importlib.util.spec_from_file_location("robokin_native_generate",
                                                  NATIVE / "_generate.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_generated_files_are_up_to_date():
    for path, text in _generator().outputs().items():
        assert path.read_text() == text, (
            f"{path.name} differs from what _generate.py writes from _declare.py: run "
            "python src/robokin/_native/_generate.py (setup.py does)")


def test_every_declared_kernel_and_constant_is_exported():
    d = _generator().load_declarations()
    for group in d.GROUPS:
        for k in group.kernels:
            assert callable(getattr(K, k.name)), k.name
            with pytest.raises(TypeError, match=rf"{k.name}\("):
                getattr(K, k.name)(*([None] * (len(k.args) + 1)))
        for c in group.constants:
            assert isinstance(getattr(K, c.name), int if c.type == "int" else float), c.name


def _lm_args():
    robot = robokin.load("ur5")
    q = np.zeros((2, 6)) + 0.3
    T = robot.fk(q)
    opts = option_vector(None, None, 1e-9, None, 100, 1.0)
    opts[K.O_USE_Q0] = 1.0
    tab, cstart, gdat = NO_TABLE
    return [robot.chain.arrays.packed, T, q + 1e-3, np.zeros((2, 1, 6)), opts,
            np.empty((2, 6 + K.N_RES)), tab, cstart, gdat, False]


@pytest.mark.parametrize(("index", "value"), [
    ("O_MAX_ITER", 0.0), ("O_MAX_ITER", 2.5), ("O_MAX_ITER", 1e12), ("O_USE_Q0", 2.0),
    ("O_TOL_P", np.nan), ("O_TOL_P", -1e-9), ("O_N_TABLE", 9.0), ("O_W", np.inf),
    ("O_SEED_SHRINK", 0.6), ("O_TABLE_ROT", -1.5), ("O_N_SEEDS", -1.0)])
def test_option_values_outside_their_ranges_are_refused(index, value):
    args = _lm_args()
    assert K.lm_solve(*args) == (0, -1)
    args[4] = args[4].copy()
    args[4][getattr(K, index)] = value
    with pytest.raises(ValueError, match="lm_solve: opts: a value outside its range"):
        K.lm_solve(*args)


def test_table_rows_indices_are_checked():
    """lm_solve checks the cell starts where it reads them (every visited cell's rows
    within [0, M]); here the one cell is read at once (no descent from q0)."""
    args = _lm_args()
    args[6] = np.zeros((3, 18))  # M = 3 rows
    args[8] = np.array([0, 0, 0, 1, 1, 1, 1.0])  # G = 1: cstart has 2 entries
    args[4] = args[4].copy()
    args[4][K.O_N_TABLE] = 1
    args[4][K.O_N_SEEDS] = 1
    args[4][K.O_USE_Q0] = 0.0  # the first attempt is the table's
    for good in ([0, 3], [0, 0], [3, 3]):
        args[7] = np.array(good, dtype=np.int64)
        K.lm_solve(*args)
    for bad in ([0, 4], [-1, 3], [2, 1]):  # past the table, negative, decreasing
        args[7] = np.array(bad, dtype=np.int64)
        with pytest.raises(ValueError, match="lm_solve: cstart: an index outside"):
            K.lm_solve(*args)
    args[7] = np.array([0, 1, 3], dtype=np.int64)  # G = 1 needs 2 entries
    with pytest.raises(ValueError, match="cstart does not match gdat"):
        K.lm_solve(*args)


def test_only_the_table_cells_lm_solve_reads_are_checked():
    """A corrupt cell start the search never reaches does not change a bit of the
    answer (oracle: the same call with the clean table), and one it reaches is
    refused. Fails on a kernel that scans every cell start at its entry (refused)."""
    robot = robokin.load("ur5")
    tab, cstart, gdat = restart_seeds.seed_table(robot.arm).kernel_args()
    G = int(gdat[6])
    q = np.array([[0.3, -1.2, 1.1, -0.4, 1.0, 0.2]])
    T = robot.fk(q)
    opts = option_vector(None, None, 1e-9, None, 100, 1.0)
    opts[K.O_USE_Q0] = 0.0
    opts[K.O_N_SEEDS] = 4
    opts[K.O_N_TABLE] = 4
    seeds = np.full((1, 4, 6), 0.5)
    target_cell = restart_seeds.grid_cells(T[:, :3, 3], gdat[:3], gdat[3:6], G)[0]
    far = (G**3 - 1) if target_cell < G**3 // 2 else 0  # a corner cell, not searched
    assert abs(far // (G * G) - target_cell // (G * G)) > 1

    def run(cs):
        out = np.empty((1, 6 + K.N_RES))
        K.lm_solve(robot.chain.arrays.packed, T, q, seeds, opts, out, tab, cs, gdat, False)
        return out

    clean = run(cstart)
    corrupt = cstart.copy()
    corrupt[far + 1] = len(tab) + 100  # rows past the table
    assert run(corrupt).tobytes() == clean.tobytes()
    corrupt = cstart.copy()
    corrupt[target_cell] = -5
    with pytest.raises(ValueError, match="lm_solve: cstart: an index outside"):
        run(corrupt)


def test_python_ints_are_range_checked_before_the_cast():
    rows, cstart, grid = np.zeros((1, 18)), np.array([0, 1]), np.array([0, 0, 0, 1, 1, 1, 1.0])
    T = np.eye(4)
    assert K.table_nearest(rows, cstart, grid, T, 1, 0.0).tolist() == [0]
    for k in (0, 9, 2**40, -(2**70)):
        with pytest.raises(ValueError, match=r"table_nearest: k must be in \[1, 8\]"):
            K.table_nearest(rows, cstart, grid, T, k, 0.0)
    with pytest.raises(TypeError, match="k must be an int"):
        K.table_nearest(rows, cstart, grid, T, 1.0, 0.0)
    with pytest.raises(ValueError, match="rot_w"):
        K.table_nearest(rows, cstart, grid, T, 1, np.nan)
    out = np.empty((1, 1, 6))
    with pytest.raises(ValueError, match="seed_uniforms: key must be in"):
        K.seed_uniforms(T[None], np.zeros((1, 6)), -1, 0, out)
    K.seed_uniforms(T[None], np.zeros((1, 6)), 2**64 - 1, 0, out)
    assert np.all((out >= 0) & (out < 1))


def test_index_arrays_are_checked():
    LB, known, C = np.zeros((3, 4)), np.zeros((3, 4), dtype=bool), np.zeros((3, 4))
    K.propagate_bounds(LB, known, C, np.array([0, 2]))
    for rows in ([3], [-1]):
        with pytest.raises(ValueError, match=r"propagate_bounds: rows: an index outside \[0, P - 1\]"):
            K.propagate_bounds(LB, known, C, np.array(rows))


def test_fk1_takes_the_general_path_for_a_misaligned_packed():
    robot = robokin.load("ur5")
    packed = robot.chain.arrays.packed
    raw = np.zeros(packed.nbytes + 8, dtype=np.uint8)
    shifted = raw[1:1 + packed.nbytes].view(np.float64)  # one byte off: not aligned
    shifted[:] = packed
    assert not shifted.flags.aligned
    q = np.full(6, 0.4)
    assert K.fk1(q, shifted) is None
    np.testing.assert_array_equal(K.fk1(q, packed), robot.fk(q))  # same bits
    with pytest.raises(ValueError, match="fk: packed must be a C-contiguous aligned"):
        K.fk(shifted, q[None], np.empty((1, 4, 4)))


def test_the_layout_the_kernels_parse_is_the_declared_one():
    d = _generator().load_declarations()
    for name in ("ur5", "panda"):
        arrays = robokin.load(name).chain.arrays
        parsed = K.layout(arrays.packed)
        names = [s.name for s in d.PACKED_LAYOUT]
        assert list(parsed)[3:] == names  # the C walk visits the declared sections in order
        at = 4
        for section in d.PACKED_LAYOUT:  # each where the declaration puts it
            value = np.asarray(getattr(arrays, section.name)).ravel()
            np.testing.assert_array_equal(arrays.packed[at:at + value.size], value)
            np.testing.assert_array_equal(parsed[section.name].ravel(), value)
            at += value.size
        assert at == arrays.packed.size
    assert K.LAYOUT_TAG == d.LAYOUT_TAG == arrays.packed[0]


def test_a_shape_the_descriptor_cannot_hold_is_refused_naming_the_kernel():
    # Oracle: the descriptor holds `sym`, `sym +- c`, `c` or `c + sym` only; any
    # other relation must be a Check, and the generator says which kernel.
    gen = _generator()
    d = gen.D  # the generator's own declaration classes
    for shape in (("N", "PK_N_OF(a->params)"), ("N", "2 * N"), ("N", "M + 1")):
        kernel = d.Kernel("probe", (d.Arr("x", "f64", shape),), "None", "probe")
        with pytest.raises(ValueError, match="probe: shape entry"):
            gen._Entry(kernel)


def test_every_checked_dimension_is_checked_by_the_descriptor_parser():
    # Oracle: the shapes declared in _declare.py; a good call runs, and changing
    # any one dimension that does not bind is refused naming the argument.
    pose = np.eye(4)[None].repeat(3, axis=0)
    args = [pose, pose.copy(), np.empty((3, 6))]
    K.pose_error(*args)
    for i, bad in ((1, np.eye(4)[None].repeat(2, axis=0)), (1, np.zeros((3, 4, 3))),
                   (2, np.empty((2, 6))), (2, np.empty((3, 5)))):
        call = list(args)
        call[i] = bad
        name = ("current", "target", "out")[i]
        with pytest.raises(ValueError, match=rf"pose_error: {name} must be \(N, "):
            K.pose_error(*call)
    ur5 = robokin.load("ur5")
    packed = ur5.chain.arrays.packed
    K.frames(packed, np.zeros((2, 6)), np.empty((2, 8, 4, 4)))
    with pytest.raises(ValueError, match=r"frames: out must be \(N, nc \+ 2, 4, 4\)"):
        K.frames(packed, np.zeros((2, 6)), np.empty((2, 7, 4, 4)))
    with pytest.raises(ValueError, match=r"frames: q must be \(N, n\)"):
        K.frames(packed, np.zeros((2, 5)), np.empty((2, 8, 4, 4)))
