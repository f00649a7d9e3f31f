"""``robokin check``: tables, plot, exit codes; the plot helper; the CSV fallback."""

import json

import numpy as np
import pytest

import robokin
from robokin.cli import main
from robokin.collision import Scene, check, scene_path

pytest.importorskip("coal")


def _write_csv(path, t, q, names, unit="rad", scale=1.0):
    header = "t [s]," + ",".join(f"{n} [{unit}]" for n in names)
    np.savetxt(
        path, np.column_stack([t, q * scale]), delimiter=",", header=header, comments=""
    )


@pytest.fixture(scope="module")
def press_motion(tmp_path_factory):
    """A short joint move from press_approach to press_place (clear of the dies)."""
    sc = Scene.load(scene_path("press"))
    r = robokin.load("aubo_i5")
    q0, q1 = sc.pose_joints["pick_approach"], sc.pose_joints["pick"]
    s = np.linspace(0.0, 1.0, 50)[:, None]
    q = q0 + s * (q1 - q0)
    t = np.linspace(0.0, 1.0, 50)
    path = tmp_path_factory.mktemp("cli") / "pick.csv"
    _write_csv(path, t, np.degrees(q), r.joint_names, unit="deg")
    return path, check(r, sc, q, t=t)


def test_check_prints_the_closest_pairs_and_passes(press_motion, capsys, tmp_path):
    path, ref = press_motion
    png = tmp_path / "dist.png"
    code = main(
        [
            "check",
            str(scene_path("press")),
            str(path),
            "--clearance",
            "4",
            "--plot",
            str(png),
        ]
    )
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "tool" in out and "fixture" in out
    assert f"{ref.min_distance * 1e3:.2f}" in out  # 20.00 mm at the pick
    assert "OK" in out
    assert png.stat().st_size > 10_000


def test_check_exits_1_when_the_clearance_is_violated(press_motion, capsys):
    path, ref = press_motion
    code = main(["check", "press", str(path), "--clearance", "25", "--json"])
    out, err = capsys.readouterr()
    assert code == 1
    data = json.loads(out)
    assert data["violated"] and not data["collides"]
    assert data["min_distance_m"] == pytest.approx(ref.min_distance, abs=1e-9)
    assert data["closest"]["body_b"] == "fixture"
    assert "25 mm" in err


def test_check_reports_collisions_with_times(capsys, tmp_path):
    sc = Scene.load(scene_path("press"))
    r = robokin.load("aubo_i5")
    # on down past the pick (another 150 mm): the fingers hit the fixture
    q0, q1 = sc.pose_joints["pick_approach"], sc.pose_joints["pick"]
    q = q1 + np.linspace(0.0, 1.0, 30)[:, None] * (q1 - q0)
    t = np.linspace(0.0, 2.9, 30)
    path = tmp_path / "crash.csv"
    _write_csv(path, t, q, r.joint_names)
    rep = check(r, sc, q, t=t)
    assert rep.collides
    code = main(["check", "press", str(path)])
    out, err = capsys.readouterr()
    assert code == 1 and "collides" in err
    first = rep.intervals[0]
    assert "collisions" in out and f"{first.t_start:.3f}" in out


def test_plot_distance_draws_the_pairs_and_the_clearance(press_motion, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from robokin.collision.plots import plot_distance

    _, rep = press_motion
    fig = plot_distance(rep, count=3, clearance=0.004)
    ax = fig.axes[0]
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert "tool – fixture" in labels and "clearance 4 mm" in labels
    line = next(ln for ln in ax.get_lines() if ln.get_label() == "tool – fixture")
    assert np.min(line.get_ydata()) == pytest.approx(rep.min_distance * 1e3, abs=1e-6)
    out = tmp_path / "d.svg"
    plot_distance(rep, out=out)
    assert out.read_text().lstrip().startswith("<?xml")


def test_trajectory_csv_reader_converts_units(tmp_path):
    from robokin.cli.collision import read_trajectory_csv

    path = tmp_path / "t.csv"
    path.write_text("t [ms],a [deg],b [mm]\n0,90,1000\n500,180,-20\n")
    t, q = read_trajectory_csv(path)
    np.testing.assert_allclose(t, [0.0, 0.5])
    np.testing.assert_allclose(q, [[np.pi / 2, 1.0], [np.pi, -0.02]])
    path.write_text("t [s],a [furlong]\n0,1\n")
    with pytest.raises(robokin.ModelError, match="unknown unit"):
        read_trajectory_csv(path)


def test_check_top_limits_the_table_and_bad_inputs_name_the_argument(
    press_motion, capsys, tmp_path
):
    path, ref = press_motion
    assert main(["check", "press", str(path), "--top", "2", "--format", "csv"]) == 0
    out, _ = capsys.readouterr()
    rows = out.split("\n\n")[0].splitlines()[1:]  # the pairs table, without its header
    assert len(rows) == 2
    assert main(["check", "press", str(path), "--top", "-1"]) == 2
    assert "--top" in capsys.readouterr().err
    # a CSV for another arm: names the file and both counts
    bad = tmp_path / "two.csv"
    _write_csv(bad, [0.0, 0.1], np.zeros((2, 2)), ["a", "b"])
    assert main(["check", "press", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "two.csv" in err and "2 joint columns" in err and "6 joints" in err
