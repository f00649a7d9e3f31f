"""The one atomic writer (issue 15, item 2), written as the attacks.

A planted ``out.html.tmp`` symlink (the old writer wrote ``FILE.tmp`` and
followed it), a kill in the middle of a plot write (the old ``savefig`` wrote
straight onto the target), failures half-way, read-only and missing folders.
"""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import robokin
from robokin.cli import main
from robokin.exceptions import InputError
from robokin.io.atomic import (
    file_stem,
    publish_folder,
    save_figure_atomic,
    write_atomic,
)


def _png(path, value: float) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2))
    FigureCanvasAgg(fig)
    fig.subplots().plot([0, 1], [0, value])
    save_figure_atomic(fig, path)
    return path.read_bytes()


def test_a_planted_tmp_symlink_is_never_followed(tmp_path, capsys):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out = tmp_path / "out.html"
    (tmp_path / "out.html.tmp").symlink_to(victim)  # the attack on FILE.tmp
    assert main(["view", "ur5", "--html", str(out)]) == 0
    assert victim.read_text() == "precious\n"
    assert os.readlink(tmp_path / "out.html.tmp") == str(victim)
    assert out.read_text().lstrip().lower().startswith("<!doctype html")
    assert not out.is_symlink()


def test_a_symlink_at_the_target_is_replaced_not_written_through(tmp_path):
    victim = tmp_path / "victim.yaml"
    victim.write_text("precious\n")
    link = tmp_path / "robot.yaml"
    link.symlink_to(victim)
    robokin.save(robokin.load("ur5"), link)
    assert victim.read_text() == "precious\n"
    assert not link.is_symlink() and robokin.load(link).name == "ur5"


def test_temporary_names_are_fresh_and_removed_on_failure(tmp_path, monkeypatch):
    target = tmp_path / "a.csv"
    target.write_text("old\n")

    def half_written(fh):
        fh.write(b"partial")
        raise RuntimeError("the writer failed half-way")

    with pytest.raises(RuntimeError, match="half-way"):
        write_atomic(target, half_written)
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv"]
    names = []
    real = os.replace
    monkeypatch.setattr(os, "replace", lambda a, b: (names.append(a), real(a, b)))
    write_atomic(target, "new\n")
    write_atomic(target, "newer\n")
    assert len(set(names)) == 2 and all(".a.csv." in n for n in names)
    assert target.read_text() == "newer\n"


def test_errors_name_the_users_path_in_one_line(tmp_path, monkeypatch):
    with pytest.raises(InputError, match=r"nowhere/x\.urdf: the folder .*nowhere "
                                         "does not exist"):
        write_atomic(tmp_path / "nowhere" / "x.urdf", "x")
    with pytest.raises(InputError, match="is a folder"):
        write_atomic(tmp_path, "x")
    write_atomic(tmp_path / "e", "x")
    with pytest.raises(InputError, match="exists; pass overwrite=True"):
        write_atomic(tmp_path / "e", "y", overwrite=False)
    assert (tmp_path / "e").read_text() == "x"

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr("tempfile.mkstemp", denied)
    with pytest.raises(InputError) as exc:
        write_atomic(tmp_path / "x.csv", "x")
    msg = str(exc.value)
    assert "x.csv" in msg and "Permission denied" in msg and "\n" not in msg
    assert ".tmp" not in msg


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_one_clear_line(tmp_path, capsys):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        assert main(["export", "ur5", "-o", str(ro / "ur5.urdf")]) == 2
    finally:
        ro.chmod(stat.S_IRWXU)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "ur5.urdf" in err


