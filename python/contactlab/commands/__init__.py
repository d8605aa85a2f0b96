"""CLI verbs ``analyze``, ``study``, ``simulate``, ``demo`` and ``diagnose``, one module each.

Each module exposes ``add_parser(subparsers)``, listed in ``contactlab.cli._VERB_MODULES``.
Every verb computes all its outputs in memory first and writes them all or nothing, so a bad
input or Ctrl-C leaves the output folder as it was.
"""


def kill_worker_processes() -> None:
    """End the worker processes of the verbs' pools (for the CLI's exit on Ctrl-C); see
    ``_common.kill_worker_processes``. Loads the verbs' shared module only when called."""
    from ._common import kill_worker_processes as kill

    kill()
