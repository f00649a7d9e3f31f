"""Every compiled kernel declared once: its arguments, shapes, options and constants.

This module is the one place (with the kernel's C body) a kernel is added.
``_generate.py`` reads it (``setup.py`` runs it before compiling; it imports
nothing from robokin) and writes

* ``csrc/chain_layout.gen.h``: the packed chain layout (``PACKED_LAYOUT`` below,
  which ``model/chain_arrays.py`` packs by) as an X-macro ``chain.h`` parses by;
* ``csrc/kernels_args.gen.h``: the kernel list ``KERNELS(X)``, per kernel a
  ``<name>_args`` struct (the checked arguments and the bound shape symbols) and
  the body's prototype ``static PyObject *<name>_body(const <name>_args *a)``; the
  option-vector indices (``enum``) and ranges;
* ``csrc/kernels_entry.gen.h``: per kernel a descriptor table (``KSpec``, one
  ``KArg`` row per argument) that ``csrc/args.h``'s ``kernel_args`` reads to
  unpack and check every argument (array dtype, ndim, C-contiguity, alignment,
  byte order, writeability, every shape relation, index arrays in range, option
  values in their declared ranges and whole where declared) before the body runs;
  the entry points and method table (macros over ``KERNELS``); ``add_constants``
  (every constant below);
* ``_interface.py``: the typed Protocol the type checker sees.

``tests/native/test_generated.py`` fails when a generated file differs from what
this module produces. ``docs/conventions.md`` ("Adding a kernel") says how to use it.

Shapes: a tuple of ints and strings. A bare name not seen before binds that
dimension (``N``); a name seen before, a C constant (``SR_N_PARAMS``) or
``sym +- c`` (``n + N_RES``) is checked; any other relation is a ``Check``.
``packed`` binds ``n`` (joints) and ``nc`` (chain coordinates). Bound names are ``npy_intp`` fields of the args struct, so the body reads ``a->N``.
"""

from __future__ import annotations

from dataclasses import dataclass

INF = float("inf")
BIG = 1.7976931348623157e308  # the largest finite double: "finite" bound


@dataclass(frozen=True)
class Arr:
    """An ndarray argument: dtype, shape, writeable (an output)."""

    name: str
    dtype: str  # f64, i64, i32, i8, u8, bool
    shape: tuple[int | str, ...]
    out: bool = False
    values: tuple[str, str] | None = None  # index arrays: every value in [lo, hi] (C exprs)
    monotone: bool = False  # values non-decreasing


@dataclass(frozen=True)
class Packed:
    """A chain's ``ChainArrays.packed`` vector, parsed into a ``Chain``."""

    name: str = "packed"


@dataclass(frozen=True)
class Int:
    """A Python int, range-checked before the cast to C ``long``."""

    name: str
    lo: int
    hi: int
    unsigned64: bool = False  # the full unsigned 64-bit range (a key)


@dataclass(frozen=True)
class Float:
    """A Python float (or int), range-checked (NaN fails)."""

    name: str
    lo: float = -INF
    hi: float = INF


@dataclass(frozen=True)
class Flag:
    """A truth value (Python's ``bool(x)``)."""

    name: str


@dataclass(frozen=True)
class Obj:
    """An object the body reads itself (the one-pose fast paths)."""

    name: str
    pytype: str = "object"


@dataclass(frozen=True)
class Opt:
    """One entry (or ``count`` entries) of an option vector, with its range."""

    name: str
    lo: float
    hi: float
    count: int = 1
    whole: bool = False  # a count or flag stored as a double: must be a whole number
    doc: str = ""


@dataclass(frozen=True)
class Opts:
    """A float64 option vector whose entries have names (``<prefix><name>``) and ranges."""

    name: str
    prefix: str
    size: str
    fields: tuple[Opt, ...]


@dataclass(frozen=True)
class Check:
    """A C condition on the bound symbols and ``a`` (the args struct) the entry tests."""

    cond: str
    message: str


Arg = Arr | Packed | Int | Float | Flag | Obj | Opts


@dataclass(frozen=True)
class Kernel:
    """One entry point: its arguments, extra checks, Python return type and doc."""

    name: str
    args: tuple[Arg, ...]
    returns: str
    doc: str
    checks: tuple[Check, ...] = ()


@dataclass(frozen=True)
class Const:
    """A module constant: its Python name, the C expression and type (int or float)."""

    name: str
    expr: str = ""
    type: str = "int"

    @property
    def c(self) -> str:
        """The C expression (the name itself by default)."""
        return self.expr or self.name


@dataclass(frozen=True)
class Group:
    """The kernels and constants of one C file."""

    file: str
    kernels: tuple[Kernel, ...] = ()
    constants: tuple[Const, ...] = ()
    init: str = ""  # a C function run once at module init, returning < 0 on error
    comment: str = ""


def _consts(names: str, prefix: str = "", py_prefix: str = "") -> tuple[Const, ...]:
    """Int constants from whitespace-separated names (C name = prefix + name)."""
    return tuple(Const(py_prefix + s, prefix + s) for s in names.split())


def _named(c: str) -> tuple[Const, ...]:
    """Int constants from whitespace-separated ``python_name=c_expr`` pairs."""
    return tuple(Const(*pair.split("=")) for pair in c.split())


