"""Studies over many recordings and tracking of one long recording over time.

- :func:`run_study` (:mod:`.study`): one table of fitted parameters against load, amplitude or
  p0 over a set of tagged recordings (:mod:`.manifest`), drawn by :mod:`.plots`.
- :func:`track` (:mod:`.track`): the same quantities window by window along a long recording
  (every N cycles or T seconds), read in chunks so that memory stays bounded.
- ``executor=`` (:mod:`.executor`): both run on ``concurrent.futures`` executors or a Dask
  ``distributed.Client`` with the serial run's results.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .executor import ordered_map
    from .manifest import StudyEntry, entry_from_file, read_manifest, tags_from_filename
    from .study import (
        KINDS,
        RecordingResult,
        StudyResult,
        analyze_entry,
        collect_entries,
        run_study,
    )
    from .tracking import TrackResult, parse_every, track, track_many

# The names load on first use (PEP 562): a command that needs one module of the package (the
# manifest's tags of a file, say) does not import the study and tracking workflows, their
# executors and concurrent.futures before it reads its first sample (issue 33).
_LAZY = {
    "ordered_map": "executor",
    "StudyEntry": "manifest",
    "entry_from_file": "manifest",
    "read_manifest": "manifest",
    "tags_from_filename": "manifest",
    "KINDS": "study",
    "RecordingResult": "study",
    "StudyResult": "study",
    "analyze_entry": "study",
    "collect_entries": "study",
    "run_study": "study",
    "TrackResult": "tracking",
    "parse_every": "tracking",
    "track": "tracking",
    "track_many": "tracking",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value  # later look-ups skip __getattr__
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "KINDS",
    "RecordingResult",
    "StudyEntry",
    "StudyResult",
    "TrackResult",
    "analyze_entry",
    "collect_entries",
    "entry_from_file",
    "ordered_map",
    "parse_every",
    "read_manifest",
    "run_study",
    "tags_from_filename",
    "track",
    "track_many",
]
