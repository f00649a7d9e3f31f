"""Closed-form IK, one module per family, plus detection from the chain's geometry."""