LM_OPTS = Opts("opts", "O_", "N_OPTS", (
    Opt("W", 0.0, BIG, count=6, doc="6 task weights, 0 = masked out"),
    Opt("TOL_P", 0.0, BIG), Opt("TOL_R", 0.0, BIG),
    Opt("MAX_ITER", 1, 1e9, whole=True, doc="iterations per attempt"),
    Opt("USE_Q0", 0, 1, whole=True, doc="1: first attempt from q0"),
    Opt("MAX_STEP", 0.0, INF, doc="largest joint step per iteration"),
    Opt("MU0", 0.0, BIG),
    Opt("N_SEEDS", 0, 1e9, whole=True, doc="restarts available (<= seeds per target)"),
    Opt("PATH_MAX_JUMP", 0.0, INF, doc="path: largest joint change per sample"),
    Opt("STALL_EVERY", 1, 1e9, whole=True), Opt("STALL_RATIO", 0.0, BIG),
    Opt("MU_DOWN", 0.0, BIG), Opt("MU_UP", 0.0, BIG),
    Opt("SEED_SHRINK", 0.0, 0.5, doc="odd restarts seed in [lo + f span, hi - f span]"),
    Opt("N_TABLE", 0, 8, whole=True, doc="the first restarts start from this many table rows"),
    Opt("TABLE_ROT", -1.0, BIG,
        doc="[m^2] per unit squared rotation distance; 0 position only, < 0 no table"),
))

POSE = ("N", 4, 4)

FK = Group("fk.c / module.c", kernels=(
    Kernel("fk1", (Obj("q"), Obj("packed")), "F64 | None",
           "Pose (4, 4) of one configuration q (n,), or None for the general path."),
    Kernel("fk", (Packed(), Arr("q", "f64", ("N", "n")), Arr("out", "f64", POSE, out=True)),
           "bool", "Batch FK of q (N, n) into out (N, 4, 4); whether every q was finite."),
    Kernel("jacobian", (Packed(), Arr("q", "f64", ("N", "n")),
                        Arr("J", "f64", ("N", 6, "n"), out=True),
                        Arr("T", "f64", POSE, out=True)),
           "bool", "Jacobians J (N, 6, n) and poses T (N, 4, 4) of q (N, n); all finite."),
    Kernel("frames", (Packed(), Arr("q", "f64", ("N", "n")),
                      Arr("out", "f64", ("N", "nc + 2", 4, 4), out=True)),
           "bool", "Base, link frames and tool pose, out (N, n_chain + 2, 4, 4); all finite."),
    Kernel("layout", (Packed(),), "dict[str, Any]",
           "The sections the kernels parse out of packed (for tests)."),
    Kernel("abs_det_jacobian", (Packed(), Arr("q", "f64", ("N", "n")),
                                Arr("mask", "bool", ("N",)), Arr("out", "f64", ("N",), out=True)),
           "bool", "``|det J|`` of q (N, 6) where mask (N,), 0 elsewhere, into out (N,).\n\n"
           "For a 6-coordinate chain (``manipulability.c``); whether every masked row was\n"
           "finite (unmasked rows are never read).",
           checks=(Check("n == 6", "needs a 6-coordinate chain"),)),
), constants=_named("LANES=W MAX_JOINTS=MAXJ FK_PARALLEL_MIN") + (
    Const("MAX_TRANSLATION", type="float"), Const("LAYOUT_TAG", "PACKED_TAG", "float"),
    Const("MANIFOLD_SLACK", type="float")))

LM = Group("lm.c", kernels=(
    Kernel("lm_solve", (Packed(), Arr("targets", "f64", POSE), Arr("q0", "f64", ("N", "n")),
                        Arr("seeds", "f64", ("N", "R", "n")), LM_OPTS,
                        Arr("out", "f64", ("N", "n + N_RES"), out=True),
                        Arr("tab", "f64", ("M", "tab_cols")),
                        # cstart's values are checked where lm.c reads them (each cell's
                        # [start, end) within [0, M]; a bad one: ValueError after the
                        # run), not all G^3 + 1 of them on every call
                        Arr("cstart", "i64", ("C",)),
                        Arr("gdat", "f64", (7,)), Flag("parallel")),
           "tuple[int, int]",
           "Numeric IK of targets (N, 4, 4) into out (N, n + N_RES).\n\n"
           "Returns the number of targets not solved and the index of the first bad\n"
           "target or q0 (-1 if none).",
           checks=(Check("R >= 1", "seeds needs at least one row per target"),
                   Check("M == 0 || tab_cols == 12 + n", "tab must be (M, 12 + n)"),
                   Check("lm_mask_rows(a->opts) > 0", "no task row selected"),
                   Check("M == 0 || a->opts[O_N_TABLE] == 0 || grid_fits(a->gdat, C)",
                         "cstart does not match gdat"))),
    Kernel("seed_uniforms", (Arr("targets", "f64", POSE), Arr("q0", "f64", ("N", "n")),
                             Int("key", 0, 2**64 - 1, unsigned64=True), Int("base", 0, 2**62),
                             Arr("out", "f64", ("N", "R", "n"), out=True)),
           "None", "Restart numbers of targets (N, 4, 4) from q0 (N, n) into out (N, R, n).\n\n"
           "Uniform in [0, 1), a stream per target keyed by its pose, its q0 and\n"
           "``key``; row r of out is the stream's number ``base + r``.",
           checks=(Check("n >= 1 && n <= MAXJ", "q0 must have 1 to 32 columns"),)),
    Kernel("lm_path", (Packed(), Arr("targets", "f64", POSE), Arr("q_start", "f64", ("n",)),
                       LM_OPTS, Arr("out", "f64", ("N", "n + N_RES"), out=True)),
           "int", "Numeric IK along targets (N, 4, 4) from q_start (n,); first failure or -1."),
    Kernel("pose_error", (Arr("current", "f64", POSE), Arr("target", "f64", POSE),
                          Arr("out", "f64", ("N", 6), out=True)),
           "None", "Residual ``[p_t - p; log(R_t R^T)]`` of (N, 4, 4) poses into out (N, 6)."),
    Kernel("table_nearest", (Arr("rows", "f64", ("M", "cols")),
                             Arr("cstart", "i64", ("C",), values=("0", "M"), monotone=True),
                             Arr("grid", "f64", (7,)), Arr("T", "f64", (4, 4)),
                             Int("k", 1, 8), Float("rot_w", -1.0, BIG)),
           "I64", "Indices of the seed-table rows nearest the pose T (4, 4), nearest first.",
           checks=(Check("grid_fits(a->grid, C) && cols >= 12", "cstart does not match grid"),)),
    Kernel("nearest", (Packed(), Arr("Q", "f64", ("N", "k", "n")), Arr("ok", "bool", ("N", "k")),
                       Arr("qn", "f64", ("N", "n")), Arr("is_rev", "bool", ("n",)),
                       Arr("T", "f64", POSE), Arr("q", "f64", ("N", "n"), out=True),
                       Arr("err", "f64", ("N", 2), out=True), Arr("found", "bool", ("N",), out=True)),
           "None", "Per pose, the solution row of Q (N, k, n) nearest qn (N, n), into q."),
    Kernel("check_poses", (Arr("T", "f64", POSE), Float("tol", 0.0, BIG)), "tuple[int, int]",
           "``(code, index)`` of the first non-rigid pose of T (N, 4, 4), or (0, -1)."),
    Kernel("sincos", (Arr("x", "f64", ("N",)), Arr("s", "f64", ("N",), out=True),
                      Arr("c", "f64", ("N",), out=True), Int("scalar", 0, 1)),
           "None", "The kernels' sine and cosine of x (N,) into s and c: chain.h ``vsincos`` "
           "(scalar 0, the lanes') or ``sincos1`` (1, its one-value twin)."),
    Kernel("wrap_into", (Arr("v", "f64", ("N",)), Arr("lo", "f64", ("N",)),
                         Arr("hi", "f64", ("N",)), Arr("out", "f64", ("N",), out=True)),
           "None", "The wrap-into-limits rule (chain.h ``wrap_into``) of v (N,) into "
           "[lo, hi] (N,) into out: within the limits up to ``LIMIT_SLACK`` stays, "
           "else the fewest whole turns that fit, else unchanged."),
    Kernel("num_threads", (), "int", "Threads of the pool the batch kernels use."),
    Kernel("set_num_threads", (Int("k", -2**31, 2**31 - 1),), "int",
           "Set the threads of the pool (1 to 64); returns the number in use."),
    Kernel("cpu_has_avx2_fma", (), "bool", "Whether this CPU runs the AVX2 + FMA copy."),
    Kernel("cpu_has_avx512", (), "bool", "Whether this CPU runs the AVX-512 copy."),
), constants=_consts(
    "N_RES R_ERR R_EP R_ER R_ITERS R_RESTARTS R_CODE CODE_OK CODE_ITER CODE_STALL "
    "CODE_BAD_TARGET CODE_JUMP CODE_NOT_RUN CODE_BAD_Q0 TAB_K_MAX"),
    comment="lm_solve / lm_path: option indices (O_*, N_OPTS), result columns, codes")

