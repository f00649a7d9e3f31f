"""The one place robokin imports MuJoCo (the ``robokin[sim]`` extra)."""

from __future__ import annotations

from typing import Any

from robokin.exceptions import MissingExtraError

__all__ = ["load_model", "mujoco"]


def mujoco() -> Any:
    """The ``mujoco`` module.

    Raises:
        MissingExtraError: MuJoCo is not installed (or is a build without its
            compiled core), naming the ``sim`` extra.
    """
    try:
        import mujoco as mj
    except ImportError:
        raise MissingExtraError("mujoco", "sim") from None
    if not hasattr(mj, "MjModel"):  # a shell without the compiled core
        raise MissingExtraError("mujoco", "sim")
    if hasattr(mj, "set_mju_user_warning") and mj.get_mju_user_warning() is None:
        # MuJoCo's default handler appends its warnings to MUJOCO_LOG.TXT in the
        # working directory: a Python warning instead (nothing written behind the
        # user's back)
        mj.set_mju_user_warning(_warn)
    return mj


def _warn(message: str) -> None:
    import warnings

    warnings.warn(f"MuJoCo: {message.strip()}", RuntimeWarning, stacklevel=2)


def load_model(xml: str) -> Any:
    """Compile MJCF text into an ``MjModel``.

    Raises:
        ModelError: MuJoCo refuses the model (its message, one line).
    """
    from robokin.exceptions import ModelError

    mj = mujoco()
    try:
        return mj.MjModel.from_xml_string(xml)
    except ValueError as exc:
        raise ModelError("MuJoCo refused the model: " + " ".join(str(exc).split())
                         ) from None


def full_mass_matrix(model: Any, data: Any) -> Any:
    """The dense joint-space mass matrix (nv, nv) after ``mj_forward``.

    MuJoCo changed ``mj_fullM``'s signature (``(m, dst, d.qM)`` before 3.3.?,
    ``(m, d, dst)`` since); both are accepted.
    """
    import numpy as np

    mj = mujoco()
    out = np.zeros((model.nv, model.nv))
    if hasattr(data, "qM"):
        mj.mj_fullM(model, out, data.qM)
    else:
        mj.mj_fullM(model, data, out)
    return out
