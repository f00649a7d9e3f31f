"""Issue 19, item 7: a CLI that never hides a number.

Tables never cut a value: plain text when stdout is not a terminal, ``--format
csv|json`` on request, folded (not cut) cells in a narrow terminal; units stay in
help texts; ``--near`` takes n values; ``show`` uses one set of units for every
arm; ``traj --force`` reruns and never leaves half its outputs; the press views'
labels do not overlap.
"""

import csv
import io
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import robokin
from robokin.cli import main

IK = ["ik", "ur5", "0.4", "0.1", "0.3", "0", "3.14", "0"]


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _ik_solutions():
    from robokin.spatial import pose_from_xyz_rpy

    r = robokin.load("ur5")
    sols = r.ik(pose_from_xyz_rpy(np.array([0.4, 0.1, 0.3]), np.array([0, 3.14, 0])))
    return sols.q[sols.valid]


def test_ik_in_a_narrow_pipe_prints_every_digit():
    """The issue's example: 80 columns, a pipe: no '…', every value in full."""
    env = {**os.environ, "COLUMNS": "80"}
    env.pop("FORCE_COLOR", None)
    env.pop("TTY_COMPATIBLE", None)
    res = subprocess.run([sys.executable, "-m", "robokin", *IK], capture_output=True,
                         text=True, timeout=120, env=env)
    assert res.returncode == 0, res.stderr
    assert "…" not in res.stdout and "┃" not in res.stdout
    rows = [ln.split() for ln in res.stdout.splitlines() if ln[:1].isdigit()]
    assert len(rows) == 8
    shown = np.array([[float(v) for v in row[1:7]] for row in rows])
    for q in _ik_solutions():  # each solution appears, to the printed 6 decimals
        assert np.min(np.max(np.abs(shown - q), axis=1)) < 5e-7


def test_ik_csv_is_full_precision_and_json_agrees(capsys):
    code, out, _ = run(capsys, *IK, "--format", "csv")
    assert code == 0
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[0][:3] == ["#", "q1 [rad]", "q2 [rad]"] and len(rows) == 9
    q_csv = np.array([[float(v) for v in row[1:7]] for row in rows[1:]])
    code, out, _ = run(capsys, *IK, "--format", "json")
    q_json = np.array([s["q"] for s in json.loads(out)["solutions"]])
    np.testing.assert_array_equal(q_csv, q_json)  # repr round-trips: bit-equal
    code, out, _ = run(capsys, *IK, "--json")
    assert json.loads(out)["solutions"][0]["q"] == q_json[0].tolist()


def test_json_and_another_format_contradict(capsys):
    code, _, err = run(capsys, *IK, "--json", "--format", "csv")
    assert code == 2 and "--format" in err


def test_a_narrow_terminal_folds_cells_instead_of_cutting(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "60")
    monkeypatch.setenv("TTY_COMPATIBLE", "1")  # rich: stdout is a terminal
    monkeypatch.delenv("NO_COLOR", raising=False)
    code, out, _ = run(capsys, *IK, "--format", "table")
    assert code == 0
    plain = re.sub(r"\x1b\[[0-9;]*m", "", out)
    assert "…" not in plain
    assert max(len(ln) for ln in plain.splitlines()) <= 60


def test_a_folded_cell_keeps_every_character(capsys, monkeypatch):
    from robokin.cli.output import Column, OutputTable, emit

    monkeypatch.setenv("COLUMNS", "12")
    monkeypatch.setenv("TTY_COMPATIBLE", "1")
    monkeypatch.setenv("NO_COLOR", "1")
    value = -1.2345678901234567
    emit(OutputTable("", [Column("q", fmt=repr)], [[value]]), "table")
    out = re.sub(r"\x1b\[[0-9;]*m", "", capsys.readouterr().out)
    lines = [ln.strip() for ln in out.splitlines() if ln.strip() not in ("", "q")
             and "─" not in ln]
    assert len(lines) > 1 and "".join(lines) == repr(value)


URDF = os.path.join(os.path.dirname(__file__), "data", "urdf", "ur5.urdf")


def _robots_table():
    """The built-in arms: one YAML file each in robokin/robots, joints from the model."""
    folder = os.path.join(os.path.dirname(robokin.__file__), "robots")
    names = sorted(f[:-5] for f in os.listdir(folder) if f.endswith(".yaml"))
    return [[n, str(robokin.load(n).n)] for n in names]


