"""What an arm IS: the canonical chain, DH and elementary inputs, couplings, files."""

from robokin.model.chain import Chain, ChainBuilder, Joint
from robokin.model.coupling import AffineMap

__all__ = ["AffineMap", "Chain", "ChainBuilder", "Joint"]
