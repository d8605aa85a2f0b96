"""Typed options per contact kind (issue 32), and how every entry point takes them.

:class:`contactlab.tangential.Options` and :class:`contactlab.normal.Options` are frozen
dataclasses of the settings a user gives once and every entry point shares (a known channel
delay, the force's sign, a reconstructed force's output filter, the static pressure ...).
The analyses, :func:`~contactlab.diagnose`, :func:`~contactlab.track` and
:func:`~contactlab.studies.run_study` take them as ``options=`` (studies as
``tangential_options=`` / ``normal_options=``), the same way they take a plain dict of the
same names; the command line only parses its flags into them. Fields left at None are not
passed on, so each function keeps its own defaults, and a field a function does not take is
refused with an :class:`~contactlab.errors.InputError` naming it.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

from .errors import InputError

F = TypeVar("F", bound=Callable[..., Any])

__all__ = ["as_dict", "takes_options"]


def as_dict(options: Any) -> dict[str, Any]:
    """The options given (an Options dataclass, a mapping or None) as a dict of the settings
    given: a dataclass's fields that are not None, a mapping's items as they are."""
    if options is None:
        return {}
    if dataclasses.is_dataclass(options) and not isinstance(options, type):
        return {
            f.name: getattr(options, f.name)
            for f in dataclasses.fields(options)
            if getattr(options, f.name) is not None
        }
    if isinstance(options, Mapping):
        return dict(options)
    raise InputError(
        f"options must be a contactlab.tangential.Options, contactlab.normal.Options or a "
        f"dict, got {type(options).__name__}"
    )


def takes_options(fn: F) -> F:
    """Decorator: ``fn(..., options=Options(...))`` passes the options' settings on as keyword
    arguments; one also given as a keyword, or one ``fn`` does not take, is an InputError."""
    accepted = set(inspect.signature(fn).parameters)

    @functools.wraps(fn)
    def wrapper(*args: Any, options: Any = None, **kwargs: Any) -> Any:
        given = as_dict(options)
        unknown = sorted(set(given) - accepted)
        if unknown:
            raise InputError(f"{fn.__name__}() takes no option {', '.join(unknown)}")
        twice = sorted(set(given) & set(kwargs))
        if twice:
            raise InputError(f"{', '.join(twice)} given both as options and as a keyword")
        return fn(*args, **given, **kwargs)

    return wrapper  # type: ignore[return-value]