# The expected tables, from the published parameters (not from robokin's output).
D = np.degrees
#: Franka's published modified DH (mm, deg) and joint limits (rad, here in deg).
PANDA = [["joint1", "revolute", 0, 0, 0, 333, -D(2.8973), D(2.8973)],
         ["joint2", "revolute", -90, 0, 0, 0, -D(1.7628), D(1.7628)],
         ["joint3", "revolute", 90, 0, 0, 316, -D(2.8973), D(2.8973)],
         ["joint4", "revolute", 90, 82.5, 0, 0, -D(3.0718), -D(0.0698)],
         ["joint5", "revolute", -90, -82.5, 0, 384, -D(2.8973), D(2.8973)],
         ["joint6", "revolute", 90, 0, 0, 0, -D(0.0175), D(3.7525)],
         ["joint7", "revolute", 90, 88, 0, 0, -D(2.8973), D(2.8973)],
         ["flange", "fixed", 0, 0, 0, 107]]
#: The SCARA paper's motor map at q = (0, 0, 0, l4 = 0.1 m): phi3 = i (q3 - 2 pi l4 /
#: lead) = -10 pi, phi4 = j q3 = 0 (i = 1, lead 20 mm, j = 15).
MOTORS = [["motor1", 0.0, "rad", "yes"], ["motor2", 0.0, "rad", "yes"],
          ["motor3", -10 * np.pi, "rad", "yes"], ["motor4", 0.0, "rad", "yes"]]
#: Universal Robots' published standard DH of the UR5 (theta, d, a, alpha; mm, deg).
UR5_DH = [["shoulder_pan_joint", "revolute", 0, 89.159, 0, 90],
          ["shoulder_lift_joint", "revolute", 0, 0, -425, 0],
          ["elbow_joint", "revolute", 0, 0, -392.25, 0],
          ["wrist_1_joint", "revolute", 0, 109.15, 0, 90],
          ["wrist_2_joint", "revolute", 0, 94.65, 0, -90],
          ["wrist_3_joint", "revolute", 0, 82.3, 0, 0]]


def _cells(row: list[str]) -> list:
    """A table row as strings and numbers (a ``[lo, hi]`` cell becomes two numbers)."""
    out: list = []
    for cell in row:
        cell = cell.strip()
        if re.fullmatch(r"\[\S+, \S+\]", cell):
            out += [float(x) for x in cell[1:-1].split(",")]
            continue
        try:
            out.append(float(cell))
        except ValueError:
            out.append(cell)
    while out and out[-1] == "":  # an empty last cell (the flange has no limits)
        out.pop()
    return out


def _same_rows(got: list[list], want: list[list], tol: float) -> None:
    assert len(got) == len(want), (got, want)
    for g, w in zip(got, want):
        assert len(g) == len(w), (g, w)
        for a, b in zip(g, w):
            if isinstance(b, str):
                assert a == b, (g, w)
            else:
                assert a == pytest.approx(b, rel=tol, abs=1e-12), (g, w)


def _text_rows(out: str, first: str, columns: int) -> list[list]:
    """The rows of the first text table from the line starting with ``first`` on."""
    lines = out.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith(first + " "))
    rows = []
    for ln in lines[start:]:
        parts = re.split(r"\s{2,}", ln.strip())
        if not ln.strip() or ":" in parts[0]:  # a blank line or the notes after it
            break
        rows.append(_cells(parts)[:columns])
    return rows


@pytest.mark.parametrize(("cmd", "want", "tol"), [
    (["robots"], "robots", 0.0),
    (["show", "panda"], PANDA, 1e-8),     # limits printed to 9 significant digits
    (["motors", "scara", "0", "0", "0", "0.1"], MOTORS, 1e-11),
    (["dh", URDF, "--mm"], UR5_DH, 1e-12),
])
def test_every_table_command_has_csv_and_text_with_the_values(capsys, cmd, want, tol):
    if want == "robots":
        want = _robots_table()
    code, out, _ = run(capsys, *cmd, "--format", "csv")
    assert code == 0 and "…" not in out
    table = list(csv.reader(io.StringIO(out.split("\n\n")[0])))
    got = [_cells(r) for r in table[1:]]
    if cmd == ["robots"]:  # the source column: checked whole below
        got = [[r[0], str(int(r[1]))] for r in got]
    _same_rows(got, want, tol)
    code, out, _ = run(capsys, *cmd)  # captured stdout: not a terminal
    assert code == 0 and "…" not in out and "━" not in out
    rows = _text_rows(out, table[1][0], 2 if cmd == ["robots"] else len(want[0]))
    if cmd == ["robots"]:
        rows = [[r[0], str(int(r[1]))] for r in rows]
    _same_rows(rows, want, max(tol, 1e-11))  # text: 12 significant digits


