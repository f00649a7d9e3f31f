"""``robokin reach`` and ``robokin place``: outputs, exit codes, one-line errors (issue 16)."""

import json

import numpy as np
import pytest

import robokin
from robokin import cell
from robokin.cli import main

pytest.importorskip("dask")


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_reach_streams_a_map_and_draws_its_sections(capsys, tmp_path):
    out = tmp_path / "r"
    code, text, _ = run(capsys, "reach", "ur5", "--voxel", "250", "--orientations", "6",
                        "--out", str(out), "--region", "-500,-500,0,500,500,500")
    assert code == 0 and "reachability map" in text
    m = cell.ReachMap.load(out / "map.zarr")
    assert m.grid.shape == (4, 4, 2) and m.orientations.shape == (6, 3, 3)
    assert (out / "sections.png").stat().st_size > 10_000
    summary = json.loads((out / "reach.json").read_text())
    assert summary["voxels"] == 32 and summary["ik_evaluations"] == 192
    same = cell.reach_map(robokin.load("ur5"), region=[[-0.5, -0.5, 0], [0.5, 0.5, 0.5]],
                          voxel=0.25, orientations=6)
    np.testing.assert_array_equal(m.counts, same.counts)
    # again with --json: the finished store is recognised, nothing recomputed
    code, text, _ = run(capsys, "reach", "ur5", "--voxel", "250", "--orientations", "6",
                        "--out", str(out), "--region", "-500,-500,0,500,500,500", "--json")
    assert code == 0 and json.loads(text)["reachable_voxels"] == summary["reachable_voxels"]
    # a different map into the same folder needs --force
    code, _, err = run(capsys, "reach", "ur5", "--voxel", "200", "--out", str(out),
                       "--region", "-500,-500,0,500,500,500", "--orientations", "2")
    assert code == 2 and "holds a different map" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize(("args", "match"), [
    (["--voxel", "0"], "'--voxel'"),
    (["--voxel", "-5"], "'--voxel'"),
    (["--region", "0,0,0,100,100"], "'--region'"),
    (["--region", "0,0,0,100,0,100"], "'region'.*is empty"),
    (["--orientations", "0"], "'--orientations': expected an integer >= 1"),
    (["--scheduler", "nowhere"], "'--scheduler'"),
    # issue 25: a MemoryError (7.45 GiB) after exit 3; now refused before anything
    (["--orientations", "1000000000"],
     "'--orientations': 1,000,000,000 orientations = 1,000,000,000 per voxel, more than "
     "the 100,000 robokin tries"),
    (["--orientations", "1000", "--rolls", "101"],
     "1,000 orientations x 101 rolls = 101,000 per voxel, more than the 100,000"),
])
def test_reach_bad_input_is_one_line_exit_2(capsys, tmp_path, args, match):
    import re

    code, _, err = run(capsys, "reach", "ur5", "--out", str(tmp_path / "x"), *args)
    assert code == 2 and re.search(match, err) and len(err.strip().splitlines()) == 1


def test_place_scores_the_press_cell(capsys, tmp_path):
    pytest.importorskip("coal")
    out = tmp_path / "p"
    code, text, _ = run(capsys, "place", "aubo_i5", "--scene", "press", "--clearance", "4",
                        "--x=-200:0:100", "--y=0:200:100", "--out", str(out))
    assert code == 0 and "bases feasible" in text
    for f in ("placement.png", "placement.csv", "placement.json"):
        assert (out / f).stat().st_size > 100
    summary = json.loads((out / "placement.json").read_text())
    assert summary["candidates"] == 9 and summary["feasible"] >= 1
    assert summary["task_poses"] == 4  # the scene's named poses


def test_place_says_no_with_exit_1(capsys, tmp_path):
    pytest.importorskip("coal")
    code, _, err = run(capsys, "place", "aubo_i5", "--scene", "press", "--clearance", "60",
                       "--x", "0", "--y", "0", "--out", str(tmp_path / "p"))
    assert code == 1 and "no feasible placement among 1 candidates" in err


