"""Are two builds' window analyses the same within their standard errors? (issue 9)

``dump`` writes every window's row of ``contactlab.track(FILE, every="auto")`` (serial) and
the pooled result as JSON; ``compare`` prints, per quantity, the largest ``|a - b| / SE`` over
the windows (SE: the first file's standard error) and the largest relative difference, and
whether every row is identical.

Run with each build's interpreter, e.g.::

    /work/main/.venv/bin/python benches/compare_track.py dump t1e7.h5 before.json
    .venv/bin/python benches/compare_track.py dump t1e7.h5 after.json
    .venv/bin/python benches/compare_track.py compare before.json after.json
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Iterator
from typing import Any


def dump(path: str, out: str) -> None:
    import contactlab

    r = contactlab.track(path, every="auto", threads=0)
    with open(out, "w") as fh:
        json.dump({"rows": r.rows, "combined": r.combined()}, fh, default=str)


def _numbers(row: dict[str, Any]) -> Iterator[tuple[str, float, Any]]:
    for k, v in row.items():
        if k.endswith("_stderr") or isinstance(v, bool) or not isinstance(v, int | float):
            continue
        yield k, float(v), row.get(f"{k}_stderr")


def compare(a_path: str, b_path: str) -> None:
    with open(a_path) as fa, open(b_path) as fb:
        a, b = json.load(fa), json.load(fb)
    if len(a["rows"]) != len(b["rows"]):
        print(f"different numbers of windows: {len(a['rows'])} and {len(b['rows'])}")
    worst: dict[str, tuple[float, float]] = {}
    identical = True
    for ra, rb in zip(a["rows"], b["rows"], strict=False):
        identical &= ra == rb
        for k, v, se in _numbers(ra):
            w = rb.get(k)
            if not isinstance(w, int | float) or isinstance(w, bool):
                worst[k] = (math.inf, math.inf)
                continue
            d = abs(v - float(w))
            has_se = isinstance(se, int | float) and se > 0
            by_se = d / se if has_se else (0.0 if d == 0 else math.inf)
            rel = d / abs(v) if v else d
            o = worst.get(k, (0.0, 0.0))
            worst[k] = (max(o[0], by_se), max(o[1], rel))
    for k, (s, r) in sorted(worst.items(), key=lambda kv: -kv[1][0]):
        print(f"{k:28s} max |diff|/SE {s:9.3g}   max relative {r:9.3g}")
    print(f"{len(a['rows'])} windows; every row identical: {identical}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("dump")
    d.add_argument("file")
    d.add_argument("out")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = ap.parse_args()
    if args.cmd == "dump":
        dump(args.file, args.out)
    else:
        compare(args.a, args.b)


if __name__ == "__main__":
    main()
