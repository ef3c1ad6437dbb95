#!/usr/bin/env python3
"""Fates of a capture's frames by how long the screen had held its image.

For each frame whose previous frame was shown, the time from that display
change to the frame's GPU completion (PresentMon 1 / FrameView columns:
TimeInSeconds + MsRenderPresentLatency, against the previous frame's
TimeInSeconds + MsUntilDisplayed), in 0.05 ms bins, with how many of the
frames in each bin were shown and dropped. Used in docs/replay.md (Alan
Wake 2 unlimited) to look for the rule by which a variable-refresh panel
drops frames.

    python3 scripts/drops-by-screen-age.py CAPTURE.csv [--skip N] [--app NAME]
"""
import argparse
import collections
import csv
import sys


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("capture")
    p.add_argument("--skip", type=int, default=0, help="frames to leave out at the start")
    p.add_argument("--app", help="the application's rows only (default: all rows)")
    a = p.parse_args()
    try:
        with open(a.capture, newline="") as f:
            rows = [r for r in csv.DictReader(f) if a.app is None or r.get("Application") == a.app]
    except OSError as e:
        sys.exit(f"{a.capture}: {e}")
    need = ["TimeInSeconds", "MsRenderPresentLatency", "MsUntilDisplayed", "Dropped"]
    missing = [c for c in need if rows and c not in rows[0]]
    if not rows or missing:
        sys.exit(f"{a.capture}: no rows, or missing columns {missing}")
    t = [float(r["TimeInSeconds"]) * 1000 for r in rows]
    done = [t[i] + float(r["MsRenderPresentLatency"]) for i, r in enumerate(rows)]
    dropped = [r["Dropped"] == "1" for r in rows]
    shown_at = [None if dropped[i] else t[i] + float(r["MsUntilDisplayed"]) for i, r in enumerate(rows)]
    bins = collections.defaultdict(lambda: [0, 0])
    for i in range(max(1, a.skip), len(rows)):
        if shown_at[i - 1] is None:
            continue
        age = done[i] - shown_at[i - 1]
        bins[round(age * 20) / 20][dropped[i]] += 1
    print("screen age at completion, ms | shown | dropped")
    for k in sorted(bins):
        s, d = bins[k]
        if s + d >= 3:
            print(f"{k:6.2f} | {s:5d} | {d:5d}")


if __name__ == "__main__":
    main()
