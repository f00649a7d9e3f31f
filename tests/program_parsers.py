"""Small readers of the six controller dialects robokin writes (tests only).

Each reads the files back with its own regular expressions, following the vendor's
syntax (not robokin's writer), and returns the moves with their targets: joint values
[deg] and / or a Cartesian pose (4, 4) [mm] built with scipy from the vendor's angle
convention, plus the configuration data as written. They are the oracle of the
round-trip tests: what a controller would read.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation


@dataclass
class ParsedMove:
    kind: str                      # "joint" | "linear"
    joints: np.ndarray | None      # (6,) [deg]
    pose: np.ndarray | None        # (4, 4) [mm]
    config: dict = field(default_factory=dict)
    speed: str = ""
    zone: str = ""


@dataclass
class ParsedProgram:
    name: str
    moves: list[ParsedMove]
    tool: np.ndarray
    base: np.ndarray
    extra: dict = field(default_factory=dict)


def pose(xyz, R) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz
    return T


def _crlf_lines(path: Path) -> list[str]:
    """The lines of a controller file written with CR LF line ends (checked)."""
    text = path.read_bytes().decode("ascii")
    assert "\n" not in text.replace("\r\n", ""), f"{path.name}: a bare LF"
    return text.split("\r\n")


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.replace(",", " ").split()]


# ----------------------------------------------------------------------- KUKA
def _krl_fields(body: str) -> dict[str, float]:
    out = {}
    for item in body.split(","):
        key, value = item.strip().split()
        out[key] = float(value)
    return out


def _krl_frame(f: dict[str, float]) -> np.ndarray:
    R = Rotation.from_euler("ZYX", [f["A"], f["B"], f["C"]], degrees=True).as_matrix()
    return pose([f["X"], f["Y"], f["Z"]], R)


def parse_kuka(folder: Path, name: str) -> ParsedProgram:
    src = _crlf_lines(folder / f"{name}.src")
    dat = _crlf_lines(folder / f"{name}.dat")
    assert src[0] == "&ACCESS RVP" and dat[0] == "&ACCESS RVP"
    decls = {}
    for line in dat:
        m = re.fullmatch(r"DECL (E6AXIS|E6POS|FRAME) (\w+)=\{(.*)\}", line)
        if m:
            decls[m.group(2)] = (m.group(1), _krl_fields(m.group(3)))
    moves = []
    speed_ptp, speed_cp, cdis = None, None, None
    for line in (s.strip() for s in src):
        if m := re.fullmatch(r"BAS\(#VEL_PTP, (\d+)\)", line):
            speed_ptp = m.group(1)
        elif m := re.fullmatch(r"\$VEL\.CP = (\S+)", line):
            speed_cp = m.group(1)
        elif m := re.fullmatch(r"\$APO\.CDIS = (\S+)", line):
            cdis = m.group(1)
        elif m := re.fullmatch(r"(PTP|LIN) (\w+)( C_PTP| C_DIS)?", line):
            kind, f = decls[m.group(2)]
            joints = np.array([f[f"A{k}"] for k in range(1, 7)]) if kind == "E6AXIS" else None
            T = _krl_frame(f) if kind == "E6POS" else None
            config = {"S": int(f["S"]), "T": int(f["T"])} if kind == "E6POS" else {}
            moves.append(ParsedMove("joint" if m.group(1) == "PTP" else "linear", joints, T,
                                    config, speed_ptp if m.group(1) == "PTP" else speed_cp,
                                    (m.group(3) or "").strip() + (
                                        f" {cdis}" if m.group(3) == " C_DIS" else "")))
    return ParsedProgram(name, moves, _krl_frame(decls["RK_TOOL"][1]),
                         _krl_frame(decls["RK_BASE"][1]))


# ------------------------------------------------------------------------ ABB
def _quat(text: str) -> np.ndarray:
    w, x, y, z = _floats(text)
    assert abs(w * w + x * x + y * y + z * z - 1.0) < 1e-6  # RAPID needs unit quaternions
    return Rotation.from_quat([x, y, z, w]).as_matrix()


def parse_abb(folder: Path, name: str) -> ParsedProgram:
    text = (folder / f"{name}.mod").read_text()
    tool = re.search(r"PERS tooldata rkTool := \[TRUE,\[\[(.*?)\],\[(.*?)\]\],", text)
    wobj = re.search(r'TASK PERS wobjdata rkWobj := \[FALSE,TRUE,"",\[\[(.*?)\],\[(.*?)\]\],',
                     text)
    joints = {m.group(1): np.array(_floats(m.group(2))) for m in re.finditer(
        r"CONST jointtarget (\w+) := \[\[(.*?)\],\[9E\+09(?:,9E\+09){5}\]\];", text)}
    robs = {m.group(1): (pose(_floats(m.group(2)), _quat(m.group(3))),
                         [int(v) for v in m.group(4).split(",")])
            for m in re.finditer(r"CONST robtarget (\w+) := \[\[(.*?)\],\[(.*?)\],\[(.*?)\],"
                                 r"\[9E\+09(?:,9E\+09){5}\]\];", text)}
    moves = []
    for m in re.finditer(r"(MoveAbsJ|MoveJ|MoveL) (\w+), (\w+), (\w+), rkTool \\WObj:=rkWobj;",
                         text):
        instr, target = m.group(1), m.group(2)
        if instr == "MoveAbsJ":
            moves.append(ParsedMove("joint", joints[target], None, {}, m.group(3), m.group(4)))
        else:
            T, cf = robs[target]
            moves.append(ParsedMove("joint" if instr == "MoveJ" else "linear", None, T,
                                    {"confdata": cf}, m.group(3), m.group(4)))
    speeds = {m.group(1): float(m.group(2)) for m in re.finditer(
        r"CONST speeddata (\w+) := \[(\S+?),", text)}
    return ParsedProgram(name, moves, pose(_floats(tool.group(1)), _quat(tool.group(2))),
                         pose(_floats(wobj.group(1)), _quat(wobj.group(2))),
                         {"speeds": speeds})


# ---------------------------------------------------------------------- FANUC
def _wpr(x, y, z, w, p, r) -> np.ndarray:
    return pose([x, y, z], Rotation.from_euler("xyz", [w, p, r], degrees=True).as_matrix())


def parse_fanuc(folder: Path, name: str) -> ParsedProgram:
    lines = _crlf_lines(folder / f"{name}.ls")
    assert lines[0] == f"/PROG  {name}"
    mn, pos = lines.index("/MN"), lines.index("/POS")
    positions = {}
    k = pos + 1
    while lines[k] != "/END":
        m = re.fullmatch(r"P\[(\d+)\]\{", lines[k])
        block = []
        k += 1
        while lines[k] != "};":
            block.append(lines[k])
            k += 1
        k += 1
        body = " ".join(block)
        conf = re.search(r"CONFIG : '(.*?)'", body)
        if "J1=" in body:
            vals = [float(v) for v in re.findall(r"J\d=\s*(\S+) deg", body)]
            positions[int(m.group(1))] = (np.array(vals), None, {})
        else:
            vals = {a: float(v) for a, v in re.findall(r"\b([XYZWPR]) =\s*(\S+)\s+(?:mm|deg)",
                                                       body)}
            T = _wpr(*(vals[a] for a in "XYZWPR"))
            positions[int(m.group(1))] = (None, T, {"config": conf.group(1)})
    moves, frames = [], {}
    for line in lines[mn + 1:pos]:
        if m := re.fullmatch(r"\s*\d+:(J|L) P\[(\d+)\] (\d+(?:%|mm/sec)) (FINE|CNT\d+)\s*;", line):
            joints, T, conf = positions[int(m.group(2))]
            moves.append(ParsedMove("joint" if m.group(1) == "J" else "linear", joints, T,
                                    conf, m.group(3), m.group(4)))
        elif m := re.fullmatch(r"\s*\d+:  (UFRAME_NUM|UTOOL_NUM)=(\d+) ;", line):
            frames[m.group(1)] = int(m.group(2))
    return ParsedProgram(name, moves, np.eye(4), np.eye(4), {"frames": frames,
                                                            "lines": lines})


# -------------------------------------------------------------------- Yaskawa
def parse_yaskawa(folder: Path, name: str, pulses_per_degree=None) -> ParsedProgram:
    lines = _crlf_lines(folder / f"{name}.JBI")
    assert lines[:3] == ["/JOB", f"//NAME {name}", "//POS"]
    variables, mode, rconf = {}, None, None
    inst = lines.index("//INST")
    for line in lines[3:inst]:
        if line == "///PULSE":
            mode = "pulse"
        elif line == "///RECTAN":
            mode = "rectan"
        elif line.startswith("///RCONF "):
            rconf = [int(v) for v in line.split()[1].split(",")]
        elif m := re.fullmatch(r"C(\d{5})=(.*)", line):
            vals = _floats(m.group(2))
            if mode == "pulse":
                variables[int(m.group(1))] = (np.array(vals) / np.asarray(pulses_per_degree),
                                              None, {"pulses": vals})
            else:
                x, y, z, rx, ry, rz = vals
                variables[int(m.group(1))] = (None, _wpr(x, y, z, rx, ry, rz),
                                              {"rconf": rconf})
    moves = []
    for line in lines[inst:]:
        if m := re.fullmatch(r"(MOVJ|MOVL) C(\d{5}) (VJ|V)=(\S+) PL=(\d)", line):
            joints, T, conf = variables[int(m.group(2))]
            moves.append(ParsedMove("joint" if m.group(1) == "MOVJ" else "linear", joints, T,
                                    conf, m.group(4), m.group(5)))
    npos = next(ln for ln in lines if ln.startswith("///NPOS "))
    return ParsedProgram(name, moves, np.eye(4), np.eye(4),
                         {"npos": int(npos.split()[1].split(",")[0]), "lines": lines,
                          "variables": len(variables)})


# -------------------------------------------------------------------- Staubli
_NS = {"d": "http://www.staubli.com/robotics/VAL3/Data/2"}


def _val3_pose(v) -> np.ndarray:
    a = {k: float(v.get(k)) for k in ("x", "y", "z", "rx", "ry", "rz")}
    R = Rotation.from_euler("XYZ", [a["rx"], a["ry"], a["rz"]], degrees=True).as_matrix()
    return pose([a["x"], a["y"], a["z"]], R)


def parse_staubli(folder: Path, name: str) -> ParsedProgram:
    app = folder / name
    pjx = ET.parse(app / f"{name}.pjx").getroot()
    files = [p.get("file") for p in pjx.iter("{http://www.staubli.com/robotics/VAL3/Project/3}"
                                             "Program")]
    assert files == ["start.pgx", "stop.pgx"]
    dtx = ET.parse(app / f"{name}.dtx").getroot()
    data = {}
    for d in dtx.iterfind("d:Datas/d:Data", _NS):
        values = d.findall("d:Value", _NS)
        assert int(d.get("size")) == len(values), d.get("name")
        assert [int(v.get("key")) for v in values] == list(range(len(values)))
        data[d.get("name")] = values
    pgx = ET.parse(app / "start.pgx").getroot()
    code = pgx.find("{http://www.staubli.com/robotics/VAL3/Program/2}Program/"
                    "{http://www.staubli.com/robotics/VAL3/Program/2}Code").text
    assert code.strip().startswith("begin") and code.strip().endswith("end")
    moves = []
    for m in re.finditer(r"(movej|movel)\((jPath|pPath)\[(\d+)\], tRk\[0\], mRk\[(\d+)\]\)",
                         code):
        k = int(m.group(3))
        desc = dict(data["mRk"][int(m.group(4))].attrib)
        if m.group(2) == "jPath":
            v = data["jPath"][k]
            moves.append(ParsedMove("joint", np.array([float(v.get(f"j{i}")) for i in
                                                       range(1, 7)]), None, {}, desc["vel"],
                                    desc["blend"]))
        else:
            v = data["pPath"][k]
            conf = {key: v.get(key) for key in ("shoulder", "elbow", "wrist")}
            moves.append(ParsedMove("joint" if m.group(1) == "movej" else "linear", None,
                                    _val3_pose(v), conf,
                                    desc["vel"] if m.group(1) == "movej" else desc["tmax"],
                                    desc["blend"]))
    return ParsedProgram(name, moves, _val3_pose(data["tRk"][0]), _val3_pose(data["fRk"][0]),
                         {"data": data})


# ------------------------------------------------------------------- Kawasaki
def _oat(x, y, z, o, a, t) -> np.ndarray:
    return pose([x, y, z], Rotation.from_euler("ZYZ", [o, a, t], degrees=True).as_matrix())


def parse_kawasaki(folder: Path, name: str) -> ParsedProgram:
    lines = _crlf_lines(folder / f"{name}.as")
    assert lines[0] == f".PROGRAM {name}()"
    end = lines.index(".END")
    tr, jt = lines.index(".TRANS"), lines.index(".JOINTS")
    trans = {ln.split()[0]: _oat(*_floats(" ".join(ln.split()[1:])))
             for ln in lines[tr + 1:lines.index(".END", tr)]}
    joints = {ln.split()[0]: np.array(_floats(" ".join(ln.split()[1:])))
              for ln in lines[jt + 1:lines.index(".END", jt)]}
    moves, speed, accuracy = [], None, None
    for line in (s.strip() for s in lines[1:end]):
        if m := re.fullmatch(r"SPEED (\S+)( MM/S)? ALWAYS", line):
            speed = m.group(1) + (m.group(2) or "")
        elif m := re.fullmatch(r"ACCURACY (\S+) ALWAYS", line):
            accuracy = m.group(1)
        elif m := re.fullmatch(r"JMOVE (#\w+)", line):
            moves.append(ParsedMove("joint", joints[m.group(1)], None, {}, speed, accuracy))
        elif m := re.fullmatch(r"LMOVE (\w+)", line):
            moves.append(ParsedMove("linear", None, trans[m.group(1)], {}, speed, accuracy))
    return ParsedProgram(name, moves, trans["rk_tool"], trans["rk_base"], {"lines": lines})


PARSERS = {"kuka_krl": parse_kuka, "abb_rapid": parse_abb, "fanuc_tp": parse_fanuc,
           "yaskawa_inform": parse_yaskawa, "staubli_val3": parse_staubli,
           "kawasaki_as": parse_kawasaki}
