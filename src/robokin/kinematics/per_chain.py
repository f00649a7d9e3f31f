"""Data derived from a chain and kept while the chain lives: one cache for all.

IK family detection, the numeric solver's seed table and the single-pose IK paths
are worth computing once per chain. A :class:`~robokin.model.chain.Chain` is
immutable, so they are stored here, keyed by the chain object (weakly: they go
when the chain goes), never as attributes on the chain.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any, TypeVar

from robokin.model.chain import Chain

__all__ = ["cached"]

T = TypeVar("T")

# id(chain) -> that chain's values; an entry goes when its chain does (a finalizer),
# before the id can be reused. A dict lookup by id costs a tenth of a weak-key one,
# and the IK single-pose path looks here on every call.
_STORE: dict[int, dict[Any, Any]] = {}


def cached(chain: Chain, key: Any, build: Callable[[], T]) -> T:
    """``build()`` for ``(chain, key)``, computed on first use and kept with the chain.

    Args:
        chain: The chain the value derives from.
        key: What the value is (hashable), e.g. ``("ik_family", tol)``.
        build: Computes the value (called at most once per chain and key, unless
            two threads race: then both compute it and one result is kept).

    Returns:
        The cached value.
    """
    per = _STORE.get(id(chain))
    if per is None:
        per = _STORE.setdefault(id(chain), {})
        weakref.finalize(chain, _STORE.pop, id(chain), None)
    try:
        return per[key]
    except KeyError:
        value = per[key] = build()
        return value
