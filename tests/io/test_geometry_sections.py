"""The geometry: and collision: robot-file sections and shape entries (units, field
paths, meshes resolved relative to the file)."""

import numpy as np
import pytest

import robokin
from robokin import ModelError
from robokin.io.robot_files import parts_from_document
from robokin.model import geometry as geo

ROW = {"name": "j1", "joint": "revolute", "a": 400, "alpha": 0, "d": 0, "theta": 0}


def _doc(geometry=None, collision=None, length="mm"):
    doc = {
        "name": "two_link",
        "units": {"length": length, "angle": "deg"},
        "joints": [ROW, {**ROW, "name": "j2", "a": 300}],
    }
    if geometry is not None:
        doc["geometry"] = geometry
    if collision is not None:
        doc["collision"] = collision
    return doc


def test_geometry_section_scales_mm_and_degrees():
    r = parts_from_document(
        _doc(
            {
                "j1": [
                    {
                        "type": "capsule",
                        "radius": 50,
                        "from": [-400, 0, 0],
                        "to": [0, 0, 0],
                    }
                ],
                "j2": [
                    {
                        "type": "box",
                        "size": [100, 40, 20],
                        "xyz": [-150, 0, 0],
                        "rpy": [0, 0, 90],
                    }
                ],
                "tool": [{"type": "sphere", "radius": 25}],
            }
        )
    )
    g = r.geometry
    assert g.names == ("base", "j1", "j2", "tool")
    (cap,) = g.link("j1")
    assert cap.size == pytest.approx((0.05, 0.4))
    np.testing.assert_allclose(cap.placement[:3, 3], [-0.2, 0, 0], atol=1e-12)
    (box,) = g.link("j2")
    assert box.size == pytest.approx((0.1, 0.04, 0.02))
    # rpy 90 deg about z: the box's x axis is the link's y axis
    np.testing.assert_allclose(box.placement[:3, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(box.placement[:3, 3], [-0.15, 0, 0], atol=1e-12)
    assert g.tool[0].size == pytest.approx((0.025,))
    assert g.link("base") == ()


def test_geometry_section_errors_name_the_field():
    with pytest.raises(ModelError, match=r"geometry\.elbow: unknown link 'elbow'"):
        parts_from_document(_doc({"elbow": [{"type": "sphere", "radius": 1}]}))
    with pytest.raises(
        ModelError, match=r"geometry\.j1\[0\]\.radius: missing required"
    ):
        parts_from_document(_doc({"j1": [{"type": "capsule", "length": 3}]}))
    with pytest.raises(
        ModelError, match=r"geometry\.j1\[0\]\.type: 'type' must be one of"
    ):
        parts_from_document(_doc({"j1": [{"type": "cone"}]}))
    with pytest.raises(ModelError, match=r"geometry\.j1\[0\]\.colour: unknown key; accepted: name, xyz, rpy, type"):
        parts_from_document(
            _doc({"j1": [{"type": "sphere", "radius": 1, "colour": "red"}]})
        )
    with pytest.raises(ModelError, match=r"geometry\.j1\[0\]\.size: expected 3 numbers"):
        parts_from_document(_doc({"j1": [{"type": "box", "size": [1, 2]}]}))


def test_collision_section_exclusions_and_adjacency():
    r = parts_from_document(
        _doc(
            {
                "base": [{"type": "sphere", "radius": 10}],
                "j2": [{"type": "sphere", "radius": 10}],
                "j1": [{"type": "sphere", "radius": 10}],
            },
            {"exclude": [["base", "j2"]]},
        )
    )
    g = r.geometry
    assert g.is_excluded("base", "j2") and g.is_excluded("j2", "base")
    assert g.is_excluded("base", "j1")  # adjacent
    assert not g.is_excluded(
        "j1", "tool"
    )  # not adjacent... tool carries nothing though
    assert g.self_pairs() == []
    r2 = parts_from_document(
        _doc(
            {
                "base": [{"type": "sphere", "radius": 10}],
                "j2": [{"type": "sphere", "radius": 10}],
            },
        )
    )
    assert r2.geometry.self_pairs() == [(0, 2)]
    with pytest.raises(
        ModelError, match=r"collision\.exclude\[0\]: unknown link 'hand'"
    ):
        parts_from_document(_doc(None, {"exclude": [["base", "hand"]]}))


def _write_box_stl(path, size_mm):
    import trimesh

    trimesh.creation.box(extents=size_mm).export(path)


def test_mesh_in_mm_is_scaled_and_resolved_relative_to_the_robot_file(tmp_path):
    import yaml

    (tmp_path / "meshes").mkdir()
    _write_box_stl(tmp_path / "meshes" / "link.stl", (200.0, 60.0, 40.0))
    doc = _doc(
        {
            "j1": [
                {
                    "type": "mesh",
                    "file": "meshes/link.stl",
                    "units": "mm",
                    "xyz": [-200, 0, 0],
                }
            ]
        }
    )
    path = tmp_path / "arm.yaml"
    path.write_text(yaml.safe_dump(doc))
    r = robokin.load(path)
    (shape,) = r.geometry.link("j1")
    assert shape.file == tmp_path / "meshes" / "link.stl"
    ext = shape.trimesh().extents
    np.testing.assert_allclose(ext, [0.2, 0.06, 0.04], rtol=1e-12)
    c, h = shape.local_box()
    np.testing.assert_allclose(h, [0.1, 0.03, 0.02], rtol=1e-12)
    # a metre mesh given with a scale factor
    shape_m = geo.mesh(tmp_path / "meshes" / "link.stl", units="m", scale=0.5)
    np.testing.assert_allclose(shape_m.trimesh().extents, [100, 30, 20], rtol=1e-12)


def test_missing_mesh_names_the_file_and_the_link(tmp_path):
    import yaml

    path = tmp_path / "arm.yaml"
    path.write_text(
        yaml.safe_dump(_doc({"j2": [{"type": "mesh", "file": "nowhere.stl"}]}))
    )
    with pytest.raises(ModelError) as exc:
        robokin.load(path)
    msg = str(exc.value)
    assert "nowhere.stl" in msg and "j2" in msg and "not found" in msg
    assert str(path) in msg


@pytest.mark.parametrize("kind", ["fifo", "dev_zero"])
def test_a_mesh_that_is_not_a_regular_file_is_refused_unread(tmp_path, kind):
    """Issue 25: a FIFO (reading blocks forever) or /dev/zero (never ends) named as a
    mesh was "not found"; it is named for what it is, and never opened."""
    import os
    import re

    import yaml

    mesh = tmp_path / "m.stl"
    if kind == "fifo":
        os.mkfifo(mesh)
    else:
        mesh.symlink_to("/dev/zero")
    path = tmp_path / "arm.yaml"
    path.write_text(yaml.safe_dump(_doc({"j2": [{"type": "mesh", "file": "m.stl"}]})))
    what = "a FIFO" if kind == "fifo" else "a character device (through a symlink)"
    with pytest.raises(ModelError, match=re.escape(
            f"geometry.j2[0].file: mesh file: {mesh} is not a regular file: {what}")):
        robokin.load(path)
    from robokin.model.geometry import mesh as mesh_shape

    with pytest.raises(ModelError, match="is not a regular file"):
        mesh_shape(mesh).trimesh()  # the API's loader checks it too


def test_corrupt_mesh_names_the_file_and_the_link(tmp_path):
    import yaml

    bad = tmp_path / "broken.stl"
    bad.write_bytes(b"solid nonsense\n this is not an STL at all \x00\x01\x02")
    path = tmp_path / "arm.yaml"
    path.write_text(
        yaml.safe_dump(_doc({"j1": [{"type": "mesh", "file": "broken.stl"}]}))
    )
    r = robokin.load(path)  # meshes load lazily ...
    with pytest.raises(ModelError) as exc:  # ... and fail clearly on first use
        r.geometry.check_files()
    msg = str(exc.value)
    assert "broken.stl" in msg and "'j1'" in msg


def test_unsupported_mesh_format_is_refused(tmp_path):
    (tmp_path / "part.step").write_text("ISO-10303-21;")
    with pytest.raises(ModelError, match="unsupported mesh format"):
        parts_from_document(
            _doc({"j1": [{"type": "mesh", "file": "part.step"}]}),
            file=tmp_path / "a.yaml",
        )



def test_an_oversized_mesh_is_refused_before_trimesh_reads_it(tmp_path, monkeypatch):
    pytest.importorskip("trimesh")
    _write_box_stl(tmp_path / "big.stl", (10.0, 10.0, 10.0))
    monkeypatch.setattr(geo, "MAX_MESH_BYTES", 100)
    shape = geo.mesh(tmp_path / "big.stl", owner="j1")
    with pytest.raises(ModelError, match=r"big\.stl: j1: mesh file of \d+ bytes "
                                         r"\(link 'j1'\), more than the 100"):
        shape.trimesh()
