"""Exception hierarchy. Every error contactlab raises derives from :class:`ContactLabError`.

The Rust core raises these same classes (it imports them from here), so ``except
contactlab.ContactLabError`` catches everything, and ``except ValueError`` still catches bad
input as users of numpy/scipy expect.
"""

from __future__ import annotations


class ContactLabError(Exception):
    """Base class of every contactlab error."""


class InputError(ContactLabError, ValueError):
    """Input data or parameters are invalid (the message names what and where)."""


class ConvergenceError(ContactLabError, RuntimeError):
    """A solver or fit could not reach the requested tolerance."""


class ContactLabWarning(UserWarning):
    """Something a user may reasonably go on with, but should know about."""
