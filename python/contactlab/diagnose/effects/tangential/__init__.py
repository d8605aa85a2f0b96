"""Tangential effects (one module each, registered on import) and the record-level memos
their ``apply`` and the family share (:mod:`._common`)."""

from ._common import delay_support, fixed, memo, turn_clipped_input

__all__ = ["delay_support", "fixed", "memo", "turn_clipped_input"]
