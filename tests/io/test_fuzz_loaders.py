"""Property-based fuzz of the robot-file and motion-file loaders (issue 15).

Random YAML structures and values, alone and grafted into valid files: whatever
the file holds, only robokin errors come out (a ModelError, an InputError, an
unreachable pose ...), never a TypeError, a KeyError or a crash. No wall-clock
deadline (tests do not time robokin); bounded work from small files is tested by
the caps' own tests (sample, joint-row and alias budgets).
"""

from __future__ import annotations

import copy
import warnings

import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import robokin
from robokin.exceptions import RobokinError
from robokin.io.motion_files import load_motion_file
from robokin.trajectory.motion_plan import plan_from_document

KEYS = ["name", "source", "units", "length", "angle", "convention", "joints", "a",
        "alpha", "d", "theta", "joint", "limits", "sign", "depends", "depends_offset",
        "coordinates", "base", "tool", "xyz", "rpy", "op", "value", "actuators",
        "drives", "type", "ratio", "matrix", "geometry", "collision", "exclude",
        "radius", "length", "size", "file", "robot", "dt", "start", "segments",
        "line", "pose", "dwell", "duration", "profile", "velocity", "acceleration",
        "mm", "deg", "revolute", "prismatic", "fixed", "standard", "elementary"]

scalars = st.one_of(
    st.none(), st.booleans(),
    st.integers(min_value=-10**30, max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1e3, max_value=1e3),
    st.sampled_from(KEYS), st.text(max_size=12),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=6),
        st.dictionaries(st.one_of(st.sampled_from(KEYS), st.text(max_size=6)),
                        inner, max_size=6)),
    max_leaves=30,
)

ROBOT = robokin.load("ur5").meta["document"]
ROBOT = {k: v for k, v in ROBOT.items() if k in ("name", "units", "joints", "tool")}
MOTION = {"robot": "ur5", "units": {"length": "mm", "angle": "deg"}, "dt": 0.01,
          "start": [0, -90, 90, 0, 90, 0],
          "limits": {"velocity": 90, "acceleration": 180},
          "segments": [{"joint": [10, -80, 80, 0, 90, 0]},
                       {"line": {"dxyz": [0, 0, -50]}, "duration": 0.5},
                       {"dwell": 0.2}]}


@st.composite
def grafted(draw, base):
    """``base`` with a few of its values (at any depth) replaced or removed."""
    doc = copy.deepcopy(base)
    for _ in range(draw(st.integers(1, 3))):
        node = doc
        while True:
            keys = list(node) if isinstance(node, dict) else list(range(len(node)))
            if not keys:
                break
            key = draw(st.sampled_from(keys))
            child = node[key]
            if isinstance(child, (dict, list)) and child and draw(st.booleans()):
                node = child
                continue
            if isinstance(node, dict) and draw(st.integers(0, 4)) == 0:
                del node[key]
            else:
                node[key] = draw(values)
            break
    return doc


def _write(tmp_path_factory, doc, name):
    path = tmp_path_factory.mktemp("fuzz") / name
    if isinstance(doc, str):
        path.write_text(doc, encoding="utf-8")
    else:
        path.write_text(yaml.safe_dump(doc, allow_unicode=True), encoding="utf-8")
    return path


FUZZ = settings(max_examples=120, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow, HealthCheck.data_too_large])


def _only_robokin_errors(action):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            action()
        except RobokinError as exc:
            event(f"refused: {type(exc).__name__}")
        else:
            event("accepted")


@FUZZ
@given(doc=st.one_of(values, grafted(ROBOT), st.text(max_size=200)))
def test_robot_file_loader_raises_only_robokin_errors(tmp_path_factory, doc):
    path = _write(tmp_path_factory, doc, "robot.yaml")

    def load():
        robot = robokin.load(path)
        robot.fk([0.0] * robot.n)

    _only_robokin_errors(load)


@FUZZ
@given(doc=st.one_of(values, grafted(MOTION), st.text(max_size=200)))
def test_motion_file_loader_raises_only_robokin_errors(tmp_path_factory, doc):
    path = _write(tmp_path_factory, doc, "motion.yaml")

    def plan():
        spec, p = load_motion_file(path)
        plan_from_document(spec, p, max_samples=3000)

    _only_robokin_errors(plan)


def test_the_bases_are_valid_files(tmp_path):
    # the fuzz grafts onto files that load and plan: its examples reach the
    # validation of every field, not only the top level
    robot = robokin.load(_write_plain(tmp_path, ROBOT, "robot.yaml"))
    assert robot.n == 6
    spec, p = load_motion_file(_write_plain(tmp_path, MOTION, "motion.yaml"))
    _, traj = plan_from_document(spec, p, max_samples=3000)
    assert len(traj.labels) == 3


def _write_plain(folder, doc, name):
    path = folder / name
    path.write_text(yaml.safe_dump(doc), encoding="utf-8")
    return path