SIX_R = Group("six_r.c", kernels=(
    Kernel("six_r_ik1", (Obj("T"), Arr("params", "f64", ("SR_N_PARAMS",)), Float("q6"), Packed()),
           "tuple[int, F64, Bools, Bools, Bools] | tuple[int, None, None, None, None]",
           "``(code, Q (8, 6), valid, singular, within_limits (8,))`` of one pose.",
           checks=(Check("six_r_params_ok(a->params)", "params is not a 6R parameter vector"),
                   Check("n == 6 && nc == 6", "packed is not a 6R chain"))),
    Kernel("six_r_ik", (Arr("params", "f64", ("SR_N_PARAMS",)), Arr("T", "f64", POSE),
                        Arr("qn", "f64", ("m", 6)), Packed()),
           "tuple[F64, Bools, Bools, Bools, npt.NDArray[np.int8]]",
           "``(Q (N, 8, 6), valid, singular, within_limits (N, 8), status (N,))``.",
           checks=(Check("six_r_params_ok(a->params)", "params is not a 6R parameter vector"),
                   Check("n == 6 && nc == 6", "packed is not a 6R chain"),
                   Check("m >= 1", "qn needs a row"))),
    Kernel("atan2", (Arr("y", "f64", ("N",)), Arr("x", "f64", ("N",)),
                     Arr("out", "f64", ("N",), out=True)),
           "None", "The kernels' atan2 of y, x (N,) into out."),
    Kernel("sp4_pair", (Arr("x", "f64", ("N", 7)), Float("tol", 0.0, BIG), Flag("mirror"),
                        Arr("lane", "f64", ("N", 8), out=True), Arr("one", "f64", ("N", 8), out=True)),
           "None", "Subproblem 4 of rows x (N, 7) in lanes and one at a time (for tests).\n\n"
           "x rows: A, B, rhs, disc, phi, cos phi, sin phi; out rows: t0, t1, c0, c1, s0,\n"
           "s1, has a root, has two."),
), constants=_consts(
    "AXES POINTS WRIST PERP2 TOOL_T TOOL_R PERP SIGN OFFSET LO HI S3 S4 SING_TOL DISC_TOL "
    "MIRROR A3 B3 C3 PHI3 CPHI3 SPHI3 A5 B5 C5 PHI5 CPHI5 SPHI5 AA BB FAMILY E5 PLANE "
    "SPLIT_TOL TOL_P TOL_R CHECK SIZE N_PARAMS THREE_PARALLEL SPHERICAL_WRIST BAD_POSE", "SR_")
    + _named("STATUS_OK=SR_OK STATUS_OUT_OF_REACH=SR_OUT_OF_REACH "
             "STATUS_NO_ORIENTATION=SR_NO_ORIENTATION SIX_R_PARALLEL_MIN=SR_PARALLEL_MIN"),
    comment="indices into a 6R parameter vector (N_PARAMS entries, _six_r.pack), codes")