def test_robots_never_cut_a_source(capsys):
    code, out, _ = run(capsys, "robots", "--format", "csv")
    assert code == 0
    sources = {row[0]: row[2] for row in list(csv.reader(io.StringIO(out)))[1:]}
    assert sources["aubo_i5"] == robokin.load("aubo_i5").source


def test_help_keeps_units_in_brackets():
    """rich ate '[mm]': help texts are shown as written, for every command."""
    from typer.testing import CliRunner

    from robokin.cli import app

    runner = CliRunner()
    res = runner.invoke(app, ["demo", "--help"], env={"COLUMNS": "200"})
    assert "Required clearance [mm]." in res.output
    res = runner.invoke(app, ["check", "--help"], env={"COLUMNS": "200"})
    assert "t [s],<joint> [rad]" in res.output and "\\[" not in res.output
    import typer.main

    group = typer.main.get_command(app)
    for name, cmd in group.commands.items():
        res = runner.invoke(app, [name, "--help"], env={"COLUMNS": "250"})
        assert res.exit_code == 0, name
        for p in cmd.params:
            raw = (getattr(p, "help", None) or "").replace("\\[", "[")
            for part in raw.split():
                if part.startswith("[") and "]" in part:
                    assert part.rstrip(".,);") in res.output, (name, p.name, part)


def test_near_takes_one_value_per_joint(capsys):
    q0 = _ik_solutions()[0]
    near = [f"{v:.4f}" for v in q0]
    # after the pose, before it, and as one quoted token (comma or space)
    for args in ([*IK, "--near", *near], [*IK[:2], "--near", *near, *IK[2:]],
                 [*IK, "--near", ",".join(near)], [*IK[:3], "--near", *near, *IK[3:]]):
        code, out, err = run(capsys, *args, "--format", "json")
        assert code == 0, (args, err)
        np.testing.assert_allclose(json.loads(out)["solutions"][0]["q"], q0, atol=1e-9)
    code, _, err = run(capsys, *IK, "--near", "0", "0")
    assert code == 2 and "--near needs 6 values, got 2" in err


def test_show_uses_mm_and_degrees_for_every_arm(capsys):
    for name, row, key, value in (("panda", 1, "alpha", -90.0),
                                  ("panda", 0, "d", 333.0),
                                  ("ur5", 0, "d", 89.159),
                                  ("scara", 3, "d", -150.0)):
        code, out, _ = run(capsys, "show", name, "--format", "json")
        assert code == 0
        doc = json.loads(out)
        assert doc["units"] == {"length": "mm", "angle": "deg"}
        dh = doc["tables"][0]
        got = dh["rows"][row][dh["columns"].index(key)]
        assert got == pytest.approx(value, abs=1e-9), (name, key)
    code, out, _ = run(capsys, "show", "panda")
    assert "(lengths mm, angles deg)" in out and "1.5707963" not in out


MOTION = """\
robot: ur5
units: {length: mm, angle: deg}
start: [0, -90, 90, 0, 90, 0]
segments:
  - joint: [10, -80, 80, 0, 90, 0]
    duration: 0.5
"""


def test_traj_rerun_needs_force_and_replaces(tmp_path, capsys):
    f = tmp_path / "m.yaml"
    f.write_text(MOTION)
    assert run(capsys, "traj", str(f))[0] == 0
    first = (tmp_path / "m.csv").read_text()
    f.write_text(MOTION.replace("duration: 0.5", "duration: 0.25"))
    code, _, err = run(capsys, "traj", str(f))
    assert code == 2 and "pass --force" in err and "overwrite=True" not in err
    assert (tmp_path / "m.csv").read_text() == first
    code, _, err = run(capsys, "traj", str(f), "--force")
    assert code == 0, err
    assert (tmp_path / "m.csv").read_text() != first
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv", "m.png", "m.yaml"]


