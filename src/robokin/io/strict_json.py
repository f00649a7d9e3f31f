"""Strict JSON for everything robokin prints or writes as JSON.

``json.dumps`` writes NaN and infinities as ``NaN`` / ``Infinity``, which is not
JSON: other tools refuse it. :func:`strict_json` writes ``null`` instead and says
why, under a top-level ``"nulls"`` key.
"""

from __future__ import annotations

import json
import math
from typing import Any

__all__ = ["strict_json"]


def strict_json(doc: Any, *, indent: int | None = None) -> str:
    """``doc`` as strict JSON: NaN and infinities become null, with the reason.

    Every replaced number is listed under a top-level ``"nulls"`` key as
    ``{"path.to[0].value": "NaN: not defined" | "Infinity: no finite value"}``
    (``doc`` must be a mapping for that key to be added). Objects JSON has no
    type for (paths) are written as their text.
    """
    nulls: dict[str, str] = {}

    def clean(x: Any, where: str) -> Any:
        if isinstance(x, dict):
            return {str(k): clean(v, f"{where}.{k}" if where else str(k))
                    for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v, f"{where}[{i}]") for i, v in enumerate(x)]
        if hasattr(x, "tolist") and not isinstance(x, (str, bytes)):
            return clean(x.tolist(), where)
        if isinstance(x, float) and not math.isfinite(x):
            nulls[where] = ("NaN: not defined here" if math.isnan(x)
                            else f"{'-' if x < 0 else ''}Infinity: no finite value")
            return None
        return x

    out = clean(doc, "")
    if nulls and isinstance(out, dict):
        out["nulls"] = nulls
    return json.dumps(out, allow_nan=False, indent=indent, default=str)
