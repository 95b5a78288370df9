#!/usr/bin/env python3
"""Check the studio's latency against issue 31's targets, from the JSON that
`tyndall_studio_latency --all --json FILE` writes (docs/testing.md, "The studio's responsiveness"):

  tools/check-latency-targets.py FILE [--first-median 50] [--first-p95 100] [--stall 20]

Prints one line per view (its first-image median and 95th percentile during the drag, its full-resolution median) with
what it misses, then the GUI thread's stalls. Exit 0: every target met; 1: a target missed; 2: the file is not such a
list (named, with the entry and field that is wrong)."""
import argparse
import json
import sys


def number(entry, index, path, field):
    value = entry
    for key in field.split("."):
        if not isinstance(value, dict) or key not in value:
            raise ValueError(f"entry {index}: no field '{field}'")
        value = value[key]
    if not isinstance(value, (int, float)) or isinstance(value, bool) or value < 0:
        raise ValueError(f"entry {index}: '{field}' is {value!r}, not a number of milliseconds >= 0")
    return float(value)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file")
    parser.add_argument("--first-median", type=float, default=50.0, help="ms (default 50)")
    parser.add_argument("--first-p95", type=float, default=100.0, help="ms (default 100)")
    parser.add_argument("--stall", type=float, default=20.0, help="the GUI thread's longest stall, ms (default 20)")
    args = parser.parse_args()
    try:
        with open(args.file, encoding="utf-8") as f:
            entries = json.load(f)
        if not isinstance(entries, list) or not entries:
            raise ValueError("the top level is not a non-empty list")
        views, stalls = [], None
        for i, e in enumerate(entries):
            if not isinstance(e, dict):
                raise ValueError(f"entry {i} is not an object")
            if "stallMs" in e:
                stalls = (number(e, i, args.file, "stallMs.longest"), number(e, i, args.file, "stallMs.p99"))
                continue
            for key in ("project", "view", "technique"):
                if not isinstance(e.get(key), str):
                    raise ValueError(f"entry {i}: no string field '{key}'")
            views.append((e["project"], e["view"], e["technique"], number(e, i, args.file, "firstImageMs.median"),
                          number(e, i, args.file, "firstImageMs.p95"),
                          number(e, i, args.file, "fullResolutionMs.median")))
        if stalls is None:
            raise ValueError("no entry with 'stallMs'")
    except (OSError, ValueError) as error:  # json.JSONDecodeError is a ValueError
        print(f"{args.file}: {error}", file=sys.stderr)
        return 2

    missed = 0
    for project, view, technique, median, p95, full in views:
        misses = []
        if median > args.first_median:
            misses.append(f"median > {args.first_median:g}")
        if p95 > args.first_p95:
            misses.append(f"p95 > {args.first_p95:g}")
        missed += bool(misses)
        print(f"{'MISS' if misses else 'ok  '} {project:40} {view:20} {technique:10} first image {median:6.0f} ms "
              f"(p95 {p95:6.0f}), full resolution {full:7.0f} ms  {'; '.join(misses)}")
    stall_missed = stalls[0] > args.stall
    print(f"{'MISS' if stall_missed else 'ok  '} GUI thread: longest stall {stalls[0]:.1f} ms (target {args.stall:g}), "
          f"99th percentile {stalls[1]:.1f} ms")
    print(f"{len(views) - missed} of {len(views)} views within the first-image targets")
    return 1 if missed or stall_missed else 0


if __name__ == "__main__":
    sys.exit(main())