def test_traj_rerun_blames_no_option_the_user_did_not_give(tmp_path, capsys):
    """Issue 25: re-running `traj m.yaml` said "argument '-o'" though no -o was given."""
    f = tmp_path / "m.yaml"
    f.write_text(MOTION)
    assert run(capsys, "traj", str(f))[0] == 0
    code, _, err = run(capsys, "traj", str(f))
    assert code == 2 and err.count("\n") == 1
    assert "'-o'" not in err and "'--plot'" not in err
    assert (f"{tmp_path / 'm.csv'} and {tmp_path / 'm.png'} exist (written next to "
            "m.yaml by an earlier run); pass --force to replace them") in err
    code, _, err = run(capsys, "traj", str(f), "--no-plot")
    assert code == 2 and f"{tmp_path / 'm.csv'} exists" in err and "or -o to" in err
    # an explicit -o is replaced, as its help says
    code, _, err = run(capsys, "traj", str(f), "-o", str(tmp_path / "m.csv"),
                       "--no-plot")
    assert code == 0, err


def test_workspace_refuses_to_overwrite_an_earlier_run_without_force(tmp_path, capsys):
    """Issue 25: `workspace` replaced its folder's files while `traj` refused."""
    out = tmp_path / "ws"
    args = ["workspace", "scara", "--samples", "2000", "--out", str(out)]
    assert run(capsys, *args)[0] == 0
    written = {p.name: p.read_bytes() for p in out.iterdir()}
    assert sorted(written) == ["scara_workspace.json", "scara_workspace_xy.png",
                               "scara_workspace_xz.png"]
    code, _, err = run(capsys, *args[:-4], "--samples", "3000", "--out", str(out))
    assert code == 2 and "argument '--out'" in err and "pass --force" in err
    assert "scara_workspace.json" in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == written
    code, _, err = run(capsys, *args[:-4], "--samples", "3000", "--out", str(out),
                       "--force")
    assert code == 0, err
    assert (out / "scara_workspace.json").read_bytes() != written["scara_workspace.json"]
    # a folder with other files is not an earlier run: nothing of it is replaced
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    assert run(capsys, *args[:-1], str(other))[0] == 0
    assert (other / "notes.txt").read_text() == "mine"


def test_traj_writes_all_outputs_or_none(tmp_path, capsys):
    f = tmp_path / "m.yaml"
    f.write_text(MOTION)
    # the plot cannot be written (its folder is missing): no CSV either
    code, _, err = run(capsys, "traj", str(f), "--plot", str(tmp_path / "no" / "p.png"))
    assert code == 2 and "--plot" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.yaml"]
    # the plot fails while being written: the CSV is not moved in, nothing is left
    code, _, err = run(capsys, "traj", str(f), "--plot", str(tmp_path / "p.txt"))
    assert code == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.yaml"]


def test_staged_outputs_refuse_one_file_twice(tmp_path):
    from robokin.exceptions import InputError
    from robokin.io.atomic import staged_outputs

    with pytest.raises(InputError, match="also the output of -o"), staged_outputs(
        [(tmp_path / "a.csv", "-o", True), (tmp_path / "a.csv", "--plot", True)]
    ):
        pass


def test_press_views_labels_do_not_overlap(monkeypatch, tmp_path):
    """column_left and column_right share x and z: the side view labels both apart."""
    pytest.importorskip("coal")
    from robokin import collision
    from robokin.cli import demo_report
    from robokin.cli.demo import plan_press_loading
    from robokin.cli.demo_report import plot_press_views

    scene = collision.Scene.load(collision.scene_path("press"))
    robot = scene.attach(robokin.load("aubo_i5"))
    traj, _ = plan_press_loading(robot, scene, dt=0.05)
    figures = []
    monkeypatch.setattr(demo_report, "save_figure",
                        lambda fig, path, **kw: figures.append(fig) or path)
    plot_press_views(traj, scene, None, tmp_path / "v.png")
    fig = figures[0]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        names = [t for t in ax.texts if t.get_text() in scene.names]
        boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in names]
        assert boxes
        for i, (a, ba) in enumerate(boxes):
            for b, bb in boxes[i + 1:]:
                assert not ba.overlaps(bb), (a, b)
    side = {t.get_text() for t in fig.axes[0].texts}
    assert {"column_left", "column_right"} <= side