PIEPER = Group("pieper.c", kernels=(
    Kernel("pieper_ik1", (Obj("T"), Arr("params", "f64", ("PK_N_PARAMS",)), Float("x"),
                          Obj("qn", "F64 | None")),
           "tuple[int, F64, Bools, Bools, Bools] | tuple[int, None, None, None, None]",
           "``(code, Q (8, n), valid, singular, within_limits (8,))`` of one pose.",
           checks=(Check("pk_params_ok(a->params)", "params is not a Pieper parameter vector"),)),
    Kernel("pieper_ik", (Arr("params", "f64", ("PK_N_PARAMS",)), Arr("T", "f64", POSE),
                         Arr("x", "f64", ("m",)), Arr("qn", "f64", ("mq", "nq"))),
           "tuple[F64, Bools, Bools, Bools, npt.NDArray[np.int8]]",
           "``(Q (N, 8, n), valid, singular, within_limits (N, 8), status (N,))``.",
           checks=(Check("pk_params_ok(a->params)", "params is not a Pieper parameter vector"),
                   Check("m >= 1 && mq >= 1", "x and qn need a row"),
                   Check("nq == PK_N_OF(a->params)", "qn must be (mq, PK_N_OF(a->params))"))),
    Kernel("pieper_limit_rows", (Arr("params", "f64", ("PK_N_PARAMS",)), Arr("T", "f64", POSE),
                                 Arr("x", "f64", ("N",)),
                                 Arr("Q", "f64", ("N", "k", "nq"), out=True),
                                 Arr("valid", "bool", ("N", "k")),
                                 Arr("singular", "bool", ("N", "k")),
                                 Arr("inside", "bool", ("N", "k"), out=True)),
           "None", "Rows of a held 7R chain moved into the limits in place (pk_walk, pk_pin).",
           checks=(Check("pk_params_ok(a->params)", "params is not a Pieper parameter vector"),
                   Check("PK_N_OF(a->params) == 7.0", "params must hold a joint of a 7R chain"),
                   Check("nq == 7", "Q must be (N, k, 7)"),
                   Check("k >= 1 && k <= 1024", "Q needs 1 to 1024 rows per pose"))),
    Kernel("pieper_roots", (Arr("coeffs", "f64", (5,)), Arr("re", "f64", (4,), out=True),
                            Arr("im", "f64", (4,), out=True)),
           "None", "The four roots of a quartic (coefficients lowest order first).",
           checks=(Check("a->coeffs[4] != 0.0", "the leading coefficient is zero"),)),
), constants=_consts(
    "N HELD CASE SING_TOL SCALE POINT AXES POINTS TOOL_R TOOL_T SIGN OFFSET LO HI TAG "
    "N_PARAMS START END BOTH POINT2 DEGENERATE BAD_POSE PARALLEL_MIN", "PK_", "PIEPER_")
    + (Const("PIEPER_MAX_JOINTS", "PK_MAXJ"), Const("PIEPER_TAG_VALUE", "PK_TAG_VALUE", "float")),
    comment="Pieper parameter vector layout (pieper.setup), triple cases, status codes")

GENERAL6R = Group("general6r.c", kernels=(
    Kernel("general6r_solve", (
        Packed(), Arr("params", "f64", ("P",)), Arr("T", "f64", POSE),
        Arr("Q", "f64", ("N", 16, 6), out=True), Arr("valid", "bool", ("N", 16), out=True),
        Arr("inside", "bool", ("N", 16), out=True), Arr("sigma", "f64", ("N", 16), out=True),
        Arr("status", "i64", ("N",), out=True), Arr("diag", "i64", ("N",), out=True),
        Arr("stats", "f64", ("N", 12), out=True), Flag("parallel")),
        "None", "Every solution of poses T (N, 4, 4): Q (N, 16, 6), masks (N, 16), ...",
        checks=(Check("g6_chain_ok(&a->packed)",
                      "the chain is not 6R revolute without dependent joints"),
                Check("g6_params_ok(a->params, (long)P)",
                      "params is not a general 6R parameter vector"))),
    Kernel("general6r_fit_rows", (Arr("consts", "f64", (7, 4, 4)), Int("a", 1, 3),
                                  Arr("angles", "f64", ("M", 3)), Arr("X", "f64", ("M", 27), out=True),
                                  Arr("Y", "f64", ("M", 14), out=True)),
           "None", "The left side's fitting rows at angles (M, 3): X (M, 27), Y (M, 14)."),
    Kernel("general6r_candidates", (Arr("params", "f64", ("P",)), Arr("T", "f64", (4, 4)),
                                    Arr("out", "f64", ("G6_MAXCAND", 6), out=True)),
           "tuple[int, int]",
           "One pose's candidates before the polish (chain values) into out; (n, flags).",
           checks=(Check("g6_params_ok(a->params, (long)P)",
                         "params is not a general 6R parameter vector"),)),
    Kernel("general6r_roots", (Arr("c", "f64", ("D",)), Arr("wr", "f64", ("D - 1",), out=True),
                               Arr("wi", "f64", ("D - 1",), out=True)),
           "bool", "Roots of the polynomial with coefficients c (low order first), into wr, wi.",
           checks=(Check("D >= 2 && D - 1 <= G6_MAXDEG && a->c[D - 1] != 0.0 && "
                         "isfinite(a->c[D - 1])",
                         "need 1 <= degree <= 32 and a finite non-zero leading coefficient"),)),
), constants=_consts(
    "G6_MAXSOL G6_MAXCAND G6_MAXVAR GP_NVAR GP_TAIL_TOL GP_NULL_TOL GP_IMAG_TOL GP_TOL "
    "GP_DEDUPE GP_MAX_ITER GP_PAIR_GAP GP_SCALE GP_FALLBACK GP_NEAR_TAIL GP_HEAD VB_DIR VB_A "
    "VB_MULT VB_C VB_CI VB_P VB_SIZE G6_OK G6_NONE G6_DEGENERATE G6_BAD_POSE G6F_DEGENERATE "
    "G6F_CLUSTER G6F_SECONDARY G6F_SEC_DEGENERATE G6F_SEC_CLUSTER G6F_PROJECTED "
    "G6F_PROJ_DEGENERATE G6F_RESCUED G6F_NOISY G6F_SEC_NOISY G6F_EIGEN G6_DIAG_CAND_SHIFT"),
    init="g6_init", comment="general6r_solve: solutions per pose, parameter layout, codes")

