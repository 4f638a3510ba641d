#!/usr/bin/env python3
"""Projects the SoRoMoX tentacle's 3-D captures (tests/data/soromox/) into
each tendon's bending plane: planar readings and markers for the planar
`calibrate` / `diagnose` (one routing: the tendon's radial offset).

Tendon k sits at angle phi_k about the clamp axis (30 deg, 150 deg); its
bending plane holds the axis and the direction (cos phi_k, sin phi_k) in
the clamp's y-z plane, so a clamp-frame point (x, y, z) projects to
(x, y cos phi_k + z sin phi_k). A stalk offset (0, oy, oz) projects the
same way (exact for a bend in the plane). The data have no tip angle and
the tip marker p4 sits 8 mm beyond the tip (s = 368 mm), so the tip angle
is the chord's from p3's centreline point to p4 (p3's offset taken off
along the chord's normal, two passes; unwrapped past pi) with a 10 deg noise, and the tip is
p4 moved 8 mm back along it. p1..p3 become planar markers.

Usage: scripts/soromox-planar.py [SOROMOX_DIR] [OUT_DIR]
(defaults: tests/data/soromox and tests/data/soromox/planar).
"""
import csv
import math
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "tests", "data", "soromox")
out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(src, "planar")
os.makedirs(out, exist_ok=True)

PHI_DEG = {1: 30.0, 2: 150.0}
ANCHOR_MM = 305.0
# The tendons' radial offset d(s) = 11.4 mm - 0.0295 s (actuator.toml), at
# the control points s_i = i * 305 / 4.
ROUTING = [11.4 - 0.0295 * i * ANCHOR_MM / 4 for i in range(5)]
TIP_BEYOND_MM = 8.0
ANGLE_NOISE_DEG = 10.0

with open(os.path.join(src, "captures.csv")) as f:
    captures = list(csv.DictReader(f))
with open(os.path.join(src, "markers.csv")) as f:
    markers = list(csv.DictReader(f))

readings, planar_markers = [], []
for step, c in enumerate(captures, start=1):
    m = c["measurement"]
    t1, t2 = float(c["tension_1_n"]), float(c["tension_2_n"])
    if (t1 > 0) == (t2 > 0):
        sys.exit(f"capture {m}: exactly one tendon must pull for a planar projection")
    k = 1 if t1 > 0 else 2
    phi = math.radians(PHI_DEG[k])
    cos_p, sin_p = math.cos(phi), math.sin(phi)
    pts = {}
    for row in markers:
        if row["measurement"] != m:
            continue
        lateral = float(row["y_mm"]) * cos_p + float(row["z_mm"]) * sin_p
        offset = float(row["offset_y_mm"]) * cos_p + float(row["offset_z_mm"]) * sin_p
        pts[row["marker"]] = (float(row["s_mm"]), offset, float(row["x_mm"]), lateral)
    _, off3, x3, y3 = pts["p3"]
    _, _, x4, y4 = pts["p4"]
    theta = math.atan2(y4 - y3, x4 - x3)
    for _ in range(2):
        cx, cy = x3 + off3 * math.sin(theta), y3 - off3 * math.cos(theta)
        theta = math.atan2(y4 - cy, x4 - cx)
    # The tip curls past the horizontal at the highest tensions: angles grow
    # from 0 toward +y, so unwrap atan2's (-pi, -pi/2) to (pi, 3pi/2).
    if theta < -math.pi / 2:
        theta += 2 * math.pi
    tip_x, tip_y = x4 - TIP_BEYOND_MM * math.cos(theta), y4 - TIP_BEYOND_MM * math.sin(theta)
    readings.append({
        "measurement": m, "routing": "tendon", **{f"y{i}_mm": f"{y:.6f}" for i, y in enumerate(ROUTING)},
        "tension_n": f"{max(t1, t2):.6f}", "direction": "static", "step": step, "dwell_s": c["dwell_s"],
        "tip_x_mm": f"{tip_x:.3f}", "tip_y_mm": f"{tip_y:.3f}", "tip_angle_rad": f"{theta:.5f}",
        "noise_deg": ANGLE_NOISE_DEG, "tendon": k,
    })
    for name in ("p1", "p2", "p3"):
        s, offset, x, y = pts[name]
        planar_markers.append({"measurement": m, "s_mm": s, "offset_mm": f"{offset:.3f}", "x_mm": f"{x:.3f}", "y_mm": f"{y:.3f}"})

header = [
    "# # Planar projection of tests/data/soromox (SoRoMoX, MIT) by scripts/soromox-planar.py: each capture",
    "# # in its tendon's bending plane; the tapered body, anchor and nominal materials of actuator.toml.",
    "# length_mm = 360.0",
    "# radius_mm = 15.41",
    "# radius_profile_mm = [[0.0, 15.41], [305.0, 6.42], [360.0, 4.8]]",
    f"# cable_anchor_mm = {ANCHOR_MM}",
    "# density_g_cm3 = 1.5",
    "# ei_n_mm2 = 22366.18",
    "# ea_n = 376.7442",
    "# ga_n = 129.9118",
]
with open(os.path.join(out, "readings.csv"), "w", newline="") as f:
    f.write("\n".join(header) + "\n")
    w = csv.DictWriter(f, fieldnames=list(readings[0]), lineterminator="\n")
    w.writeheader()
    w.writerows(readings)
with open(os.path.join(out, "markers.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(planar_markers[0]), lineterminator="\n")
    w.writeheader()
    w.writerows(planar_markers)
print(f"{len(readings)} readings, {len(planar_markers)} markers -> {out}")