# ------------------------------------------------ issue 25: names printed literally
# A name holding rich markup and emoji codes, a source holding a terminal escape
# sequence (YAML "\e" is ESC). Oracle: the text as written, ESC shown as \x1b.
WEIRD = "arm:x:1 :warning: [red]r[/red]"
SOURCE = "vendor \\e[2J sheet :x:"
SOURCE_SHOWN = "vendor \\x1b[2J sheet :x:"


@pytest.fixture
def weird_robot(tmp_path):
    text = (robokin.robots.path("ur5")).read_text()
    text = re.sub(r"(?m)^name: .*$", lambda m: f'name: "{WEIRD}"', text, count=1)
    text = re.sub(r"(?ms)^source: .*?^units:", lambda m: f'source: "{SOURCE}"\nunits:',
                  text, count=1)
    f = tmp_path / "weird.yaml"
    f.write_text(text)
    robot = robokin.load(f)
    assert robot.name == WEIRD and robot.source == SOURCE.replace("\\e", "\x1b")
    return f


@pytest.mark.parametrize("fmt", ["table", "text"])
def test_show_prints_markup_emoji_and_escapes_literally(capsys, monkeypatch,
                                                       weird_robot, fmt):
    monkeypatch.setenv("COLUMNS", "200")
    code, out, _ = run(capsys, "show", str(weird_robot), "--format", fmt)
    assert code == 0
    assert f"{WEIRD}: standard" in out and f"source: {SOURCE_SHOWN}" in out
    assert "\x1b" not in out and "❌" not in out and "⚠" not in out


def test_export_and_import_lines_print_the_name_literally(capsys, tmp_path,
                                                          weird_robot):
    pytest.importorskip("yourdfpy")
    urdf = tmp_path / "w.urdf"
    code, out, _ = run(capsys, "export", str(weird_robot), "-o", str(urdf))
    assert code == 0 and out.startswith(f"{WEIRD}: wrote ")
    code, out, err = run(capsys, "import", str(urdf), "-o", str(tmp_path / "w.yaml"))
    assert code == 0, err
    assert out.startswith(f"{WEIRD}: 6 joints") and "❌" not in out


def test_a_name_with_a_control_character_is_refused(tmp_path):
    text = robokin.robots.path("ur5").read_text()
    f = tmp_path / "esc.yaml"
    f.write_text(re.sub(r"(?m)^name: .*$", lambda m: 'name: "arm\\e[2J"', text, count=1))
    with pytest.raises(robokin.ModelError, match=r"esc.yaml:1: name: .*control "
                                                 r"character \\x1b at position 3"):
        robokin.load(f)


def test_the_one_console_replaces_no_emoji():
    from robokin.cli.output import console

    con = console()
    with con.capture() as cap:
        con.print(":warning: :x:", markup=False)
    assert cap.get().strip() == ":warning: :x:"


# ------------------------------------ issue 25: two outputs to one path, or an input
def _csv_plan(folder, name):
    """A small UR5 trajectory CSV (robokin's format) at folder/name."""
    from robokin import trajectory
    from robokin.trajectory.io import write_csv

    ur5 = robokin.load("ur5")
    q0 = np.radians([0, -90, 90, 0, 90, 0])
    tr = trajectory.quintic(q0, q0 + 0.1, 0.3, dt=0.01)
    return write_csv(tr, folder / name, ur5.joint_names)


