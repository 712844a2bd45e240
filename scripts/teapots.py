#!/usr/bin/env python3
"""Writes the Utah teapots benchmark scene: an N x N grid (8 x 8 by default) of copies of
examples/teapot.json (32 bicubic Bezier patches each, 17 x 17 samples), 4 units apart, copy k
at (k mod N, k div N) * 4 in x and y, its objects named t{k}_{name}. N = 8 gives 2048 patches
and about a million triangles at full resolution; N = 64, 131,072 patches.

    python3 scripts/teapots.py 8 teapots64.json     # well under a second
    prespline bench teapots64.json --scenario drag --frames 120 --warmup 20

Runs from any directory; needs only Python 3 (no build).
"""
import json
import os
import sys

SPACING = 4.0


def main(argv):
    if len(argv) > 2:
        sys.exit("error: usage: teapots.py [N (1..=64, default 8)] [OUT.json]")
    try:
        n = int(argv[0]) if argv else 8
    except ValueError:
        n = 0
    if not 1 <= n <= 64:
        sys.exit(f"error: N must be a whole number in 1..=64, got {argv[0]!r}")
    out = argv[1] if len(argv) > 1 else f"teapots{n * n}.json"
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "..", "examples", "teapot.json")) as f:
        one = json.load(f)["objects"]
    objects = []
    for k in range(n * n):
        dx, dy = (k % n) * SPACING, (k // n) * SPACING
        for o in one:
            copy = dict(o)
            copy["name"] = f"t{k}_{o['name']}"
            copy["points"] = [[[p[0] + dx, p[1] + dy, p[2]] for p in row] for row in o["points"]]
            objects.append(copy)
    try:
        with open(out, "w") as f:
            f.write('{"objects": [\n')
            f.write(",\n".join("  " + json.dumps(o) for o in objects))
            f.write("\n]}\n")
    except OSError as e:
        sys.exit(f"error: cannot write {out}: {e.strerror}")
    print(f"wrote {out} ({n * n} teapots, {len(objects)} patches)", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1:])