_PAIRS = (Arr("pa", "i64", ("P",), values=("0", "S - 1")), Arr("pb", "i64", ("P",)), Arr("is_self", "bool", ("P",)))
BROADPHASE = Group("broadphase.c", kernels=(
    Kernel("rounded_box_bounds", (
        Arr("frames", "f64", ("m", "L", 4, 4)), Arr("link", "i64", ("S",), values=("0", "L - 1")),
        Arr("local", "f64", ("S", 4, 4)), Arr("h", "f64", ("S", 3)), Arr("r", "f64", ("S",)),
        Arr("ob_pose", "f64", ("O", 4, 4)), Arr("ob_h", "f64", ("O", 3)), Arr("ob_r", "f64", ("O",)),
        *_PAIRS, Arr("skip", "bool", ("P",)), Arr("out", "f64", ("P", "m"), out=True)),
        "None", "Separating-axis lower bounds of every pair at every sample, into out."),
    Kernel("capsule_distances", (
        Arr("frames", "f64", ("m", "L", 4, 4)), Arr("link", "i64", ("S",), values=("0", "L - 1")),
        Arr("seg", "f64", ("S", 2, 3)), Arr("seg_r", "f64", ("S",)),
        Arr("ob_seg", "f64", ("O", 2, 3)), Arr("ob_r", "f64", ("O",)), *_PAIRS,
        Arr("pairs", "i64", ("k",), values=("0", "P - 1")), Arr("out", "f64", ("k", "m"), out=True)),
        "None", "Exact distances of the listed capsule/sphere pairs at every sample."),
    Kernel("propagate_bounds", (Arr("LB", "f64", ("P", "m"), out=True),
                                Arr("known", "bool", ("P", "m")), Arr("C", "f64", ("P", "m")),
                                Arr("rows", "i64", ("k",), values=("0", "P - 1"))),
           "None", "Spread known distances through the motion bounds, in place in LB."),
    Kernel("motion_bounds", (
        Packed(), Arr("q", "f64", ("m", "n")), Arr("frames", "f64", ("m", "nc + 2", 4, 4)),
        Arr("link", "i64", ("S",), values=("0", "nc + 1")), Arr("sph_c", "f64", ("nq", 3)),
        Arr("sph_r", "f64", ("nq",)), Arr("sph_start", "i64", ("S",), values=("0", "nq")),
        Arr("sph_count", "i64", ("S",), values=("0", "nq")), Arr("reach", "f64", ("nc", "S")),
        Arr("spins", "bool", ("S",)), *_PAIRS, Arr("out", "f64", ("P", "m - 1"), out=True)),
        "None", "Per interval and pair, the bound on the change of the distance, into out.",
        checks=(Check("m >= 1", "q needs a row"),)),
    Kernel("seg_seg", (Arr("pts", "f64", ("N", 4, 3)), Arr("out", "f64", ("N",), out=True)),
           "None", "Segment-segment distances of pts (N, 4, 3) into out (N,)."),
), constants=(Const("BP_CHUNK_WORK"),))

PROCESS = Group("process.c", kernels=(
    Kernel("process_nodes", (
        Packed(), Arr("Q", "f64", ("P", "n")), Arr("valid", "bool", ("P",)),
        Arr("singular", "bool", ("P",)), Arr("mode", "u8", ("n",), ), Arr("weights", "f64", ("PW_N",)),
        Arr("Qc", "f64", ("P", "n"), out=True), Arr("cost", "f64", ("P",), out=True),
        Arr("mu", "f64", ("P",), out=True), Arr("code", "i8", ("P",), out=True)),
        "None", "Per node of Q (P, n): canonical values Qc, cost, manipulability, status.",
        checks=(Check("pr_modes_ok(&a->packed, a->mode)",
                      "a turn mode on a coordinate that does not wrap"),)),
    Kernel("process_dp", (
        Arr("Q", "f64", ("L", "M", "n")), Arr("cost", "f64", ("L", "M")), Arr("circle", "u8", ("n",)),
        Float("max_step", 5e-324, INF), Float("weight", 0.0, BIG), Arr("start", "f64", ("M",)),
        Arr("forbidden", "i64", ("F", 3)), Arr("value", "f64", ("L", "M"), out=True),
        Arr("pred", "i32", ("L", "M"), out=True), Arr("restart", "u8", ("L",), out=True),
        Arr("choice", "i32", ("L",), out=True)),
        "int", "The exact shortest path through layers Q (L, M, n); returns the segments.",
        checks=(Check("L >= 1 && M >= 1 && M <= 0x3fffffff && n >= 1 && n <= MAXJ",
                      "Q must have a layer, a node and 1 to 32 joints"),
                Check("pr_forbidden_ok(a->forbidden, F, L, M)",
                      "forbidden edges out of range or not sorted by (layer, v)"))),
    Kernel("process_clusters", (Arr("Q", "f64", ("P", "M", "n")), Arr("cost", "f64", ("P", "M")),
                                Arr("circle", "u8", ("n",)), Arr("out", "f64", ("P", "P"), out=True)),
           "None", "The least largest-joint-change between every two layers into out (P, P).",
           checks=(Check("n >= 1 && n <= MAXJ && M <= 0x3fffffff && P <= 0x3fffffff",
                         "Q must have 1 to 32 joints"),)),
    Kernel("process_pairs", (Arr("A", "f64", ("na", "n")), Arr("B", "f64", ("nb", "n")),
                             Arr("circle", "u8", ("n",)), Arr("out", "f64", ("na", "nb"), out=True)),
           "None", "The largest joint change between every row of A (a, n) and B (b, n).",
           checks=(Check("n >= 1 && n <= MAXJ", "A must have 1 to 32 joints"),)),
    Kernel("process_limit_cost", (Arr("values", "f64", ("P",)), Float("lo"), Float("hi"),
                                  Float("margin"), Arr("out", "f64", ("P",), out=True)),
           "None", "The limit cost of each value (P,) into out (P,)."),
), constants=_consts(
    "PN_OK PN_NONE PN_LIMITS PN_SINGULAR PM_PLAIN PM_TURN PM_CIRCLE PW_SING_W PW_SING_MARGIN "
    "PW_SING_TOL PW_MU_REF PW_LIM_W PW_LIM_MARGIN PW_N PR_MAXB")
    + (Const("PR_LIMIT_TOL", type="float"),),
    comment="node status codes, coordinate modes, the weights layout, the bucket cap")

