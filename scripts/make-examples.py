#!/usr/bin/env python3
"""Writes the example scenes in examples/ (one per object type, plus combinations).

Run from the repository root: python3 scripts/make-examples.py
"""
import json, math

def dump(name, objects):
    with open(f"examples/{name}.json", "w") as f:
        f.write('{"objects": [\n')
        f.write(",\n".join("  " + json.dumps(o) for o in objects))
        f.write("\n]}\n")

def clamped(d, n, a=0.0, b=1.0):
    spans = n - d
    return [a] * (d + 1) + [a + (b - a) * i / spans for i in range(1, spans)] + [b] * (d + 1)

# Bézier curve: the lecture's example.
dump("bezier_curve", [{"name": "lecture", "type": "bezier_curve",
     "points": [[1, 1, 0], [1, 10, 0], [10, 10, 0], [10, 1, 0]], "samples": 200}])

# B-spline curve: the paper's example (degree 3, 10 points, knots 0,0,0,0,1,...,6,7,7,7,7).
pts = [[i, 2.5 * math.sin(i * 1.1), 0.4 * i] for i in range(10)]
dump("bspline_curve", [{"name": "paper", "type": "bspline_curve", "degree": 3,
     "knots": [0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7], "points": pts, "samples": 300}])

# NURBS circle: degree 2, nine points, weights 1 and sqrt(2)/2.
w = math.sqrt(0.5)
sq = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1), (1, 0)]
dump("nurbs_circle", [{"name": "circle", "type": "bspline_curve", "degree": 2,
     "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
     "points": [[2 * x, 2 * y, 0] for x, y in sq],
     "weights": [w if i % 2 else 1 for i in range(9)], "samples": 256, "color": [0.95, 0.8, 0.2]}])

# ERBS curve: four quadratic local curves on knots {0,0,1,2,3,3} (the paper's Figure 3 layout).
local = []
for l in range(4):
    x = 2.0 * l
    local.append({"points": [[x - 1.2, -0.4, 0], [x, 1.6 + 0.4 * (l % 2), 0], [x + 1.2, -0.2, 0]]})
dump("erbs_curve", [{"name": "erbs", "type": "erbs_curve", "knots": [0, 0, 1, 2, 3, 3],
     "local": local, "samples": 300}])

# Bézier surface: a bicubic patch.
net = [[[i, j, (1.5 if (i, j) in ((1, 1), (2, 2)) else 0) - 0.8 * ((i - 1.5) ** 2) * 0.2] for j in range(4)] for i in range(4)]
dump("bezier_surface", [{"name": "patch", "type": "bezier_surface", "points": net, "samples": [48, 48]}])

# B-spline surface: bicubic, 7x7 control points, clamped uniform, with a bump.
n = 7
net = [[[i - 3, j - 3, 0.5 * math.sin(0.9 * i) * math.cos(0.8 * j) + (1.4 if (i, j) == (3, 3) else 0)]
        for j in range(n)] for i in range(n)]
dump("bspline_surface", [{"name": "bumps", "type": "bspline_surface", "degree": [3, 3],
     "knots": [clamped(3, n), clamped(3, n)], "points": net, "samples": [64, 64], "color": [0.8, 0.55, 0.3]}])

# ERBS surface: 3x3 biquadratic local patches on knots {0,0,1,2,2} per direction.
patches = []
for k in range(3):
    row = []
    for l in range(3):
        cx, cy = 2.0 * k, 2.0 * l
        pts = [[[cx + 1.3 * (a - 1), cy + 1.3 * (b - 1), (2.2 + 1.2 * ((k + l) % 2)) if (a, b) == (1, 1) else 0.0]
                for b in range(3)] for a in range(3)]
        row.append({"points": pts})
    patches.append(row)
dump("erbs_surface", [{"name": "domes", "type": "erbs_surface", "knots": [[0, 0, 1, 2, 2], [0, 0, 1, 2, 2]],
     "local": patches, "samples": [60, 60]}])

# The benchmark surface of DESIGN.md's performance model: bicubic, clamped uniform, 100x100
# control points, 512x512 samples.
n = 100
net = [[[i / 10.0, j / 10.0, 0.4 * math.sin(0.3 * i) * math.cos(0.2 * j)] for j in range(n)] for i in range(n)]
dump("surface_100x100", [{"name": "surface", "type": "bspline_surface", "degree": [3, 3],
     "knots": [clamped(3, n), clamped(3, n)], "points": net, "samples": [512, 512]}])