CLASHES = [
    # traj: every pair of its outputs (csv -o, --plot, --ros2, --program), and FILE
    (["traj", "{m}", "-o", "{d}/X.csv", "--force", "--ros2", "{d}/X.csv"],
     "'--ros2': {d}/X.csv is also the output of -o"),
    (["traj", "{m}", "-o", "{d}/X.csv", "--program", "{d}/./X.csv"],
     "'--program': {d}/X.csv is also the output of -o"),
    (["traj", "{m}", "--plot", "{d}/p.png", "--ros2", "{d}/sub/../p.png"],
     "'--ros2': {d}/sub/../p.png is also the output of --plot"),
    (["traj", "{m}", "--ros2", "{d}/r.yaml", "--program", "{d}/r.yaml"],
     "'--program': {d}/r.yaml is also the output of --ros2"),
    (["traj", "{m}", "-o", "{m}"], "'-o': {m} is the input FILE"),
    # a symlink to the input: writing would replace the user's link
    (["traj", "{m}", "--ros2", "{d}/link.yaml"], "'--ros2': {d}/link.yaml is the input FILE"),
    # folder commands: a file they write is the input they read
    (["retime", "{d}/retimed.csv", "--robot", "ur5", "--out", "{d}"],
     "'--out': {d}/retimed.csv is the input TRAJ"),
    (["sim", "ur5", "{d}/simulated.csv", "--out", "{d}"],
     "'--out': {d}/simulated.csv is the input TRAJECTORY"),
    (["place", "ur5", "--task", "{d}/placement.csv", "--out", "{d}"],
     "'--out': {d}/placement.csv is the input --task"),
    (["reach", "{d}/reach.json", "--out", "{d}"], "'--out': {d}/reach.json is the input NAME"),
    (["workspace", "{d}/ur5_workspace.json", "--out", "{d}", "-n", "10"],
     "'--out': {d}/ur5_workspace.json is the input NAME"),
    (["check", "press", "{d}/aubo.csv", "--robot", "aubo_i5", "--plot", "{d}/aubo.csv"],
     "'--plot': {d}/aubo.csv is the input TRAJECTORY"),
    (["compare", "{d}/retimed.csv", "{d}/simulated.csv", "--plot", "{d}/retimed.csv"],
     "'--plot': {d}/retimed.csv is the input PLAN"),
]


@pytest.mark.parametrize(("args", "message"), CLASHES, ids=lambda a: " ".join(a[:2])
                         if isinstance(a, list) else None)
def test_an_output_that_is_another_output_or_an_input_is_refused(tmp_path, capsys, args,
                                                                  message):
    """Issue 25: ``traj m.yaml -o X.csv --force --ros2 X.csv`` exited 0 and the CSV
    was lost (the ROS 2 YAML replaced it); an output named like an input replaced
    the user's file. Each is refused before anything is written: the folder holds
    exactly what it held, byte for byte."""
    d = tmp_path
    m = d / "m.yaml"
    m.write_text(MOTION)
    (d / "link.yaml").symlink_to(m)
    for name in ("retimed.csv", "simulated.csv", "placement.csv"):
        _csv_plan(d, name)
    aubo = robokin.load("aubo_i5")
    from robokin.trajectory import quintic
    from robokin.trajectory.io import write_csv

    q0 = np.radians([0, -20, 80, 0, 60, 0])
    write_csv(quintic(q0, q0 + 0.05, 0.2, dt=0.05), d / "aubo.csv", aubo.joint_names)
    ur5_file = robokin.robots.path("ur5").read_text()
    (d / "reach.json").write_text(ur5_file)
    (d / "ur5_workspace.json").write_text(ur5_file)
    before = {p.name: p.read_bytes() for p in d.iterdir()}
    argv = [a.format(d=d, m=m) for a in args]
    code, _, err = run(capsys, *argv)
    assert code == 2, err
    assert message.format(d=d, m=m) in err
    assert {p.name: p.read_bytes() for p in d.iterdir()} == before


def test_check_distinct_keys_files_not_spellings(tmp_path):
    from robokin.exceptions import InputError
    from robokin.io.atomic import check_distinct

    a = tmp_path / "a.csv"
    a.write_text("x")
    (tmp_path / "hard.csv").hardlink_to(a)
    (tmp_path / "sub").mkdir()
    (tmp_path / "alias").symlink_to(tmp_path / "sub")
    with pytest.raises(InputError, match="is the input IN"):
        check_distinct([(tmp_path / "hard.csv", "-o")], [(a, "IN")])
    with pytest.raises(InputError, match="is also the output of -o"):
        check_distinct([(tmp_path / "sub" / "x.csv", "-o"),
                        (tmp_path / "alias" / "x.csv", "--plot")])
    # distinct files pass, and an input through a symlink is its target
    check_distinct([(tmp_path / "b.csv", "-o"), (tmp_path / "c.csv", "--plot")],
                   [(a, "IN"), (None, "--scene")])
    with pytest.raises(InputError, match="is the input IN"):
        check_distinct([(tmp_path / "sub" / "t.yaml", "-o")],
                       [(tmp_path / "alias" / "t.yaml", "IN")])
