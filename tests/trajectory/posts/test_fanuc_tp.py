"""FANUC TP ASCII programs (.ls): structure (issue 27 item 4).

Oracle: the .ls layout of FANUC's ASCII programs (/PROG, /ATTR with LINE_COUNT the
number of /MN lines, numbered /MN lines ending in ' ;', J moves in %, L moves in
mm/sec, FINE or CNTn, /POS with one block per P[] used, /END), names in capitals.
"""

import re

import numpy as np
import pytest

from program_parsers import parse_fanuc
from robokin.exceptions import InputError
from robokin.trajectory.posts import FanucTp, write_program
from vendor_arms import CREATED, PROFILES


def test_sections_line_numbers_and_positions(tmp_path, arm, seam):
    result, wobj = seam
    prog = write_program(arm, result, "fanuc_tp", tmp_path, profile=PROFILES["fanuc"],
                         created=CREATED, name="seam", work_object=wobj, zone=0.002,
                         options={"cnt": 100, "user_frame": 3, "user_tool": 2})
    assert prog.name == "SEAM"
    parsed = parse_fanuc(tmp_path, "SEAM")
    lines = parsed.extra["lines"]
    sections = [ln for ln in lines if ln.startswith("/")]
    assert sections == ["/PROG  SEAM", "/ATTR", "/MN", "/POS", "/END"]
    mn = lines[lines.index("/MN") + 1:lines.index("/POS")]
    assert [int(ln.split(":")[0]) for ln in mn] == list(range(1, len(mn) + 1))
    assert all(ln.endswith(" ;") for ln in mn) and all(len(ln.split(":", 1)[1]) > 2 for ln in mn)
    assert f"LINE_COUNT\t= {len(mn)};" in lines
    assert "CREATE\t\t= DATE 24-05-06  TIME 07:08:09;" in lines
    assert parsed.extra["frames"] == {"UFRAME_NUM": 3, "UTOOL_NUM": 2}
    used = [int(x) for x in re.findall(r"P\[(\d+)\] ", "\n".join(mn))]
    blocks = [int(x) for x in re.findall(r"^P\[(\d+)\]\{$", "\n".join(lines), re.M)]
    assert used == blocks == list(range(1, len(result.q) + 1))
    assert all("UF : 3, UT : 2," in ln for ln in lines if ln.startswith("\tUF"))
    terms = [m.zone for m in parsed.moves]
    assert terms[0] == "FINE" and terms[-1] == "FINE" and set(terms[1:-1]) == {"CNT100"}
    assert [m.speed for m in parsed.moves][:2] == ["20%", "100mm/sec"]


def test_set_frames_writes_position_register_assignments(arm):
    from robokin.trajectory.posts import render_program

    prog = render_program(arm, np.zeros((2, 6)) + 0.2, "fanuc_tp", profile=PROFILES["fanuc"],
                          name="f", options={"set_frames": True, "frame_register": 7})
    text = prog.texts["F.ls"]
    assert "PR[7]=LPOS-LPOS ;" in text and "UTOOL[1]=PR[7] ;" in text
    assert "UFRAME[1]=PR[7] ;" in text and text.count("PR[7,") == 12


def test_options_are_checked():
    with pytest.raises(InputError, match="cnt"):
        FanucTp(cnt=101)
    with pytest.raises(InputError, match="turn_axes"):
        FanucTp(turn_axes=(4, 5))
    assert FanucTp(turn_axes=[1, 4, 6]).turn_axes == (1, 4, 6)
