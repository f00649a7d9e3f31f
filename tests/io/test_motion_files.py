"""Motion files: the sample budget and strict fields (issue 15, item 1).

A motion file of a few lines asking for 10**9 samples (``dt: 1e-9``, or
``duration: 1e7``) used to allocate until the machine gave out; it is refused
before anything is allocated, naming the field and the limit.
"""

from __future__ import annotations

import pytest

from bounded import run_bounded
from robokin.cli import main
from robokin.exceptions import ModelError
from robokin.io.motion_files import MAX_MOTION_SAMPLES, load_motion_file
from robokin.trajectory.motion_plan import plan_from_document

MOTION = """\
robot: ur5
dt: {dt}
start: [0, -1.5, 1.5, 0, 1.5, 0]
segments:
  - joint: [0.5, -1.2, 1.2, 0, 1.5, 0]
    duration: {duration}
  - dwell: {dwell}
"""


def _file(tmp_path, dt=0.005, duration=1.0, dwell=0.5):
    p = tmp_path / "motion.yaml"
    p.write_text(MOTION.format(dt=dt, duration=duration, dwell=dwell))
    return p


@pytest.mark.parametrize(("kw", "field"), [
    ({"dt": "1e-9"}, r"motion\.yaml:2: dt: dt 1e-09 s makes the motion"),
    ({"duration": "1e7"}, r"motion\.yaml:6: segments\[0\]\.duration: 1e\+07 s makes"),
    ({"dwell": "1e9"}, r"motion\.yaml:7: segments\[1\]\.dwell: 1e\+09 s makes"),
])
def test_absurd_sample_counts_are_refused_before_allocating(tmp_path, kw, field):
    path = _file(tmp_path, **kw)
    proc = run_bounded(f"""
        from robokin.io.motion_files import load_motion_file
        from robokin.trajectory.motion_plan import plan_from_document
        spec, p = load_motion_file({str(path)!r})
        try:
            plan_from_document(spec, p)
        except robokin.ModelError as exc:
            print("REFUSED", exc)
    """, extra_mb=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "REFUSED" in proc.stdout
    import re

    assert re.search(field, proc.stdout), proc.stdout
    assert f"more than the limit of {MAX_MOTION_SAMPLES:,} samples" in proc.stdout
    assert "--max-samples" in proc.stdout


def test_the_cap_can_be_raised(tmp_path, capsys):
    path = _file(tmp_path, dt=0.001, duration=1.0, dwell=0.5)  # 1500 samples
    spec, p = load_motion_file(path)
    with pytest.raises(ModelError, match="limit of 1,000 samples"):
        plan_from_document(spec, p, max_samples=1000)
    _, traj = plan_from_document(spec, p, max_samples=2000)
    assert len(traj) == 1501  # 1.0 s + 0.5 s at 1 ms, both ends
    assert main(["traj", str(path), "--no-plot", "--max-samples", "1000"]) == 2
    assert "limit of 1,000" in capsys.readouterr().err
    assert main(["traj", str(path), "--no-plot", "--max-samples", "2000",
                 "-o", str(tmp_path / "out.csv")]) == 0


def test_derived_durations_are_held_to_the_cap_too(tmp_path):
    p = tmp_path / "slow.yaml"
    p.write_text("robot: ur5\nstart: [0, -1.5, 1.5, 0, 1.5, 0]\n"
                 "limits: {velocity: 1e-6, acceleration: 1e-6}\n"
                 "segments:\n  - joint: [0.5, -1.2, 1.2, 0, 1.5, 0]\n")
    spec, path = load_motion_file(p)
    with pytest.raises(ModelError, match=r"slow\.yaml: dt: the path reaches .* samples "
                                         r".*more than the limit of 200,000"):
        plan_from_document(spec, path)


@pytest.mark.parametrize(("line", "message"), [
    ("dt: '0.005'", r":2: dt: Input should be a valid number"),
    ("dt: .nan", r":2: dt: Input should be a finite number"),
    ("dt: 0.005\ndt: 0.01", r":3: duplicate key 'dt'"),
])
def test_fields_are_strict(tmp_path, line, message):
    p = _file(tmp_path)
    p.write_text(p.read_text().replace("dt: 0.005", line))
    with pytest.raises(ModelError, match=message):
        load_motion_file(p)
