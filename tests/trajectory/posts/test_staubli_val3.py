"""Staubli VAL3 applications: well-formed XML in the VAL3 name spaces (issue 27).

Oracle: the files parse as XML (ElementTree), in VAL3's project, program and data
name spaces; the project lists start.pgx and stop.pgx and the data file; every data
array's size equals its values, keys 0..size-1 (program_parsers.parse_staubli); the
code is begin .. end with one movej / movel per move and waitEndMove().
"""

import re

import numpy as np

from program_parsers import parse_staubli
from robokin.trajectory.posts import write_program
from vendor_arms import CREATED, PROFILES


def test_application_files(tmp_path, arm, seam):
    result, wobj = seam
    prog = write_program(arm, result, "staubli_val3", tmp_path, name="seam",
                         profile=PROFILES["staubli"], created=CREATED, work_object=wobj,
                         zone=0.002)
    assert sorted(p.relative_to(tmp_path).as_posix() for p in prog.files) == \
        ["seam/seam.dtx", "seam/seam.pjx", "seam/start.pgx", "seam/stop.pgx"]
    parsed = parse_staubli(tmp_path, "seam")
    code = (tmp_path / "seam" / "start.pgx").read_text()
    assert len(re.findall(r"\bmove[jl]\(", code)) == len(result.q)
    assert code.count("waitEndMove()") == 1
    data = parsed.extra["data"]
    assert len(data["jPath"]) == len(data["pPath"]) == len(data["mRk"]) == len(result.q)
    blends = [m.zone for m in parsed.moves]
    assert blends[0] == "off" and blends[-1] == "off" and set(blends[1:-1]) == {"cartesian"}
    assert data["mRk"][1].get("leave") == data["mRk"][1].get("reach") == "2.000"
    assert data["tRk"][0].get("fatherId") == "flange[0]"
    assert data["fRk"][0].get("fatherId") == "world[0]"
    assert all(v.get("fatherId") == "fRk[0]" for v in data["pPath"])


def test_joint_speed_is_a_percentage(tmp_path, arm):
    write_program(arm, np.zeros((2, 6)) + 0.3, "staubli_val3", tmp_path, name="j",
                  joint_speed=0.35, profile=PROFILES["staubli"])
    data = parse_staubli(tmp_path, "j").extra["data"]
    assert [v.get("vel") for v in data["mRk"]] == ["35", "35"]
