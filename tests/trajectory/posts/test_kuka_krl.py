"""KUKA KRL files: every statement the syntax requires (issue 27 item 4).

Oracle: the KRL rules of KUKA System Software 8 (a .src with DEF NAME( ) .. END, a
.dat with DEFDAT NAME .. ENDDAT declaring every data name the .src uses, the first
motion a PTP to a complete position, approximation only with its $APO parameter
set, names of at most 24 characters).
"""

import re

import numpy as np
import pytest

from robokin.exceptions import InputError
from robokin.trajectory.posts import KukaKrl, render_program
from vendor_arms import CREATED, PROFILES, PathResult


@pytest.fixture
def files(arm, seam):
    result, wobj = seam
    prog = render_program(arm, result, "kuka_krl", profile=PROFILES["kuka"],
                          created=CREATED, name="seam_1", work_object=wobj, zone=0.002)
    return prog.texts["seam_1.src"].split("\r\n"), prog.texts["seam_1.dat"].split("\r\n")


def test_src_and_dat_structure(files):
    src, dat = files
    assert src[:3] == ["&ACCESS RVP", "&REL 1", "DEF seam_1( )"] and src[-2:] == ["END", ""]
    assert dat[:3] == ["&ACCESS RVP", "&REL 1", "DEFDAT seam_1"] and dat[-2:] == ["ENDDAT", ""]
    body = [s.strip() for s in src[3:-2] if not s.strip().startswith(";")]
    assert body[:6] == ["BAS(#INITMOV, 0)", "$TOOL = RK_TOOL", "$BASE = RK_BASE",
                        "$APO.CPTP = 50", "BAS(#VEL_PTP, 20)", "PTP XJ1"]
    declared = {m.group(2): m.group(1) for m in
                (re.fullmatch(r"DECL (E6AXIS|E6POS|FRAME) (\w+)=\{.*\}", d) for d in dat[4:-2])
                if m}
    assert len(declared) == len(dat) - 6  # every line between the header and ENDDAT
    used = re.findall(r"^(?:PTP|LIN) (\w+)", "\n".join(body), re.M)
    assert all(declared[u] in ("E6AXIS", "E6POS") for u in used)
    assert {"RK_TOOL", "RK_BASE"} <= set(declared)
    # linear moves blend with C_DIS after $APO.CDIS is set; the last stops exactly
    lins = [b for b in body if b.startswith("LIN")]
    assert all(b.endswith(" C_DIS") for b in lins[:-1]) and not lins[-1].endswith("C_DIS")
    assert body.index("$APO.CDIS = 2.000") < body.index(lins[0])
    assert body.index("$VEL.CP = 0.1") < body.index(lins[0])
    # E6POS: X Y Z A B C, then S and T as integers, then six external axes
    pos = next(d for d in dat if d.startswith("DECL E6POS"))
    keys = re.findall(r"[{,]([A-Z]\d?) ", pos)
    assert keys == ["X", "Y", "Z", "A", "B", "C", "S", "T", "E1", "E2", "E3", "E4", "E5", "E6"]
    assert re.search(r",S \d+,T \d+,", pos)


def test_names_are_kept_to_krl_rules(arm):
    prog = render_program(arm, np.zeros((2, 6)) + 0.3, "kuka_krl", created=CREATED,
                          name="weld seam #12 of the left side panel", profile=PROFILES["kuka"])
    assert prog.name == "weld_seam_12_of_the_left"
    assert len(prog.name) == 24 and any("at most 24" in n for n in prog.notes)
    assert set(prog.texts) == {"weld_seam_12_of_the_left.src", "weld_seam_12_of_the_left.dat"}
    assert render_program(arm, np.zeros((1, 6)), "kuka_krl", name="END",
                          profile=PROFILES["kuka"]).name == "RK_END"
    assert render_program(arm, np.zeros((1, 6)), "kuka_krl", name="2nd",
                          profile=PROFILES["kuka"]).name == "P2nd"


def test_blended_joint_moves_use_c_ptp_and_speed_changes_once(arm, sampled):
    prog = render_program(arm, sampled, "kuka_krl", created=CREATED, name="t",
                          profile=PROFILES["kuka"], options={"ptp_approximation": 30})
    src = [s.strip() for s in prog.texts["t.src"].split("\r\n")]
    ptp = [s for s in src if s.startswith("PTP")]
    assert ptp[0] == "PTP XJ1" and ptp[-1] == f"PTP XJ{len(ptp)}"
    assert all(p.endswith(" C_PTP") for p in ptp[1:-1]) and "$APO.CPTP = 30" in src
    vel = [s for s in src if s.startswith("BAS(#VEL_PTP")]
    assert len(vel) <= len(ptp) and all(a != b for a, b in zip(vel, vel[1:]))
    with pytest.raises(InputError, match="ptp_approximation"):
        KukaKrl(ptp_approximation=0)


def test_first_move_is_never_cartesian(arm):
    res = PathResult(np.radians([[0, -90, 90, 0, 30, 0], [5, -90, 90, 0, 30, 0]]))
    prog = render_program(arm, res, "kuka_krl", profile=PROFILES["kuka"], name="a",
                          cartesian=True)
    assert "PTP XJ1" in prog.texts["a.src"] and "LIN XP2" in prog.texts["a.src"]
