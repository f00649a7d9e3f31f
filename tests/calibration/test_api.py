"""The calibration package's public names: ``__all__`` imports, sorted; the DESIGN contract."""

from __future__ import annotations

import inspect

import robokin
from robokin import calibration


def test_every_all_name_imports_and_is_sorted():
    for name in calibration.__all__:
        assert getattr(calibration, name) is not None, name
    assert calibration.__all__ == sorted(calibration.__all__)
    assert robokin.calibration is calibration  # the lazy attribute


def test_contract_names_and_arguments():
    sig = inspect.signature(calibration.calibrate)
    assert list(sig.parameters)[:5] == ["robot", "q", "measured", "kind", "model"]
    assert sig.parameters["kind"].default == "position"
    assert sig.parameters["model"].default == "auto"
    assert list(inspect.signature(calibration.evaluate).parameters)[:3] == [
        "robot", "q", "measured"]
    sel = inspect.signature(calibration.select_poses)
    assert list(sel.parameters)[:4] == ["robot", "candidate_q", "k", "kind"]
    fields = calibration.CalibrationResult.__dataclass_fields__
    assert {"robot", "parameters", "unidentifiable", "residual_rms"} <= set(fields)
    assert {"name", "nominal", "identified", "std"} <= set(
        calibration.Parameter.__dataclass_fields__)
