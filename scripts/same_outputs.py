#!/usr/bin/env python3
"""Compares two output folders of mbot_nav runs file by file, ignoring what depends on the machine's
speed: JSON keys about wall time (wall*, *_ms, ms_*, real_time_factor, timing, rss*, graph SLAM's
phase seconds, planning times in µs) and the output folder's name, and CSV columns named so (update_ms, rss_mb).
JSON files are compared as JSON (the same keys and values; layout aside), everything else must
be byte-identical.

  scripts/same_outputs.py OLD_DIR NEW_DIR     exit 0: the same; 1: the files that differ are listed
"""
import csv
import io
import json
import os
import re
import sys

TIMING = re.compile(
    r"(^wall|_ms$|^ms_|_ms_|real_time_factor|^timing$|^rss|^(front_end|loop_search|optimize|render|apply_max)_s$"
    r"|_us$|^expansions_per_s$|^speedup_of_mean$|^outputs$)")
SKIP_FILES = re.compile(r"\.log$")


def scrub(value):
    if isinstance(value, dict):
        return {k: scrub(v) for k, v in value.items() if not TIMING.search(k)}
    if isinstance(value, list):
        return [scrub(v) for v in value]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)  # a JSON number: 0 and 0.0 are the same number
    return value


def normalized(path):
    data = open(path, "rb").read()
    if path.endswith(".json"):
        try:
            return json.dumps(scrub(json.loads(data)), sort_keys=True)
        except ValueError:
            return data
    if path.endswith(".csv"):
        rows = list(csv.reader(io.StringIO(data.decode("utf-8", "replace"))))
        if not rows:
            return data
        keep = [i for i, name in enumerate(rows[0]) if not TIMING.search(name)]
        return "\n".join(",".join(r[i] for i in keep if i < len(r)) for r in rows)
    return data


def files(root):
    out = set()
    for d, _, names in os.walk(root):
        for n in names:
            rel = os.path.relpath(os.path.join(d, n), root)
            if not SKIP_FILES.search(rel):
                out.add(rel)
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, b = sys.argv[1], sys.argv[2]
    fa, fb = files(a), files(b)
    bad = sorted(("only in " + a + ": " + f) for f in fa - fb) + sorted(("only in " + b + ": " + f) for f in fb - fa)
    same = 0
    for f in sorted(fa & fb):
        if normalized(os.path.join(a, f)) != normalized(os.path.join(b, f)):
            bad.append("differs: " + f)
        else:
            same += 1
    for line in bad:
        print(line)
    print("%d files the same, %d differ or are missing" % (same, len(bad)))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