RC_OPTS = Opts("opts", "RC_", "RC_N_OPTS", (
    Opt("RANGE", 5e-324, BIG, doc="[joint units] longest step of an extension"),
    Opt("TIME", -INF, INF, doc="[s] time limit of the search"),
    Opt("MAX_NODES", 1, 1e9, whole=True, doc="most nodes of both trees"),
))
SP_OPTS = Opts("opts", "SP_", "SP_N_OPTS", (
    Opt("VERTEX_TRIES", 0, 1e12, whole=True, doc="vertex-pair shortcut attempts"),
    Opt("TRIES", 0, 1e12, whole=True, doc="point-pair shortcut attempts"),
    Opt("MAX_FAIL", 0, 1e12, whole=True, doc="failures in a row that end a phase"),
    Opt("TIME", -INF, INF, doc="[s] time limit of each phase"),
    Opt("CUT_ROUNDS", 0, 1000, whole=True, doc="rounds of corner cutting"),
    Opt("SHARP_TURN", -BIG, BIG, doc="[rad] corners turning more than this are cut"),
))

_MODEL = Obj("model", "object")  # plan_model's capsule; the body checks it and its sizes
_EXACT = Obj("exact", "object")  # None or a callable (p, q) -> distance (coal)
_SEED = Int("seed", 0, 2**64 - 1, unsigned64=True)
_STATS = "tuple[int, int, int, int, int, int]"
PLAN_CHECK = Group("plan_check.c", kernels=(
    Kernel("plan_model", (Arr("packed", "f64", ("len",)), Arr("shape_i", "i64", ("N", 4)),
                          Arr("shape_f", "f64", ("N", 21)), Arr("hull", "f64", ("H", 3)),
                          Arr("pair_i", "i64", ("P", 7)), Arr("reach", "f64", ("S_r", "nc")),
                          Int("S", 0, 1000000)),
           "object", "The compiled planning model of a robot in a scene (a capsule).\n\n"
           "shape_i (N, 4): core kind, link (-1: object), hull start, hull count;\n"
           "shape_f (N, 21): rb pose, half sizes, radius, cylinder radius; hull (H, 3);\n"
           "pair_i (P, 7): shapes a, b, method, self, mover, j0, j1; reach (S, nc).",
           checks=(Check("S_r == a->S && a->S <= N && N <= 1000000 && P <= 10000000",
                         "reach must be (S, nc) with S <= N <= 1000000 shapes, P <= 10000000 "
                         "pairs"),)),
    Kernel("plan_check_states", (_MODEL, Arr("q", "f64", ("m", "n")), Arr("margin", "f64", ("P",)),
                                 _EXACT, Arr("status", "i64", ("m",), out=True),
                                 Arr("pair", "i64", ("m",), out=True)),
           _STATS, "Validity of states q (m, n) into status (m,) and pair (m,); work counters."),
    Kernel("plan_check_edges", (_MODEL, Arr("q0", "f64", ("m", "n")), Arr("q1", "f64", ("m", "n")),
                                Arr("margin", "f64", ("P",)), _EXACT,
                                Arr("status", "i64", ("m",), out=True),
                                Arr("pair", "i64", ("m",), out=True),
                                Arr("where", "f64", ("m",), out=True)),
           _STATS, "Validity of the straight edges q0 -> q1 (m, n); work counters."),
    Kernel("plan_distances", (_MODEL, Arr("q", "f64", ("m", "n")),
                              Arr("out", "f64", ("m", "P"), out=True)),
           "None", "Certified lower bounds on every pair's distance at q (m, n) into out (m, P)."),
), constants=_consts(
    "PC_FREE PC_HIT PC_UNDECIDED PG_POINT PG_SEGMENT PG_BOX PG_CYLINDER PG_HULL PD_SEGSEG "
    "PD_SEGBOX PD_BOXSEG PD_GJK PD_HULL") + (Const("PC_EPS", type="float"),),
    comment="check results (PC_*), core kinds of shapes (PG_*), pair distance methods (PD_*), "
    "the distance taken off every computed one [m]")

PLAN_RRTC = Group("plan_rrtc.c", kernels=(
    Kernel("plan_rrtc", (_MODEL, Arr("start", "f64", ("n",)), Arr("goals", "f64", ("k", "n")),
                         Arr("lo", "f64", ("n",)), Arr("hi", "f64", ("n",)),
                         Arr("margin", "f64", ("P",)), RC_OPTS, _SEED, _EXACT),
           "tuple[int, F64 | None, int, " + _STATS + ", tuple[int, int, int, float]]",
           "RRT-Connect: (code, path (K, n) or None, goal row, counters, search).",
           checks=(Check("k >= 1", "goals needs a row"),)),
), constants=_consts("RC_SOLVED RC_TIMEOUT RC_NODES RC_FAILED"),
    comment="plan_rrtc result codes")

PLAN_PATH = Group("plan_path.c", kernels=(
    Kernel("plan_simplify", (_MODEL, Arr("path", "f64", ("K", "n")), Arr("margin", "f64", ("P",)),
                             SP_OPTS, _SEED, _EXACT),
           "tuple[F64, " + _STATS + "]",
           "Shortcuts, then sharp corners cut, of path (K, n); (path, counters).",
           checks=(Check("K >= 1", "path needs a row"),)),
))

