"""Studies over many recordings and tracking of one long recording over time.

- :func:`run_study` (:mod:`.study`): one table of fitted parameters against load, amplitude or
  p0 over a set of tagged recordings (:mod:`.manifest`), drawn by :mod:`.plots`.
- :func:`track` (:mod:`.track`): the same quantities window by window along a long recording
  (every N cycles or T seconds), read in chunks so that memory stays bounded.
- ``executor=`` (:mod:`.executor`): both run on ``concurrent.futures`` executors or a Dask
  ``distributed.Client`` with the serial run's results.
"""

from __future__ import annotations

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