def test_the_cli_reports_a_missing_folder_in_one_line(tmp_path, capsys):
    assert main(["export", "ur5", "-o", str(tmp_path / "nope" / "ur5.urdf")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nope" in err and "does not exist" in err


def test_new_files_get_the_umask_permissions_and_replaced_ones_keep_theirs(tmp_path):
    old = os.umask(0o022)
    try:
        p = write_atomic(tmp_path / "new.txt", "x")
        assert stat.S_IMODE(p.stat().st_mode) == 0o644
        p.chmod(0o600)
        write_atomic(p, "y")
        assert stat.S_IMODE(p.stat().st_mode) == 0o600
    finally:
        os.umask(old)


def test_a_kill_during_a_plot_write_leaves_the_old_png_intact(tmp_path):
    target = tmp_path / "plot.png"
    before = _png(target, 1.0)
    assert before.startswith(b"\x89PNG")
    script = textwrap.dedent(f"""
        import sys, time
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from robokin.io.atomic import save_figure_atomic

        fig = Figure(figsize=(2, 2))
        FigureCanvasAgg(fig)
        fig.subplots().plot([0, 1], [0, 2])
        real = fig.savefig

        def slow(fh, **kw):  # write part of the image, then stall until killed
            fh.write(b"\\x89PNG partial")
            fh.flush()
            print("WRITING", flush=True)
            time.sleep(600)

        fig.savefig = slow
        save_figure_atomic(fig, {str(target)!r})
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline().strip() == "WRITING"
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=120)
    assert proc.returncode == -signal.SIGKILL
    assert target.read_bytes() == before  # the old image, whole
    # the killed writer's temporary file is a hidden sibling, never the target
    leftovers = [p.name for p in tmp_path.iterdir() if p.name != "plot.png"]
    assert all(n.startswith(".plot.png.") and n.endswith(".tmp") for n in leftovers)


def test_plot_writers_go_through_the_atomic_writer(tmp_path, monkeypatch):
    from robokin.trajectory import quintic
    from robokin.viz.plots import plot_joints

    seen = []
    import robokin.io.atomic as atomic

    real = atomic.write_atomic
    monkeypatch.setattr(atomic, "write_atomic",
                        lambda path, *a, **k: (seen.append(path), real(path, *a, **k))[1])
    tr = quintic(np.zeros(2), np.ones(2), 1.0, dt=0.1)
    plot_joints(tr, path=tmp_path / "j.png")
    assert [p.name for p in seen] == ["j.png"]
    assert (tmp_path / "j.png").read_bytes().startswith(b"\x89PNG")


def test_file_stems_from_names_cannot_leave_the_folder():
    assert file_stem("../../etc/passwd") == "_.._etc_passwd"
    assert file_stem("ur5") == "ur5"
    assert file_stem("") == "robot" and file_stem("...") == "robot"
    assert len(file_stem("x" * 500)) == 80


def _build(folder, text):
    folder.mkdir()
    (folder / "a.txt").write_text(text)


def _publish_nothing(path, **kwargs):
    with publish_folder(path, **kwargs):
        pass


def test_a_published_folder_appears_whole_or_not_at_all(tmp_path):
    target = tmp_path / "store"
    with publish_folder(target) as tmp:
        assert not tmp.exists() and tmp.parent.parent == tmp_path
        _build(tmp, "one")
        assert not target.exists()
    assert (target / "a.txt").read_text() == "one"
    with pytest.raises(InputError, match="argument 'out'.*store exists; pass overwrite=True"):
        _publish_nothing(target, argument="out")
    with (pytest.raises(RuntimeError, match="half-way"),
          publish_folder(target, overwrite=True) as tmp):
        _build(tmp, "two")
        raise RuntimeError("the writer failed half-way")
    assert (target / "a.txt").read_text() == "one"
    with publish_folder(target, overwrite=True) as tmp:
        _build(tmp, "three")
    assert (target / "a.txt").read_text() == "three"
    assert [p.name for p in tmp_path.iterdir()] == ["store"]  # no temporary left
    (tmp_path / "afile").write_text("x")
    with pytest.raises(InputError, match="afile is a file, expected a store folder"):
        _publish_nothing(tmp_path / "afile", overwrite=True)
    with pytest.raises(InputError, match="the folder .*afile does not exist"):
        _publish_nothing(tmp_path / "afile" / "m")


def test_os_errors_publishing_a_folder_name_the_users_path(tmp_path):
    long = tmp_path / ("n" * 300)  # too long a name, even for root
    with pytest.raises(InputError) as exc:
        _publish_nothing(long, argument="store")
    msg = str(exc.value)
    assert msg.startswith("argument 'store': ") and "File name too long" in msg
    assert "\n" not in msg
    with pytest.raises(InputError) as exc, publish_folder(tmp_path / "m") as tmp:
        (tmp / "sub").mkdir()  # the body fails: its folder was never made
    msg = str(exc.value)
    assert msg.startswith("argument 'path': ") and "m: cannot write" in msg
    assert ".tmp" not in msg and "No such file" in msg
    assert list(tmp_path.iterdir()) == []


def test_a_reach_map_store_that_cannot_be_written_is_named(tmp_path):
    pytest.importorskip("dask")
    pytest.importorskip("zarr")
    from robokin import cell

    ur5 = robokin.load("ur5")
    kw = dict(region=[[-0.6, -0.6, -0.3], [0.6, 0.6, 0.9]], voxel=0.6, orientations=2)
    m = cell.reach_map(ur5, **kw)
    long = tmp_path / ("n" * 300)
    with pytest.raises(InputError, match="argument 'path'.*cannot write.*File name too long"):
        m.save(long)
    with pytest.raises(InputError, match="argument 'store'.*File name too long"):
        cell.reach_map(ur5, store=long, **kw)
    (tmp_path / "afile").write_text("x")
    (tmp_path / "link").symlink_to(tmp_path / "afile" / "x")  # a link into a file
    with pytest.raises(InputError, match="argument 'store'.*link: cannot create the store"):
        cell.reach_map(ur5, store=tmp_path / "link", **kw)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "link"]
