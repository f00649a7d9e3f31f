"""The interface every compiled copy of the kernels exports, for the type checker.

``_base``, ``_avx2`` and ``_avx512`` are one C source (``csrc/module.c`` and the
files it includes) built three times, so they export the same functions and
constants: :class:`Kernels` declares them. The type checker cannot read a C
extension, so it sees :data:`robokin._native.kernels` through this Protocol;
``tests/native/test_interface.py`` checks that every built copy exports exactly
these names, functions as functions and constants with the declared types. A new
entry of a C method table or ``*_constants`` function is declared here too.

Shapes are those the C code checks (it raises ``ValueError`` otherwise); every array
is C-contiguous and native-endian, float64 unless the type says otherwise, and the
``out`` arrays are writeable. ``packed`` is a chain's
:attr:`~robokin.model.chain_arrays.ChainArrays.packed` vector.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

__all__ = ["Kernels"]

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Bools = npt.NDArray[np.bool_]


class Kernels(Protocol):
    """One compiled copy of the kernels (``csrc/module.c``): functions and constants."""

    # ------------------------------------------------------------ module.c PyInit
    ISA: str
    LANES: int
    MAX_JOINTS: int
    FK_PARALLEL_MIN: int
    TAB_K_MAX: int
    LAYOUT_TAG: float
    MAX_TRANSLATION: float
    # lm_solve / lm_path option indices (opts has N_OPTS entries)
    O_W: int
    O_TOL_P: int
    O_TOL_R: int
    O_MAX_ITER: int
    O_USE_Q0: int
    O_MAX_STEP: int
    O_MU0: int
    O_N_SEEDS: int
    O_PATH_MAX_JUMP: int
    O_STALL_EVERY: int
    O_STALL_RATIO: int
    O_MU_DOWN: int
    O_MU_UP: int
    O_SEED_SHRINK: int
    O_N_TABLE: int
    O_TABLE_ROT: int
    N_OPTS: int
    # result columns after the n joint values (out has n + N_RES columns)
    R_ERR: int
    R_EP: int
    R_ER: int
    R_ITERS: int
    R_RESTARTS: int
    R_CODE: int
    N_RES: int
    # result codes (column R_CODE)
    CODE_OK: int
    CODE_ITER: int
    CODE_STALL: int
    CODE_BAD_TARGET: int
    CODE_JUMP: int
    CODE_NOT_RUN: int
    CODE_BAD_Q0: int
    # ----------------------------------------------------------- six_r.c constants
    # indices into a 6R parameter vector (N_PARAMS entries, _six_r.pack)
    AXES: int
    POINTS: int
    WRIST: int
    PERP2: int
    TOOL_T: int
    TOOL_R: int
    PERP: int
    SIGN: int
    OFFSET: int
    LO: int
    HI: int
    S3: int
    S4: int
    SING_TOL: int
    DISC_TOL: int
    MIRROR: int
    A3: int
    B3: int
    C3: int
    PHI3: int
    CPHI3: int
    SPHI3: int
    A5: int
    B5: int
    C5: int
    PHI5: int
    CPHI5: int
    SPHI5: int
    AA: int
    BB: int
    FAMILY: int
    E5: int
    PLANE: int
    SPLIT_TOL: int
    TOL_P: int
    TOL_R: int
    CHECK: int
    SIZE: int
    N_PARAMS: int
    # family codes (params[FAMILY]) and per-pose status codes
    THREE_PARALLEL: int
    SPHERICAL_WRIST: int
    STATUS_OK: int
    STATUS_OUT_OF_REACH: int
    STATUS_NO_ORIENTATION: int
    BAD_POSE: int
    SIX_R_PARALLEL_MIN: int
    # ------------------------------------------------------ broadphase.c constants
    BP_CHUNK_WORK: int
    # ------------------------------------------------- plan_check.c, plan_geom.c
    # check results (PC_*), core kinds of shapes (PG_*), pair distance methods
    # (PD_*), the distance taken off every computed one [m]
    PC_FREE: int
    PC_HIT: int
    PC_UNDECIDED: int
    PG_POINT: int
    PG_SEGMENT: int
    PG_BOX: int
    PG_CYLINDER: int
    PG_HULL: int
    PD_SEGSEG: int
    PD_SEGBOX: int
    PD_BOXSEG: int
    PD_GJK: int
    PD_HULL: int
    PC_EPS: float
    # ------------------------------------------------------------- plan_rrtc.c
    # plan_rrtc options (RC_N_OPTS entries) and result codes
    RC_RANGE: int
    RC_TIME: int
    RC_MAX_NODES: int
    RC_N_OPTS: int
    RC_SOLVED: int
    RC_TIMEOUT: int
    RC_NODES: int
    RC_FAILED: int
    # ------------------------------------------------------------- plan_path.c
    # plan_simplify options (SP_N_OPTS entries)
    SP_VERTEX_TRIES: int
    SP_TRIES: int
    SP_MAX_FAIL: int
    SP_TIME: int
    SP_CUT_ROUNDS: int
    SP_SHARP_TURN: int
    SP_N_OPTS: int

    # ------------------------------------------------------- general6r.c constants
    # general6r_solve: solutions per pose, parameter-vector layout (GP_*: header
    # fields; VB_*: one variant block of VB_SIZE values), status and flag codes
    G6_MAXSOL: int
    G6_MAXCAND: int
    G6_MAXVAR: int
    GP_NVAR: int
    GP_TAIL_TOL: int
    GP_NULL_TOL: int
    GP_IMAG_TOL: int
    GP_TOL: int
    GP_DEDUPE: int
    GP_MAX_ITER: int
    GP_PAIR_GAP: int
    GP_SCALE: int
    GP_FALLBACK: int
    GP_NEAR_TAIL: int
    GP_HEAD: int
    VB_DIR: int
    VB_A: int
    VB_MULT: int
    VB_C: int
    VB_CI: int
    VB_P: int
    VB_SIZE: int
    G6_OK: int
    G6_NONE: int
    G6_DEGENERATE: int
    G6_BAD_POSE: int
    G6F_DEGENERATE: int
    G6F_CLUSTER: int
    G6F_SECONDARY: int
    G6F_SEC_DEGENERATE: int
    G6F_SEC_CLUSTER: int
    G6F_PROJECTED: int
    G6F_PROJ_DEGENERATE: int
    G6F_RESCUED: int
    G6F_NOISY: int
    G6F_SEC_NOISY: int
    G6F_EIGEN: int
    G6_DIAG_CAND_SHIFT: int
    # ---------------------------------------------------------- pieper.c constants
    # Pieper parameter vector layout (PIEPER_N_PARAMS entries, pieper.setup), the
    # triple cases, status codes and the batch size that goes to the pool
    PIEPER_N: int
    PIEPER_HELD: int
    PIEPER_CASE: int
    PIEPER_SING_TOL: int
    PIEPER_SCALE: int
    PIEPER_POINT: int
    PIEPER_AXES: int
    PIEPER_POINTS: int
    PIEPER_TOOL_R: int
    PIEPER_TOOL_T: int
    PIEPER_SIGN: int
    PIEPER_OFFSET: int
    PIEPER_LO: int
    PIEPER_HI: int
    PIEPER_TAG: int
    PIEPER_N_PARAMS: int
    PIEPER_MAX_JOINTS: int
    PIEPER_START: int
    PIEPER_END: int
    PIEPER_BOTH: int
    PIEPER_POINT2: int
    PIEPER_DEGENERATE: int
    PIEPER_BAD_POSE: int
    PIEPER_PARALLEL_MIN: int
    PIEPER_TAG_VALUE: float
    # --------------------------------------------------------- process.c constants
    # process_nodes: node status codes (PN_*), coordinate modes (PM_*), the layout
    # of its weights vector (PW_*: PW_N entries); process_dp's bucket cap
    PN_OK: int
    PN_NONE: int
    PN_LIMITS: int
    PN_SINGULAR: int
    PM_PLAIN: int
    PM_TURN: int
    PM_CIRCLE: int
    PW_SING_W: int
    PW_SING_MARGIN: int
    PW_SING_TOL: int
    PW_MU_REF: int
    PW_LIM_W: int
    PW_LIM_MARGIN: int
    PW_N: int
    PR_MAXB: int
    PR_LIMIT_TOL: float
    # ---------------------------------------------------------- FK and Jacobian
    def fk1(self, q: object, packed: object, /) -> F64 | None:
        """Pose (4, 4) of one configuration q (n,), or None for the general path."""

    def fk(self, packed: F64, q: F64, out: F64, /) -> bool:
        """Batch FK of q (N, n) into out (N, 4, 4); whether every q was finite."""

    def jacobian(self, packed: F64, q: F64, J: F64, T: F64, /) -> bool:
        """Jacobians J (N, 6, n) and poses T (N, 4, 4) of q (N, n); all finite."""

    def frames(self, packed: F64, q: F64, out: F64, /) -> bool:
        """Base, link frames and tool pose, out (N, n_chain + 2, 4, 4); all finite."""

    # --------------------------------------------------------------- numeric IK
    def lm_solve(
        self,
        packed: F64,
        targets: F64,
        q0: F64,
        seeds: F64,
        opts: F64,
        out: F64,
        tab: F64,
        cstart: I64,
        gdat: F64,
        parallel: bool,
        /,
    ) -> tuple[int, int]:
        """Numeric IK of targets (N, 4, 4) into out (N, n + N_RES).

        Returns the number of targets not solved and the index of the first bad
        target or q0 (-1 if none).
        """

    def seed_uniforms(
        self, targets: F64, q0: F64, key: int, base: int, out: F64, /
    ) -> None:
        """Restart numbers of targets (N, 4, 4) from q0 (N, n) into out (N, R, n).

        Uniform in [0, 1), a stream per target keyed by its pose, its q0 and
        ``key``; row r of out is the stream's number ``base + r``.
        """

    def lm_path(
        self, packed: F64, targets: F64, q_start: F64, opts: F64, out: F64, /
    ) -> int:
        """Numeric IK along targets (N, 4, 4) from q_start (n,); first failure or -1."""

    def pose_error(self, current: F64, target: F64, out: F64, /) -> None:
        """Residual ``[p_t - p; log(R_t R^T)]`` of (N, 4, 4) poses into out (N, 6)."""

    def table_nearest(
        self, rows: F64, cstart: I64, grid: F64, T: F64, k: int, rot_w: float, /
    ) -> I64:
        """Indices of the seed-table rows nearest the pose T (4, 4), nearest first."""

    def nearest(
        self,
        packed: F64,
        Q: F64,
        ok: Bools,
        qn: F64,
        is_rev: Bools,
        T: F64,
        q: F64,
        err: F64,
        found: Bools,
        /,
    ) -> None:
        """Per pose, the solution row of Q (N, k, n) nearest qn (N, n), into q."""

    def abs_det_jacobian(self, packed: F64, q: F64, mask: Bools, out: F64, /) -> bool:
        """``|det J|`` of q (N, 6) where mask (N,), 0 elsewhere, into out (N,).

        For a 6-coordinate chain (``manipulability.c``); whether every masked row was
        finite (unmasked rows are never read).
        """

    # -------------------------------------------------------------- validation
    def check_poses(self, T: F64, tol: float, /) -> tuple[int, int]:
        """``(code, index)`` of the first non-rigid pose of T (N, 4, 4), or (0, -1)."""

    # ------------------------------------------------------------------ 6R IK
    def six_r_ik1(
        self, T: object, params: F64, q6: float, packed: F64, /
    ) -> (
        tuple[int, F64, Bools, Bools, Bools] | tuple[int, None, None, None, None]
    ):
        """``(code, Q (8, 6), valid, singular, within_limits (8,))`` of one pose."""

    def six_r_ik(
        self, params: F64, T: F64, qn: F64, packed: F64, /
    ) -> tuple[F64, Bools, Bools, Bools, npt.NDArray[np.int8]]:
        """``(Q (N, 8, 6), valid, singular, within_limits (N, 8), status (N,))``."""

    # ------------------------------------------------- Pieper (intersecting triple)
    def pieper_ik1(
        self, T: object, params: F64, x: float, qn: F64 | None, /
    ) -> (
        tuple[int, F64, Bools, Bools, Bools] | tuple[int, None, None, None, None]
    ):
        """``(code, Q (8, n), valid, singular, within_limits (8,))`` of one pose."""

    def pieper_ik(
        self, params: F64, T: F64, x: F64, qn: F64, /
    ) -> tuple[F64, Bools, Bools, Bools, npt.NDArray[np.int8]]:
        """``(Q (N, 8, n), valid, singular, within_limits (N, 8), status (N,))``."""

    def pieper_roots(self, coeffs: F64, re: F64, im: F64, /) -> None:
        """The four roots of a quartic (coefficients lowest order first)."""

    # ------------------------------------------------------------ general 6R IK
    def general6r_solve(
        self,
        packed: F64,
        params: F64,
        T: F64,
        Q: F64,
        valid: Bools,
        inside: Bools,
        sigma: F64,
        status: I64,
        diag: I64,
        stats: F64,
        parallel: bool,
        /,
    ) -> None:
        """Every solution of poses T (N, 4, 4): Q (N, 16, 6), masks (N, 16), ..."""

    def general6r_fit_rows(
        self, consts: F64, a: int, angles: F64, X: F64, Y: F64, /
    ) -> None:
        """The left side's fitting rows at angles (M, 3): X (M, 27), Y (M, 14)."""

    def general6r_candidates(self, params: F64, T: F64, out: F64, /) -> tuple[int, int]:
        """One pose's candidates before the polish (chain values) into out; (n, flags)."""

    def general6r_roots(self, c: F64, wr: F64, wi: F64, /) -> bool:
        """Roots of the polynomial with coefficients c (low order first), into wr, wi."""

    # ----------------------------------------------------------- collision
    def rounded_box_bounds(
        self,
        frames: F64,
        link: I64,
        local: F64,
        h: F64,
        r: F64,
        ob_pose: F64,
        ob_h: F64,
        ob_r: F64,
        pa: I64,
        pb: I64,
        is_self: Bools,
        skip: Bools,
        out: F64,
        /,
    ) -> None:
        """Separating-axis lower bounds of every pair at every sample, into out."""

    def capsule_distances(
        self,
        frames: F64,
        link: I64,
        seg: F64,
        seg_r: F64,
        ob_seg: F64,
        ob_r: F64,
        pa: I64,
        pb: I64,
        is_self: Bools,
        pairs: I64,
        out: F64,
        /,
    ) -> None:
        """Exact distances of the listed capsule/sphere pairs at every sample."""

    def propagate_bounds(self, LB: F64, known: Bools, C: F64, rows: I64, /) -> None:
        """Spread known distances through the motion bounds, in place in LB."""

    def motion_bounds(
        self,
        packed: F64,
        q: F64,
        frames: F64,
        link: I64,
        sph_c: F64,
        sph_r: F64,
        sph_start: I64,
        sph_count: I64,
        reach: F64,
        spins: Bools,
        pa: I64,
        pb: I64,
        is_self: Bools,
        out: F64,
        /,
    ) -> None:
        """Per interval and pair, the bound on the change of the distance, into out."""

    # ----------------------------------------------------------------- planning
    def plan_model(
        self, packed: F64, shape_i: I64, shape_f: F64, hull: F64, pair_i: I64,
        reach: F64, S: int, /,
    ) -> object:
        """The compiled planning model of a robot in a scene (a capsule).

        shape_i (N, 4): core kind, link (-1: object), hull start, hull count;
        shape_f (N, 21): rb pose, half sizes, radius, cylinder radius; hull (H, 3);
        pair_i (P, 7): shapes a, b, method, self, mover, j0, j1; reach (S, nc).
        """

    def plan_check_states(
        self, model: object, q: F64, margin: F64, exact: object, status: I64,
        pair: I64, /,
    ) -> tuple[int, ...]:
        """Validity of states q (m, n) into status (m,) and pair (m,); work counters."""

    def plan_check_edges(
        self, model: object, q0: F64, q1: F64, margin: F64, exact: object,
        status: I64, pair: I64, where: F64, /,
    ) -> tuple[int, ...]:
        """Validity of the straight edges q0 -> q1 (m, n); work counters."""

    def plan_distances(self, model: object, q: F64, out: F64, /) -> None:
        """Certified lower bounds on every pair's distance at q (m, n) into out (m, P)."""

    def plan_rrtc(
        self, model: object, start: F64, goals: F64, lo: F64, hi: F64, margin: F64,
        opts: F64, seed: int, exact: object, /,
    ) -> tuple[int, F64 | None, int, tuple[int, ...], tuple[int, int, int, float]]:
        """RRT-Connect: (code, path (K, n) or None, goal row, counters, search)."""

    def plan_simplify(
        self, model: object, path: F64, margin: F64, opts: F64, seed: int,
        exact: object, /,
    ) -> tuple[F64, tuple[int, ...]]:
        """Shortcuts, then sharp corners cut, of path (K, n); (path, counters)."""

    # --------------------------------------------------------- process paths
    def process_nodes(
        self,
        packed: F64,
        Q: F64,
        valid: Bools,
        singular: Bools,
        mode: npt.NDArray[np.uint8],
        weights: F64,
        Qc: F64,
        cost: F64,
        mu: F64,
        code: npt.NDArray[np.int8],
        /,
    ) -> None:
        """Per node of Q (P, n): canonical values Qc, cost, manipulability, status."""

    def process_dp(
        self,
        Q: F64,
        cost: F64,
        circle: npt.NDArray[np.uint8],
        max_step: float,
        weight: float,
        start: F64,
        forbidden: I64,
        value: F64,
        pred: npt.NDArray[np.int32],
        restart: npt.NDArray[np.uint8],
        choice: npt.NDArray[np.int32],
        /,
    ) -> int:
        """The exact shortest path through layers Q (L, M, n); returns the segments."""

    def process_clusters(
        self, Q: F64, cost: F64, circle: npt.NDArray[np.uint8], out: F64, /
    ) -> None:
        """The least largest-joint-change between every two layers into out (P, P)."""

    def process_pairs(
        self, A: F64, B: F64, circle: npt.NDArray[np.uint8], out: F64, /
    ) -> None:
        """The largest joint change between every row of A (a, n) and B (b, n)."""

    def process_limit_cost(
        self, values: F64, lo: float, hi: float, margin: float, out: F64, /
    ) -> None:
        """The limit cost of each value (P,) into out (P,)."""

    # ------------------------------------------------------- for tests and set-up
    def seg_seg(self, pts: F64, out: F64, /) -> None:
        """Segment-segment distances of pts (N, 4, 3) into out (N,)."""

    def sincos(self, x: F64, s: F64, c: F64, /) -> None:
        """The kernels' sine and cosine of x (N,) into s and c."""

    def atan2(self, y: F64, x: F64, out: F64, /) -> None:
        """The kernels' atan2 of y, x (N,) into out."""

    def layout(self, packed: F64, /) -> dict[str, Any]:
        """The sections the kernels parse out of packed (for tests)."""

    def num_threads(self) -> int:
        """Threads of the pool the batch kernels use."""

    def set_num_threads(self, k: int, /) -> int:
        """Set the threads of the pool (1 to 64); returns the number in use."""

    def cpu_has_avx2_fma(self) -> bool:
        """Whether this CPU runs the AVX2 + FMA copy."""

    def cpu_has_avx512(self) -> bool:
        """Whether this CPU runs the AVX-512 copy."""
