"""ABB RAPID modules: structure and data types (issue 27 item 4).

Oracle: RAPID's rules (MODULE .. ENDMODULE, data declared before the routine,
tooldata [robhold, tframe, tload] with a load mass > 0, wobjdata, jointtarget and
robtarget aggregates with six 9E+09 external axes, unit quaternions, predefined
speeddata vNNN / zonedata zNN and fine, identifiers of at most 32 characters).
"""

import re

import numpy as np
import pytest

from robokin.exceptions import InputError
from robokin.trajectory.posts import AbbRapid, render_program
from vendor_arms import CREATED, PROFILES


def test_module_structure_and_declarations(arm, seam):
    result, wobj = seam
    prog = render_program(arm, result, "abb_rapid", profile=PROFILES["abb"],
                          created=CREATED, name="Seam", work_object=wobj, speed=0.1,
                          zone=0.005)
    lines = prog.texts["Seam.mod"].splitlines()
    assert lines[0] == "MODULE Seam" and lines[-1] == "ENDMODULE"
    start = lines.index("  PROC main()")
    assert lines[start + 1:start + 3] == ["    ConfJ \\On;", "    ConfL \\On;"]
    assert lines[-2] == "  ENDPROC"
    decls = [ln.strip() for ln in lines[1:start] if ln.strip() and not ln.strip().startswith("!")]
    assert decls[0].startswith("PERS tooldata rkTool := [TRUE,[[")
    mass = float(re.search(r"\]\],\[([\d.]+),", decls[0]).group(1))
    assert mass > 0
    assert decls[1].startswith('TASK PERS wobjdata rkWobj := [FALSE,TRUE,"",[[')
    names = {re.match(r"CONST (\w+) (\w+) :=", d).groups()[1]: re.match(
        r"CONST (\w+)", d).group(1) for d in decls[2:]}
    calls = [ln.strip() for ln in lines[start + 3:-2]]
    assert calls[0].startswith("MoveAbsJ j1, v200, fine, rkTool \\WObj:=rkWobj;")
    for call in calls[1:]:
        m = re.fullmatch(r"MoveL (p\d+), (v\d+|rkV\w+), (z\d+|fine|rkZ\w+), "
                         r"rkTool \\WObj:=rkWobj;", call)
        assert m and names[m.group(1)] == "robtarget"
    assert calls[-1].split(", ")[2] == "fine"
    assert all(c.split(", ")[1:3] == ["v100", "z5"] for c in calls[1:-1])


def test_speeds_and_zones_predefined_or_declared():
    post = AbbRapid()
    assert [post.speed_name(v) for v in (100, 7000, 12.5, 101)] == \
        ["v100", "v7000", "rkV12_5", "rkV101"]
    assert [post.zone_name(z) for z in (0, 1, 200, 0.3, 7)] == \
        ["fine", "z1", "z200", "rkZ0_3", "rkZ7"]
    with pytest.raises(InputError, match="tool_mass"):
        AbbRapid(tool_mass=0)


def test_custom_speed_is_declared_once(arm, sampled):
    prog = render_program(arm, sampled, "abb_rapid", profile=PROFILES["abb"], name="m",
                          options={"joint_tcp_speed": 333})
    text = prog.texts["m.mod"]
    used = set(re.findall(r"MoveAbsJ j\d+, (\w+),", text))
    declared = re.findall(r"CONST speeddata (\w+) :=", text)
    assert len(declared) == len(set(declared))
    assert {u for u in used if u.startswith("rk")} == set(declared)
    # joint moves: joint_tcp_speed times the stretch's share of the rate limits
    assert all(float(re.search(rf"CONST speeddata {d} := \[([\d.]+),", text).group(1)) <= 333
               for d in declared)


def test_identifier_rules(arm):
    prog = render_program(arm, np.zeros((1, 6)), "abb_rapid", name="x" * 40,
                          profile=PROFILES["abb"])
    assert prog.name == "x" * 32
    assert render_program(arm, np.zeros((1, 6)), "abb_rapid", name="MODULE",
                          profile=PROFILES["abb"]).name == "RK_MODULE"
