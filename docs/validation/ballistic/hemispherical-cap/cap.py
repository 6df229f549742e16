#!/usr/bin/env python3
"""The material on a hemispherical nose below its equator, from a run's snapshot.

    python3 cap.py RUN_DIR/particles_NNNNN.vtu RUN_DIR/history.csv TIME_S SPACING_M

Reads plugsim's VTU snapshot (raw appended binary, UInt64 headers) and the
projectile's tip position at TIME_S from history.csv (`projectile_y`, the
tip of `borvik-2002-12mm-hemispherical`, nose radius 10 mm, flight along
-y). Counts the particles within one spacing of the nose's hemisphere
below its equator ("on the nose"): their mass and the radii they span;
then groups them by reference radius r0 with their hoop stretch r/r0,
damage and plastic strain (particle values). Standard library only.
"""
import csv
import math
import re
import struct
import sys

RADIUS = 0.01  # the nose's radius, m


def read_vtu(path):
    b = open(path, "rb").read()
    head = b[: b.index(b"<AppendedData")]
    start = b.index(b"_", b.index(b"<AppendedData")) + 1
    fmt = {"Float64": "d", "Int32": "i", "UInt8": "B", "Int64": "q", "UInt32": "I", "UInt64": "Q"}
    arrays = {}
    pattern = rb'<DataArray type="(\w+)" Name="(\w+)" NumberOfComponents="(\d+)" format="appended" offset="(\d+)"'
    for m in re.finditer(pattern, head):
        kind, name, nc, off = m.group(1).decode(), m.group(2).decode(), int(m.group(3)), int(m.group(4))
        n = struct.unpack("<Q", b[start + off : start + off + 8])[0]
        f = fmt[kind]
        vals = struct.unpack("<%d%s" % (n // struct.calcsize(f), f), b[start + off + 8 : start + off + 8 + n])
        arrays[name] = [vals[i * nc : (i + 1) * nc] for i in range(len(vals) // nc)] if nc > 1 else list(vals)
    return arrays


def main(vtu, history, time, spacing):
    a = read_vtu(vtu)
    rows = list(csv.DictReader(open(history)))
    row = min(rows, key=lambda r: abs(float(r["time"]) - time))
    centre = float(row["projectile_y"]) + RADIUS
    on = []
    for i, (x, y, _) in enumerate(a["Points"]):
        if x >= 0 and y < centre and math.hypot(x, y - centre) - RADIUS < spacing:
            u = a["displacement"][i]
            on.append((x - u[0], y - u[1], x, a["mass"][i], a["damage"][i], a["plastic_strain"][i]))
    print("t = %.1f us, tip at %.2f mm" % (float(row["time"]) * 1e6, (centre - RADIUS) * 1e3))
    if not on:
        print("nothing on the nose below its equator")
        return
    print("on the nose: %d particles, %.3f g, r = %.2f-%.2f mm" % (
        len(on), sum(p[3] for p in on) * 1e3, min(p[2] for p in on) * 1e3, max(p[2] for p in on) * 1e3))
    groups = {}
    for p in on:
        groups.setdefault(round(p[0] * 1e3), []).append(p)
    for k in sorted(groups):
        g = groups[k]
        hoop = [p[2] / p[0] for p in g if p[0] > 1e-9]
        print("  r0 ~ %d mm: %d particles, %.3f g, y0 %.2f-%.2f mm, hoop r/r0 %s, D %.2f-%.2f, plastic strain %.2f-%.2f" % (
            k, len(g), sum(p[3] for p in g) * 1e3, min(p[1] for p in g) * 1e3, max(p[1] for p in g) * 1e3,
            "%.2f-%.2f" % (min(hoop), max(hoop)) if hoop else "-",
            min(p[4] for p in g), max(p[4] for p in g), min(p[5] for p in g), max(p[5] for p in g)))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]))
