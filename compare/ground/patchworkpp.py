#!/usr/bin/env python3
"""Patchwork++ (PyPI `pypatchworkpp`) ground segmentation of one KITTI-style .bin scan.

Usage: patchworkpp.py SCAN.bin LABELS_OUT [--sensor-height H] [--repeat N]

Reads the scan (little-endian float32 x, y, z, remission per point), runs Patchwork++ with its
default parameters (only the sensor height set), `repeat` times on the same scan, and writes one
byte per input point to LABELS_OUT (1 = ground, 0 = not), in the scan's order. Prints one JSON
line: points, ground count, the first call's time and the best and median of the others (ms,
wall clock around `estimateGround`, which runs on one core).
"""

import argparse
import importlib.metadata
import json
import statistics
import sys
import time

import numpy as np
import pypatchworkpp


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("scan")
    ap.add_argument("labels_out")
    ap.add_argument("--sensor-height", type=float, default=1.73)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()

    cloud = np.fromfile(a.scan, dtype="<f4").reshape(-1, 4).astype(np.float64)
    params = pypatchworkpp.Parameters()
    params.sensor_height = a.sensor_height
    params.verbose = False
    pw = pypatchworkpp.patchworkpp(params)

    times = []
    ground = None
    for _ in range(1 + a.repeat):
        t = time.perf_counter()
        pw.estimateGround(cloud)
        times.append((time.perf_counter() - t) * 1e3)
        ground = pw.getGroundIndices()
    labels = np.zeros(len(cloud), dtype=np.uint8)
    labels[np.asarray(ground, dtype=np.int64)] = 1
    labels.tofile(a.labels_out)
    rest = times[1:]
    print(json.dumps({
        "tool": "patchworkpp",
        "package": importlib.metadata.version("pypatchworkpp"),
        "points": int(len(cloud)),
        "ground": int(labels.sum()),
        "sensor_height_m": a.sensor_height,
        "first_ms": times[0],
        "best_ms": min(rest),
        "median_ms": statistics.median(rest),
        "repeat": a.repeat,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
