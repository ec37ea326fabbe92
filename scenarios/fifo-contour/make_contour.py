#!/usr/bin/env python3
"""Writes contour.csv: 6 s of a 3-axis contour on a 2 ms FIFO cycle (3001 rows).

The path is a figure in X/Y that climbs in Z, run along a smootherstep time law
(u = 6s^5 - 15s^4 + 10s^3), so the axes start and end at rest; it starts at the origin,
where the scenario's axes stand, and ends at (0, 0, 15).
"""
import math

T_F = 0.002
DURATION = 6.0
rows = int(round(DURATION / T_F)) + 1
with open("contour.csv", "w") as out:
    out.write("x,y,z\n")
    for k in range(rows):
        s = k / (rows - 1)
        u = 6 * s**5 - 15 * s**4 + 10 * s**3
        x = 50.0 * math.sin(2 * math.pi * u)
        y = 20.0 * (1 - math.cos(4 * math.pi * u))
        z = 15.0 * u
        out.write(f"{x:.6f},{y:.6f},{z:.6f}\n")
