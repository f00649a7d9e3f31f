"""The build (``setup.py``, issue 25): without a C compiler or the Python headers it
stops with one line saying what is missing, not setuptools' or the compiler's own
error; and the documentation site is not built into setuptools' ``build/``.

Each build runs in a temporary copy of the sources (no compiled kernels in it), so
the tree under test is never touched. The oracle is the build's own output: exactly
one ``error:`` line, naming what is missing, and no traceback.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]


def _copy_sources(tmp_path: Path) -> Path:
    dest = tmp_path / "robokin"
    dest.mkdir()
    for name in ("setup.py", "pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, dest / name)
    shutil.copytree(ROOT / "src", dest / "src",
                    ignore=shutil.ignore_patterns("*.so", "*.pyd", "__pycache__",
                                                  "*.egg-info"))
    return dest


def _build(src: Path, **env: str) -> subprocess.CompletedProcess[str]:
    full = dict(os.environ, **env)
    full.pop("PYTHONPATH", None)
    return subprocess.run([sys.executable, "setup.py", "-q", "build_ext"], cwd=src,
                          env=full, capture_output=True, text=True, timeout=300,
                          check=False)


def _one_error_line(proc: subprocess.CompletedProcess[str]) -> str:
    assert proc.returncode != 0
    text = proc.stdout + proc.stderr
    assert "Traceback" not in text, text
    errors = [ln for ln in text.splitlines() if ln.startswith("error:")]
    assert len(errors) == 1, text
    assert errors[0].startswith("error: robokin: "), errors[0]
    return errors[0]


@pytest.mark.skipif(sys.platform == "win32", reason="unix compilers (CC)")
def test_no_compiler_is_one_clear_line(tmp_path):
    src = _copy_sources(tmp_path)
    line = _one_error_line(_build(src, CC=str(tmp_path / "no-such-cc")))
    assert "no C compiler" in line and "no-such-cc" in line
    assert "apt-get install gcc python3-dev" in line and "README.md" in line
    assert not list(src.rglob("*.so"))


@pytest.mark.skipif(sys.platform == "win32", reason="unix compilers (CC)")
def test_pip_shows_the_same_line(tmp_path):
    """What a user sees from pip: its own block, ending with robokin's one line."""
    src = _copy_sources(tmp_path)
    env = dict(os.environ, CC=str(tmp_path / "no-such-cc"))
    env.pop("PYTHONPATH", None)
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "--wheel-dir", str(tmp_path / "dist"), str(src)],
        env=env, capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode != 0
    ours = [ln.strip() for ln in (proc.stdout + proc.stderr).splitlines()
            if "error: robokin: no C compiler" in ln]
    assert len(ours) == 1, proc.stdout + proc.stderr
    assert not list(tmp_path.rglob("*.whl"))


@pytest.mark.skipif(not hasattr(sysconfig, "_get_sysconfigdata_name"),
                    reason="needs CPython's sysconfig data module (posix)")
def test_no_python_headers_is_one_clear_line(tmp_path):
    """The headers' folder empty, as without python3-dev.

    CPython reads its build configuration from the module that
    ``_PYTHON_SYSCONFIGDATA_NAME`` names; a copy of it with ``INCLUDEPY`` pointing
    to an empty folder is what setuptools sees on a machine without the headers.
    """
    import importlib

    if any(Path(d, "Python.h").is_file() for d in (
            Path(sys.prefix) / "include", Path(sys.exec_prefix) / "include")):
        pytest.skip("this environment's own include folder holds Python.h")
    name = sysconfig._get_sysconfigdata_name()  # type: ignore[attr-defined]
    config = dict(importlib.import_module(name).build_time_vars)
    empty = tmp_path / "include"
    empty.mkdir()
    config["INCLUDEPY"] = config["CONFINCLUDEPY"] = str(empty)
    fake = tmp_path / "config"
    fake.mkdir()
    (fake / "_sysconfigdata_robokin_test.py").write_text(
        f"build_time_vars = {config!r}\n")
    src = _copy_sources(tmp_path)
    full = dict(os.environ, _PYTHON_SYSCONFIGDATA_NAME="_sysconfigdata_robokin_test",
                PYTHONPATH=str(fake))
    proc = subprocess.run([sys.executable, "setup.py", "-q", "build_ext"], cwd=src,
                          env=full, capture_output=True, text=True, timeout=300,
                          check=False)
    line = _one_error_line(proc)
    assert "no Python headers" in line and str(empty) in line
    assert "python3-dev" in line


def test_the_documentation_site_is_not_built_into_setuptools_build_folder():
    """mkdocs cleans its site_dir: inside build/ it would share setuptools' folder."""
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    site = Path(config["site_dir"])
    assert not site.is_absolute() and site.parts[0] != "build", site
    assert f"{site.parts[0]}/" in (ROOT / ".gitignore").read_text().splitlines()
