"""Kawasaki AS programs (.as): structure (issue 27 item 4).

Oracle: AS's save format (.PROGRAM NAME() .. .END, .TRANS .. .END with 'name x y z
o a t', .JOINTS .. .END with '#name j1 .. j6'); every location the code uses is
declared; TOOL and BASE name declared transformations; joint moves are joint values.
"""

import re

import numpy as np

from program_parsers import parse_kawasaki
from robokin.trajectory.posts import write_program
from vendor_arms import CREATED, PROFILES


def test_program_sections(tmp_path, arm, seam):
    result, wobj = seam
    write_program(arm, result, "kawasaki_as", tmp_path, name="seam", created=CREATED,
                  profile=PROFILES["kuka"], work_object=wobj, speed=0.05, zone=0.003)
    parsed = parse_kawasaki(tmp_path, "seam")
    lines = parsed.extra["lines"]
    assert [ln for ln in lines if ln.startswith(".")] == \
        [".PROGRAM seam()", ".END", ".TRANS", ".END", ".JOINTS", ".END"]
    code = [ln.strip() for ln in lines[1:lines.index(".END")]]
    assert code.index("TOOL rk_tool") < code.index("BASE rk_base") < code.index("JMOVE #rkj1")
    assert code[-1] == "BREAK"
    assert len(parsed.moves) == len(result.q)
    assert parsed.moves[1].speed == "50 MM/S" and parsed.moves[1].zone == "3.000"
    assert parsed.moves[0].zone == "1.000"  # exact stop: AS's default accuracy
    declared = {ln.split()[0] for ln in lines if re.match(r"^#?rk", ln)}
    used = set(re.findall(r"(?:JMOVE|LMOVE) (#?\w+)", "\n".join(code)))
    assert used <= declared


def test_cartesian_joint_moves_are_joint_values(tmp_path, arm):
    write_program(arm, np.zeros((3, 6)) + 0.3, "kawasaki_as", tmp_path, name="j",
                  cartesian=True, profile=PROFILES["kuka"])
    assert [m.joints is not None for m in parse_kawasaki(tmp_path, "j").moves] == [True] * 3