SELF_MOTION = Group("self_motion.c", kernels=(
    Kernel("swivel_rows", (Arr("params", "f64", ("SM_N_PARAMS",)), Arr("T", "f64", POSE),
                           Arr("psi", "f64", ("N", "m")), Arr("Q", "f64", ("N", "m", 8, 7), out=True),
                           Arr("valid", "bool", ("N", "m", 8), out=True),
                           Arr("sing", "bool", ("N", "m", 8), out=True)),
           "None", "Every SRS configuration of poses T (N, 4, 4) at swivel angles psi (N, m): "
                   "Q (N, m, 8, 7), valid, singular (N, m, 8).",
           checks=(Check("sm_params_ok(a->params)", "params is not a swivel parameter vector"),)),
    Kernel("swivel_manifold", (Arr("params", "f64", ("SM_N_PARAMS",)), Arr("T", "f64", POSE),
                               Arr("iv", "f64", ("N", 8, "SM_MAXI", 2), out=True),
                               Arr("niv", "i64", ("N", 8), out=True),
                               Arr("pts", "f64", ("N", "SM_MAXP", 4), out=True),
                               Arr("npts", "i64", ("N",), out=True)),
           "None", "Per pose: the swivel intervals inside every limit per branch (N, 8, "
                   "SM_MAXI, 2) with counts (N, 8); points [psi, branch, joint, kind] "
                   "(N, SM_MAXP, 4) with counts (N,).",
           checks=(Check("sm_params_ok(a->params)", "params is not a swivel parameter vector"),)),
    Kernel("swivel_manifold_one", (Arr("params", "f64", ("SM_N_PARAMS",)),
                                   Arr("T", "f64", (4, 4))),
           "tuple[F64, I64, F64, bool]", "``swivel_manifold`` of one pose T (4, 4), packed: "
                                         "new arrays of its intervals (m, 2) branch by branch, "
                                         "their branches (m,) and its points (p, 4); close: "
                                         "two crossings of a branch within SM_PAIR, one within "
                                         "it of +-pi or an interval at most SM_POINT long. "
                                         "One thread.",
           checks=(Check("sm_params_ok(a->params)", "params is not a swivel parameter vector"),)),
    Kernel("swivel_near", (Arr("params", "f64", ("SM_N_PARAMS",)), Arr("T", "f64", POSE),
                           Arr("q_near", "f64", ("N", 7)), Arr("q", "f64", ("N", 7), out=True),
                           Arr("psi", "f64", ("N",), out=True),
                           Arr("slot", "i64", ("N",), out=True),
                           Arr("dist", "f64", ("N",), out=True),
                           Arr("found", "bool", ("N",), out=True)),
           "None", "Per pose: the in-limit configuration nearest q_near (N, 7) (2 pi wrapped "
                   "distance) on the exact swivel intervals: q (N, 7), its psi, slot and "
                   "distance (N,); found (N,) false (q NaN) where no part is inside.",
           checks=(Check("sm_params_ok(a->params)", "params is not a swivel parameter vector"),)),
), constants=_consts(
    "H O S W MR MT SIGN OFFSET LO HI REF TAG ARC LIMCS FOLDCS N_PARAMS MAXI MAXP KIND_LOWER "
    "KIND_UPPER "
    "KIND_ALIGNED KIND_FOLD", "SM_", "SM_") + tuple(Const(c, c, "float") for c in (
        "SM_TAG_VALUE", "SM_PAIR", "SM_POINT")),
    comment="swivel parameter vector layout (swivel.SwivelArm.packed), point kinds")

REACH = Group("reach.c", kernels=(
    Kernel("six_r_reach", (Arr("params", "f64", ("SR_N_PARAMS",)), Arr("T", "f64", ("G", "K", 4, 4)),
                           Packed(), Flag("with_w"), Arr("counts", "u8", ("G", "K"), out=True),
                           Arr("best", "f64", ("G",), out=True)),
           "None", "A reach map's 6R closed form in one pass, T (G voxels, K targets each).\n\n"
                   "Per target the solutions inside the limits into counts (G, K); with ``with_w`` the\n"
                   "best ``|det J|`` over a voxel's solutions into best (G,) (0: none).",
           checks=(Check("six_r_params_ok(a->params)", "params is not a 6R parameter vector"),
                   Check("n == 6 && nc == 6", "packed is not a 6R chain"),
                   Check("K >= 1", "T needs a target per voxel"))),
))

@dataclass(frozen=True)
class Section:
    """One section of a chain's packed vector: ``ChainArrays`` field, ``Chain`` field, shape.

    Dimensions are ints or ``"nc"``, ``"n"``, ``"nc + 1"`` (C and Python read them alike).
    """

    name: str
    c_field: str
    shape: tuple[int | str, ...]


#: packed[0]: the layout's version, checked by chain.h's chain_view.
LAYOUT_TAG = 7391.0
#: packed[0:4] = [LAYOUT_TAG, nc, n, identity], then these sections, in this order.
PACKED_LAYOUT: tuple[Section, ...] = (
    Section("consts", "consts", ("nc + 1", 4, 4)),  # C_0 .. C_nc
    Section("xform", "xform", ("nc + 1", 6)),  # per constant: [1, cos a, sin a, t] or 0
    Section("kind", "kind", ("nc",)),  # 1.0 prismatic, 0.0 revolute
    Section("sign", "sign", ("nc",)),
    Section("offset", "offset", ("nc",)),
    Section("M", "M", ("nc", "n")),  # coupling, row-major
    Section("c", "c", ("nc",)),
    Section("base", "base", (4, 4)),
    Section("frame", "frame", ("nc", 4, 4)),  # F_k
    Section("link", "link", ("nc", 4, 4)),  # G_k (the last times the tool)
    Section("lower", "lo", ("n",)),
    Section("upper", "hi", ("n",)),
    Section("seed_lower", "seed_lo", ("n",)),
    Section("seed_upper", "seed_hi", ("n",)),
    Section("wrap", "wrap", ("n",)),  # 1.0 where a coordinate may move by whole turns
)