@pytest.mark.parametrize(("args", "match"), [
    (["--task", "poses"], "'poses' needs a --scene"),
    (["--scene", "press", "--x", "a:b"], "'--x'"),
    (["--scene", "press", "--x", "0:10:0"], "'--x'"),
    (["--scene", "press", "--clearance", "-1"], "'--clearance'"),
    (["--scene", "press", "--task", "missing.csv"], "missing.csv"),
])
def test_place_bad_input_is_one_line_exit_2(capsys, tmp_path, args, match):
    import re

    code, _, err = run(capsys, "place", "aubo_i5", "--out", str(tmp_path / "p"), *args)
    assert code == 2 and re.search(match, err) and len(err.strip().splitlines()) == 1


# ------------------------------------------- issue 25: what a bad option really is
@pytest.mark.parametrize(("option", "value", "message"), [
    ("--x", "0:1e9:0.001", "'0:1e9:0.001' gives 1,000,000,000,001 values, more than the "
                           "10,000 a range may hold"),
    ("--x", "1:0:1", "'1:0:1' runs backwards: from 1 is above to 0 (write '0:1:1')"),
    ("--x", "0:100:0", "'0:100:0': the step must be > 0, got 0"),
    ("--y", "0:100:-5", "'0:100:-5': the step must be > 0, got -5"),
    ("--yaw", "0:360:1e-9", "'0:360:1e-9' gives 360,000,000,001 values"),
    ("--x", "-1e308:1e308:1", "'-1e308:1e308:1' gives too many values"),  # b - a = inf
    ("--x", "0:1", "expected 'from:to:step' (three numbers), got '0:1'"),
    ("--z", "nan:1:1", "expected finite numbers"),
])
def test_place_ranges_say_the_real_problem(capsys, tmp_path, option, value, message):
    """Issue 25: each said "expected 'from:to:step'"; it is said before the robot
    or the scene is loaded (no scene is given here), and nothing is written."""
    out = tmp_path / "p"
    code, _, err = run(capsys, "place", "ur5", f"{option}={value}", "--out", str(out))
    assert code == 2 and f"argument '{option}': " + message in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


def test_place_refuses_a_grid_of_too_many_bases(capsys, tmp_path):
    code, _, err = run(capsys, "place", "ur5", "--scene", "press", "--x=0:9999:1",
                       "--y=0:9999:1", "--out", str(tmp_path / "p"))
    assert code == 2 and ("10,000 x 10,000 x 1 x 1 = 100,000,000 candidate bases, more "
                          "than the 1,000,000") in err


class _Server:
    """A local TCP server that accepts and then stays silent, or sends junk."""

    def __init__(self, junk: bytes | None):
        import socket
        import threading

        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.junk, self.conns = junk, []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.conns.append(conn)
            if self.junk is not None:
                conn.sendall(self.junk)

    def close(self):
        for c in self.conns:
            c.close()
        self.sock.close()


def _closed_port() -> int:
    import socket

    with socket.create_server(("127.0.0.1", 0)) as s:
        return s.getsockname()[1]


@pytest.mark.parametrize("kind", ["closed", "silent", "junk"])
@pytest.mark.parametrize("command", ["reach", "place"])
def test_a_scheduler_that_does_not_answer_is_exit_2_naming_it(capsys, tmp_path, kind,
                                                               command):
    """Issue 25: ``--scheduler tcp://10.255.255.1:8786`` ended in exit 3 with a raw
    TimeoutError after 30 s. A closed port, a port that accepts and stays silent
    (an unroutable address behind a proxy looks like this) and one that answers
    junk each end within --connect-timeout (per step) with exit 2 naming the address,
    before anything is computed or written."""
    server = None if kind == "closed" else _Server(None if kind == "silent" else
                                                   b"\xff" * 64 + b"HTTP/1.1 400\r\n")
    port = _closed_port() if server is None else server.port
    address = f"tcp://127.0.0.1:{port}"
    out = tmp_path / "o"
    try:
        code, _, err = run(capsys, command, "ur5", "--scheduler", address,
                           "--connect-timeout", "0.5", "--out", str(out))
    finally:
        if server is not None:
            server.close()
    assert code == 2, err
    assert err.startswith(f"robokin: error: argument '--scheduler': cannot reach the Dask "
                          f"scheduler at '{address}' within 0.5 s: ")
    why = {"closed": "connection refused", "silent": "no answer",
           "junk": "something answers there, but not as a Dask scheduler"}[kind]
    assert why in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_probe_lets_a_real_scheduler_through():
    from distributed import LocalCluster

    from robokin.cell._scheduler import probe_scheduler

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        probe_scheduler(cluster.scheduler_address, 5.0)  # no error
