"""robokin.process.views: the per-waypoint diagnostics drawn (green / red).

Oracles: a path with two waypoints moved out of reach; the markers must be red
exactly there and green elsewhere, at the waypoints' positions; the figure's
path panels carry the same colours; the HTML page carries the markers.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from process.paths import circle, load
from robokin import process
from robokin.exceptions import InputError

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def broken():
    robot = load("ur5")
    poses = circle(robot, n=12)
    poses[[4, 9], 0, 3] += 3.0
    return robot, poses, process.follow(robot, poses, max_step=0.3)


def test_markers_are_red_where_no_configuration_reaches_the_waypoint(broken):
    robot, poses, res = broken
    marks = process.path_markers(res, radius=0.01)
    assert [m.name for m in marks] == [f"waypoint {i:02d}" for i in range(12)]
    colors = np.array([m.color for m in marks])
    red = np.flatnonzero((colors == [215, 40, 40]).all(axis=1))
    assert red.tolist() == [4, 9]
    assert (colors[[0, 1, 2, 3, 5, 6, 7, 8, 10, 11]] == [40, 160, 60]).all()
    np.testing.assert_allclose([m.pose[:3, 3] for m in marks], poses[:, :3, 3])
    assert all(m.kind == "sphere" and m.size == (0.01,) for m in marks)


def test_plot_shows_the_same_colours_and_the_reason(broken, tmp_path):
    robot, poses, res = broken
    out = tmp_path / "follow.png"
    fig = process.plot_follow(res, robot=robot, path=out)
    assert out.stat().st_size > 10_000
    assert fig._suptitle.get_text().startswith("waypoint 4: out of reach")
    scatter = fig.axes[0].collections[0]
    face = scatter.get_facecolors()[:, :3]
    np.testing.assert_allclose(face, res.waypoints.colors() / 255.0)
    with pytest.raises(InputError) as err:
        process.plot_follow(res, path=out)  # no overwrite
    assert err.value.argument == "path"


def test_html_export_draws_the_markers_with_the_scene(broken, tmp_path):
    pytest.importorskip("coal")
    from robokin import collision
    from robokin.viz.html import write_html

    robot, poses, res = broken
    scene = collision.Scene()
    scene.add_box("table", size=(0.5, 0.5, 0.02), pose=np.eye(4))
    page = write_html(tmp_path / "p.html", robot, np.nan_to_num(res.q),
                      scene=process.path_markers(res, scene=scene)).read_text()
    text = re.search(r'<script id="robokin-data" type="application/json">(.*?)</script>',
                     page, re.S).group(1)
    data = json.loads(text.replace("<\\/", "</"))
    names = [s["name"] for s in data["scene"]]
    assert names[0] == "table" and names[1:] == [f"waypoint {i:02d}" for i in range(12)]
    assert data["scene"][5]["color"] == [215, 40, 40]


def test_not_a_result_is_named():
    with pytest.raises(InputError) as err:
        process.plot_follow(np.zeros((3, 6)))
    assert err.value.argument == "result"
    with pytest.raises(InputError) as err:
        process.path_markers("res")
    assert err.value.argument == "result"