HELD_MANIFOLD = Group("held_manifold.c", kernels=(
    Kernel("held_manifold", (Arr("params", "f64", ("PK_N_PARAMS",)), Arr("T", "f64", POSE),
                             Arr("aligned", "f64", ("A", 2)), Int("grid", 3, 100000),
                             Arr("iv", "f64", ("N", 8, "HM_MAXI", 2), out=True),
                             Arr("niv", "i64", ("N", 8), out=True),
                             Arr("pts", "f64", ("N", "HM_MAXP", 4), out=True),
                             Arr("npts", "i64", ("N",), out=True),
                             Arr("flags", "i64", ("N",), out=True),
                             Arr("evals", "i64", ("N",), out=True), Int("mode", 0, 2)),
           "None", "Per pose of a held-joint Pieper family (the Panda's q7): the intervals "
                   "inside every limit per slot (N, 8, HM_MAXI, 2) with counts (N, 8); points "
                   "[t, branch, joint, kind] (N, HM_MAXP, 4) with counts (N,); flags (N,) "
                   "(0: certain, else the solved-points path is needed) and pk_one calls (N,).\n\n"
                   "aligned (A, 2): [joint, value] rows where a triple's outer axes line up; grid: "
                   "values of t on the first grid; mode: HM_MODE_AUTO (the closed forms of "
                   "held_closed.c where they certify the pose, else the grid), HM_MODE_GRID, "
                   "HM_MODE_CLOSED (HM_FLAG_BAD where they do not).",
           checks=(Check("pk_params_ok(a->params)", "params is not a Pieper parameter vector"),)),
    Kernel("held_manifold_one", (Arr("params", "f64", ("PK_N_PARAMS",)), Obj("T"),
                                 Arr("aligned", "f64", ("A", 2)), Int("grid", 3, 100000),
                                 Float("exact", 0.0, 1e-6)),
           "tuple[F64, I64, F64, int, int, bool] | None",
           "``held_manifold`` of one pose T (4, 4), packed: new arrays of its intervals (m, 2) "
           "branch by branch, their branches (m,) and its points (p, 4); its flags and pk_one "
           "calls; close: two crossings of a branch within SM_PAIR, one within it of an end of the "
           "held joint's range or an interval at most SM_POINT long (False on a flagged pose). "
           "None where T is not a C-contiguous aligned float64 (4, 4) ndarray, or, with exact "
           "> 0, not rigid with its rotation within exact of orthonormal (chain.h "
           "pose_problem): the caller checks it and calls again.",
           checks=(Check("pk_params_ok(a->params)", "params is not a Pieper parameter vector"),)),
), constants=_consts("MAXI MAXP KIND_LOWER KIND_UPPER KIND_ALIGNED KIND_FOLD FLAG_SINGULAR "
                     "FLAG_UNRESOLVED FLAG_CONVERGE FLAG_FULL FLAG_VANISH FLAG_MEMORY FLAG_BAD "
                     "MODE_AUTO MODE_GRID MODE_CLOSED",
                     "HM_", "HM_"),
    comment="held-joint manifold output sizes, point kinds and flags")

NEAR_COINCIDENT = Group("near_coincident.c", kernels=(
    Kernel("near_coincident", (
        Packed(), Arr("T", "f64", POSE), Arr("H", "f64", ("M", "n")),
        Arr("pose", "i64", ("M",), values=("0", "N - 1"), monotone=True),
        Int("held", 0, 6), Int("a", 0, 6), Int("b", 0, 6), Float("sign", -1.0, 1.0),
        Float("v0", -10.0, 10.0), Float("v", -10.0, 10.0), Float("accept", 0.0, 1.0),
        Arr("Q", "f64", ("S", "n"), out=True), Arr("at", "i64", ("S",), out=True),
        Arr("exact", "bool", ("S",), out=True), Arr("singular", "bool", ("S",), out=True),
        Arr("slot", "i64", ("S",), out=True)),
        "int", "The rows of a 7R arm with joint ``held`` at v next to v0 (axes a and b "
               "nearly on one line), from the helper rows H (M, n) of poses ``pose`` (M,), "
               "non-decreasing: seeds, Newton, moved into the limits, checked to ``accept`` "
               "(m, rad), into Q (S, n) with their poses ``at``, ``exact``, ``singular`` "
               "and ``slot`` (the row's place among its pose's solutions, -1: dropped); "
               "returns the rows written (S >= NC_SEEDS * M).",
        checks=(Check("a->packed.ident && n == NC_N",
                      "the chain is not 7 independent joints"),
                Check("a->held != a->a && a->held != a->b && a->a != a->b",
                      "held, a and b must be three different joints"),
                Check("a->sign == 1.0 || a->sign == -1.0", "sign must be 1.0 or -1.0"),
                Check("S >= NC_SEEDS * M", "Q needs NC_SEEDS rows per helper row"))),
), constants=tuple(Const(name, name, "float") for name in (
    "NC_RCOND", "NC_FINAL_RCOND", "NC_MAX_STEP", "NC_CONVERGED", "NC_SAME", "NC_SAME_SEED",
    "NC_SHIFT", "NC_FLAG", "NC_FAMILY_RANK")) + _consts(
    "NC_STEPS NC_FINAL NC_PIN_STEPS NC_SPREAD NC_SEEDS NC_N"),
    comment="near-coincident held joint: Newton and acceptance constants, seeds per row")

GROUPS: tuple[Group, ...] = (FK, LM, SIX_R, PIEPER, GENERAL6R, BROADPHASE, PROCESS,
                             PLAN_CHECK, PLAN_RRTC, PLAN_PATH, SELF_MOTION, REACH,
                             HELD_MANIFOLD, NEAR_COINCIDENT)
OPTION_VECTORS: tuple[Opts, ...] = (LM_OPTS, RC_OPTS, SP_OPTS)
