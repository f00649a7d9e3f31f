"""Tool-path files (robokin follow's PATH.csv | PATH.yaml): poses read in SI.

Oracle: poses built independently with scipy from the values written (fixed-axis
roll-pitch-yaw, unit quaternions), and the error messages that name the file, the
line and the field.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robokin.exceptions import ModelError
from robokin.io.path_files import read_tool_path


def _pose(xyz_m, rpy_deg):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy_deg, degrees=True).as_matrix()
    T[:3, 3] = xyz_m
    return T


def test_csv_in_mm_and_deg_any_column_order(tmp_path):
    f = tmp_path / "seam.csv"
    f.write_text("yaw [deg],x [mm],y [mm],z [mm],roll [deg],pitch [deg]\n"
                 "90,600,-100,300,180,0\n\n-90.5,610,-90,300.5,170,-5\n")
    T = read_tool_path(f)
    np.testing.assert_allclose(T[0], _pose([0.6, -0.1, 0.3], [180, 0, 90]), atol=1e-12)
    np.testing.assert_allclose(T[1], _pose([0.61, -0.09, 0.3005], [170, -5, -90.5]),
                               atol=1e-12)


def test_csv_quaternions_and_si(tmp_path):
    f = tmp_path / "q.csv"
    q = Rotation.from_euler("xyz", [10, 20, 30], degrees=True).as_quat().tolist()  # x y z w
    f.write_text("x,y,z,qw,qx,qy,qz\n" + f"0.5,0.1,0.2,{q[3]!r},{q[0]!r},{q[1]!r},{q[2]!r}\n")
    np.testing.assert_allclose(read_tool_path(f)[0], _pose([0.5, 0.1, 0.2], [10, 20, 30]),
                               atol=1e-12)
    f.write_text("x,y,z,qw,qx,qy,qz\n0.5,0.1,0.2,1,0,0.1,0\n")
    with pytest.raises(ModelError, match=r"q.csv:2: the quaternion .* is not of unit length"):
        read_tool_path(f)


def test_yaml(tmp_path):
    f = tmp_path / "seam.yaml"
    f.write_text("units: {length: mm, angle: deg}\nposes:\n"
                 "  - {xyz: [600, -100, 300], rpy: [180, 0, 90]}\n"
                 "  - {xyz: [600, 100, 300], rpy: [180, 0, 90]}\n")
    T = read_tool_path(f)
    assert T.shape == (2, 4, 4)
    np.testing.assert_allclose(T[1], _pose([0.6, 0.1, 0.3], [180, 0, 90]), atol=1e-12)


@pytest.mark.parametrize("text, message", [
    ("x [mm],y [mm],z [mm]\n1,2,3\n", r"p.csv:1: missing column\(s\): roll, pitch, yaw or"),
    ("x,y,z,roll,pitch,yaw,speed\n1,2,3,0,0,0,5\n", r"p.csv:1: unknown column 'speed'"),
    ("x [in],y,z,roll,pitch,yaw\n1,2,3,0,0,0\n", r"p.csv:1: column 'x': unknown unit \[in\]"),
    ("x,y,z,roll,pitch,yaw,qw\n1,2,3,0,0,0,1\n", r"one of them"),
    ("x,y,z,roll,pitch\n1,2,3,0,0\n", r"missing column\(s\): yaw"),
    ("x,y,z,roll,pitch,yaw\n1,2,3,0,0\n", r"p.csv:2: 5 values, the header has 6"),
    ("x,y,z,roll,pitch,yaw\n1,2,3,0,0,nan\n", r"p.csv:2: holds a non-finite value"),
    ("x,y,z,roll,pitch,yaw\n1,2,a,0,0,0\n", r"p.csv:2: holds a value that is not a number"),
    ("x,y,z,roll,pitch,yaw\n", r"holds no poses"),
    ("", r"is empty"),
])
def test_bad_csv(tmp_path, text, message):
    f = tmp_path / "p.csv"
    f.write_text(text)
    with pytest.raises(ModelError, match=message):
        read_tool_path(f)


@pytest.mark.parametrize("text, message", [
    ("poses: []\n", r"poses: expected a non-empty list"),
    ("units: {length: inch}\nposes: [{xyz: [1, 2, 3], rpy: [0, 0, 0]}]\n", r"units"),
    ("poses:\n  - {xyz: [1, 2, 3], rpy: [0, 0, 0]}\n  - {xyz: [1, 2], rpy: [0, 0, 0]}\n",
     r"p.yaml:3: poses\[1\].xyz: expected 3 finite numbers"),
    ("poses:\n  - {xyz: [1, 2, 3]}\n", r"poses\[0\]: expected \{xyz"),
    ("speed: 3\nposes: [{xyz: [1, 2, 3], rpy: [0, 0, 0]}]\n", r"unknown key\(s\) \['speed'\]"),
])
def test_bad_yaml(tmp_path, text, message):
    f = tmp_path / "p.yaml"
    f.write_text(text)
    with pytest.raises(ModelError, match=message):
        read_tool_path(f)
    with pytest.raises(ModelError, match=r"expected a .csv or .yaml"):
        read_tool_path(tmp_path / "p.txt")
