"""CLI verbs ``analyze``, ``study``, ``simulate``, ``demo`` and ``diagnose``, one module each.

Each module exposes ``add_parser(subparsers)``, listed in ``contactlab.cli._VERB_MODULES``.
Every verb computes all its outputs in memory first and writes them all or nothing, so a bad
input or Ctrl-C leaves the output folder as it was.
"""
