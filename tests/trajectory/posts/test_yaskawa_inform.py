"""Yaskawa INFORM jobs (.JBI): structure, pulse and Cartesian variables (issue 27).

Oracle: the job data format (/JOB, //NAME, //POS with ///NPOS counting the C
variables, ///TOOL, ///POSTYPE with ///PULSE or ///RECTAN and ///RCONF before the
variables, //INST with ///DATE ///ATTR ///GROUP1, NOP, the moves, END).
"""

import numpy as np
import pytest

from program_parsers import parse_yaskawa
from robokin.exceptions import InputError
from robokin.trajectory.posts import YaskawaInform, write_program
from vendor_arms import CREATED, PROFILES

PPD = [1000.0, 1200.0, 900.0, 700.0, 800.0, 500.0]


@pytest.mark.parametrize("pulses", [False, True])
def test_job_structure(tmp_path, arm, seam, pulses):
    result, wobj = seam
    options = {"pulses_per_degree": PPD} if pulses else {"user_frame": 4}
    prog = write_program(arm, result, "yaskawa_inform", tmp_path, name="seam",
                         profile=PROFILES["yaskawa"], created=CREATED, work_object=wobj,
                         options=options, zone=0.002)
    parsed = parse_yaskawa(tmp_path, "SEAM", PPD if pulses else None)
    lines = parsed.extra["lines"]
    inst = lines.index("//INST")
    assert lines[inst + 1] == "///DATE 2024/05/06 07:08"
    assert parsed.extra["npos"] == parsed.extra["variables"] == len(result.q) == prog.moves
    assert lines[inst:].count("NOP") == 1 and lines[-2:] == ["END", ""]
    assert "///GROUP1 RB1" in lines and "///TOOL 1" in lines
    if pulses:
        assert "///PULSE" in lines and "///RECTAN" not in lines
        assert "///ATTR SC,RW" in lines
        # every pulse an integer, every move to a pulse variable
        q = np.degrees(PROFILES["yaskawa"].export(result.q))
        got = np.array([m.joints for m in parsed.moves])
        assert np.all(np.abs(got - q) <= 0.5 / np.array(PPD) + 1e-12)
    else:
        assert lines[lines.index("///RECTAN") - 2:lines.index("///RECTAN") + 1] == \
            ["///USER 4", "///POSTYPE USER", "///RECTAN"]
        assert "///ATTR SC,RW,RJ" in lines and "///FRAME USER 4" in lines
    assert [m.zone for m in parsed.moves] == ["0"] + ["3"] * (len(result.q) - 2) + ["0"]


def test_robot_frame_needs_no_user_frame(arm):
    from robokin.trajectory.posts import render_program

    text = render_program(arm, np.zeros((2, 6)) + 0.3, "yaskawa_inform", name="j",
                          profile=PROFILES["yaskawa"]).texts["J.JBI"]
    assert "///POSTYPE ROBOT" in text and "///USER" not in text


def test_options_are_checked():
    with pytest.raises(InputError, match="pulses_per_degree"):
        YaskawaInform(pulses_per_degree=(1.0, 2.0))
    with pytest.raises(InputError, match="pl"):
        YaskawaInform(pl=9)
