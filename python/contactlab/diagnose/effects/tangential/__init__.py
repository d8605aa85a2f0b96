"""Tangential effects (one module each, registered on import)."""
