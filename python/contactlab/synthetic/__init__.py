"""Synthetic recordings: independent generators of the measurement chain (see docs/effects.md)."""
