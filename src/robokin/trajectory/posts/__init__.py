"""Post processors: programs in the languages of the controllers people own.

Six built-in dialects (docs/controllers.md has each one's files, units, frames,
configuration flags and limits):

=================  ===================================================  ==============
``kuka_krl``       KUKA KRL (KR C4 / KR C5)                             ``.src`` + ``.dat``
``abb_rapid``      ABB RAPID (IRC5 / OmniCore)                          ``.mod``
``fanuc_tp``       FANUC TP, ASCII source (R-30iA / R-30iB)             ``.ls``
``yaskawa_inform`` Yaskawa Motoman INFORM (DX100 / DX200 / YRC1000)     ``.JBI``
``staubli_val3``   Staubli VAL3 (CS8 / CS9)                             folder: ``.pjx``, ``.pgx``, ``.dtx``
``kawasaki_as``    Kawasaki AS (E / F controllers)                      ``.as``
=================  ===================================================  ==============

::

    from robokin.trajectory.posts import write_program
    prog = write_program(robot, traj_or_result, "kuka_krl", "out/", name="seam")
    prog.files, prog.notes

A post processor is a frozen dataclass deriving :class:`PostProcessor` (its fields
are its options); :func:`register` adds one, and so does the ``robokin.post_processors``
entry point group. Configuration flags (KUKA Status/Turn, ABB confdata, FANUC config,
Yaskawa RCONF, Staubli config) come from :mod:`.arm_config`.
"""

from __future__ import annotations

from robokin.trajectory.posts._abb_rapid import AbbRapid
from robokin.trajectory.posts._fanuc_tp import FanucTp
from robokin.trajectory.posts._kawasaki_as import KawasakiAs
from robokin.trajectory.posts._kuka_krl import KukaKrl
from robokin.trajectory.posts._staubli_val3 import StaubliVal3
from robokin.trajectory.posts._yaskawa_inform import YaskawaInform
from robokin.trajectory.posts.arm_config import ArmConfiguration, arm_configuration
from robokin.trajectory.posts.base import (
    Move,
    PostProcessor,
    ProgramJob,
    Statement,
    Target,
)
from robokin.trajectory.posts.program import (
    Program,
    decimate,
    program_job,
    render_program,
    write_program,
)
from robokin.trajectory.posts.registry import (
    ENTRY_POINT_GROUP,
    get_post,
    post_names,
    register,
    unregister,
)

__all__ = [
    "ENTRY_POINT_GROUP",
    "AbbRapid",
    "ArmConfiguration",
    "FanucTp",
    "KawasakiAs",
    "KukaKrl",
    "Move",
    "PostProcessor",
    "Program",
    "ProgramJob",
    "Statement",
    "StaubliVal3",
    "Target",
    "YaskawaInform",
    "arm_configuration",
    "decimate",
    "get_post",
    "post_names",
    "program_job",
    "register",
    "render_program",
    "unregister",
    "write_program",
]
