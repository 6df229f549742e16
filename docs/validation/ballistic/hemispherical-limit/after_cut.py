#!/usr/bin/env python3
"""The projectile's speed when the first piece is cut out, and what it loses after.

    python3 after_cut.py RUN_DIR/history.csv [RUN_DIR/history.csv ...]

For each run of `plugsim ballistic` (rigid projectile named `projectile`):
the time the cracks first cut a piece out (`perforation_time`), the
projectile's speed along its flight then (the first history row at or
after it), the last row whose axial contact force (`projectile_f_axial`)
is above 0.1 % of its peak (the release, as the residual's definition
reads it), the residual (the last row's speed) and the speed lost
between the cut and the end. Standard library only.
"""
import csv
import sys


def after_cut(path):
    rows = list(csv.DictReader(open(path)))
    t = [float(r["time"]) for r in rows]
    v = [-float(r["projectile_vy"]) for r in rows]
    force = [float(r["projectile_f_axial"]) for r in rows]
    cut = next((float(r["perforation_time"]) for r in rows if float(r["perforation_time"]) > 0.0), None)
    if cut is None:
        return None
    k = next(i for i, x in enumerate(t) if x >= cut)
    peak = max(abs(f) for f in force)
    release = max(i for i, f in enumerate(force) if abs(f) > 1e-3 * peak)
    return cut, v[k], t[release], v[-1]


print("| run | first cut (us) | v then (m/s) | release (us) | v_r (m/s) | lost after the cut (m/s) |")
print("|---|---|---|---|---|---|")
for path in sys.argv[1:]:
    r = after_cut(path)
    if r is None:
        print(f"| {path} | no piece cut | | | | |")
        continue
    cut, v_cut, release, v_r = r
    print(f"| {path} | {cut * 1e6:.1f} | {v_cut:.1f} | {release * 1e6:.1f} | {v_r:.2f} | {v_cut - v_r:.1f} |")
