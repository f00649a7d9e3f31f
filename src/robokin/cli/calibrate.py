"""``robokin calibrate``: identify a robot's kinematic errors from tracker measurements.

Reads a measurement CSV (:mod:`robokin.calibration.data_files`: joint columns and
x y z, plus a rotation for ``--kind pose``, by name, units in brackets),
calibrates, prints the parameter table (mm and degrees) and writes, all or none:

* ``-o FILE`` -- the calibrated robot file (base = measuring frame -> robot base,
  tool = flange -> TCP);
* ``FILE_report.json`` and ``FILE_report.txt`` -- parameters, what could not be
  identified and why, the residual and hold-out statistics;
* ``FILE_errors.png`` -- per-pose errors before and after (hold-out poses with
  ``--holdout``, else the calibration poses);
* ``--urdf FILE`` -- also a URDF with the same forward kinematics.

Nothing the user has is overwritten unless ``--force``. Exit codes: 0; 2 for
usage and input errors (a bad file, data that cannot identify the model).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robokin.cli.common import json_text, load_robot
from robokin.cli.output import FormatOption

if TYPE_CHECKING:
    from robokin.calibration import CalibrationResult, HoldoutReport
    from robokin.robot import Robot

__all__ = ["calibrate_command", "commands"]

commands = typer.Typer()


def _split(q: Any, m: Any, holdout: str | None, robot: Robot, kind: str
           ) -> tuple[Any, Any, Any, Any]:
    """Calibration and hold-out rows: a fraction (every k-th row) or a second file."""
    import numpy as np

    from robokin.calibration.data_files import read_measurements
    from robokin.exceptions import InputError

    if holdout is None:
        return q, m, None, None
    try:
        frac = float(holdout)
    except ValueError:
        qh, mh = read_measurements(Path(holdout), robot, kind)
        return q, m, qh, mh
    if not 0.0 < frac < 1.0:
        raise InputError("--holdout", f"expected a fraction in (0, 1) or a CSV file, "
                         f"got {holdout!r}")
    n = len(q)
    k = max(2, round(1.0 / frac))
    hold = np.zeros(n, bool)
    hold[k - 1::k] = True  # every k-th row: deterministic, spread over the file
    return q[~hold], m[~hold], q[hold], m[hold]


def _outputs(out: Path, urdf: Path | None, force: bool) -> list[tuple[Path, str, bool]]:
    stem = out.with_suffix("")
    targets = [(out, "-o", force), (Path(f"{stem}_report.json"), "-o", force),
               (Path(f"{stem}_report.txt"), "-o", force),
               (Path(f"{stem}_errors.png"), "-o", force)]
    if urdf is not None:
        targets.append((urdf, "--urdf", force))
    return targets


def _tables(res: CalibrationResult) -> list[Any]:
    from robokin.cli.output import Column, OutputTable, general

    num = general(8)
    t = OutputTable("identified parameters (lengths mm, angles deg)",
                    [Column("parameter"), Column("unit"), Column("nominal", num, True),
                     Column("identified", num, True), Column("change", num, True),
                     Column("std", general(3), True)])
    for p in res.parameters:
        k, unit = {"m": (1e3, "mm"), "rad": (180 / math.pi, "deg")}.get(p.unit,
                                                                       (1.0, p.unit))
        t.add_row(p.name, unit, p.nominal * k, p.identified * k, p.error * k, p.std * k)
    u = OutputTable("not identified (held at nominal)", [Column("parameter"),
                                                         Column("reason")])
    for name, reason in res.unidentifiable:
        u.add_row(name, reason)
    return [t, u]


def _report_text(res: CalibrationResult, rep: HoldoutReport, on: str) -> str:
    lines = [f"kind: {res.kind}; residual RMS {res.residual_rms * 1e3:.4f} mm "
             f"(noise estimate {res.sigma * 1e3:.4f} mm per coordinate); "
             f"outliers set aside: {list(res.outliers)}",
             f"observability: O1 {res.observability['O1']:.4g}, condition "
             f"{res.observability['condition']:.4g}", f"errors on {on}:", rep.text()]
    return "\n".join(lines)


@commands.command("calibrate")
def calibrate_command(
    robot: Annotated[str, typer.Argument(help="Built-in name or robot file (nominal).")],
    data: Annotated[Path, typer.Argument(help="Measurement CSV file.", metavar="DATA.csv")],
    out: Annotated[Path, typer.Option("-o", "--out", help="Calibrated robot file to write.")],
    kind: Annotated[str, typer.Option(
        "--kind", help="position (x y z) or pose (also a rotation).")] = "position",
    holdout: Annotated[str | None, typer.Option(
        "--holdout", help="Hold-out: a fraction of the rows (every k-th) or a second CSV.",
        metavar="F")] = None,
    urdf: Annotated[Path | None, typer.Option(
        "--urdf", help="Also write a URDF with the same FK.")] = None,
    extras: Annotated[list[str] | None, typer.Option(
        "--extras", help="Declared extras: scale (a gear-ratio error per joint).")] = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Replace existing output files.")] = False,
    output_format: FormatOption = None,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")
                       ] = False,
) -> None:
    """Calibrate ROBOT from measured tool positions (or poses); write the calibrated robot.

    Prints the identified parameters (nominal, identified, change, standard
    deviation), those held at nominal and why, and the hold-out errors.
    """
    import robokin
    from robokin import calibration
    from robokin.calibration.data_files import read_measurements
    from robokin.cli.output import emit, resolve_format, say
    from robokin.exceptions import InputError
    from robokin.io.atomic import staged_outputs

    fmt = resolve_format(output_format, as_json)
    if kind not in ("position", "pose"):
        raise InputError("--kind", f"expected position or pose, got {kind!r}")
    if extras and any(e != "scale" for e in extras):
        raise InputError("--extras", f"the CLI takes 'scale'; got {extras}")
    nominal = load_robot(robot)
    q, m = read_measurements(data, nominal, kind)
    qc, mc, qh, mh = _split(q, m, holdout, nominal, kind)
    targets = _outputs(out, urdf, force)
    with staged_outputs(targets, how="pass --force") as staged:
        res = calibration.calibrate(nominal, qc, mc, kind=kind,  # type: ignore[arg-type]
                                    extras=tuple(extras or ()))
        on = "hold-out poses" if qh is not None else "the calibration poses (no hold-out)"
        rep = calibration.holdout_report(res, qc if qh is None else qh,
                                         mc if mh is None else mh)
        robokin.save(res.robot, staged[0])
        doc = {"robot": nominal.name, "data": str(data), "errors_on": on,
               **res.to_dict(), "errors": rep.to_dict(),
               "files": [str(t[0]) for t in targets]}
        staged[1].write_text(json_text(doc, indent=2) + "\n")
        staged[2].write_text(_report_text(res, rep, on) + "\n")
        calibration.plot_errors(rep, path=staged[3], title=f"{nominal.name}: errors on {on}")
        if urdf is not None:
            staged[4].write_text(res.robot.to_urdf())
    if fmt == "json":
        print(json_text(doc))
        return
    tables = _tables(res)
    emit(tables, fmt)
    say(_report_text(res, rep, on), fmt)
    say("wrote " + ", ".join(str(t[0]) for t in targets), fmt)
