"""From one laser scan to a planned path, notebook style.

Reads a scan (the repository's simulated lab scan unless a path is given), extracts a hybrid
map of planar and triangle-mesh patches, checks a few robot steps, plans with RRT from the
sensor's position to the free spot farthest from it, and draws the top view with matplotlib
when it is installed (written to scan_to_plan.png, or the path of --plot).

    python python/examples/scan_to_plan.py [SCAN] [--plot OUT.png]
"""

import argparse
import sys
from pathlib import Path

import numpy as np

import patchnav

HERE = Path(__file__).resolve().parent
RADIUS = 0.3  # the robot, a sphere of 30 cm
HEIGHT = 0.5  # its centre above the floor

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("scan", nargs="?", default=HERE.parents[1] / "fixtures" / "lab-alrf-2deg.ply")
parser.add_argument("--plot", default="scan_to_plan.png")
args = parser.parse_args()

# 1. Read the scan: points (organised scans have NaN where a beam saw nothing) and the pose.
cloud = patchnav.read_cloud(args.scan)
measured = np.isfinite(cloud.points).all(axis=1)
print(f"{args.scan}: {measured.sum()} points, organised {cloud.shape}, pose {'yes' if cloud.pose is not None else 'no'}")

# 2. Extract the map: planar patches, plus trimesh patches where no plane fits.
world = patchnav.extract(cloud.organised(), "alrf", cloud.pose, hybrid=True)
print(world, world.counts())

# 3. Where can the robot stand? Test a grid of places at its height (a step of length 0).
lo, hi = world.bounds
floor = lo[2] + 0.05 if cloud.pose is None else cloud.pose[2, 3] - 0.6
xs, ys = np.meshgrid(np.arange(lo[0], hi[0], 0.25), np.arange(lo[1], hi[1], 0.25))
places = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, floor + HEIGHT)])
free = world.is_free(places, places, RADIUS)
print(f"{free.sum()} of {len(places)} places on a 25 cm grid are free")

# 4. Plan from the sensor's position to the free place farthest from it.
start = places[0] if cloud.pose is None else np.array([*cloud.pose[:2, 3], floor + HEIGHT])
candidates = places[free]
goal = candidates[np.argmax(np.linalg.norm(candidates - start, axis=1))]
path, stats = patchnav.plan(world, start, goal, "rrt", RADIUS, seed=1, iterations=20_000, shortcut=True)
print(f"rrt: {stats['status']}, {stats['vertices']} vertices, {stats['collision_checks']} collision checks")
if stats["reached"][0]:
    short = stats["shortcuts"][0]
    print(f"path: {len(path)} vertices, {stats['lengths'][0]:.2f} m; shortcut: {len(short)} vertices")
    assert world.is_free(short[:-1], short[1:], RADIUS).all()

# 5. Plot the top view, if matplotlib is there.
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no plot")
    sys.exit(0)
fig, ax = plt.subplots(figsize=(8, 6))
p = cloud.world_points()[measured]
ax.scatter(p[:, 0], p[:, 1], s=0.2, c=p[:, 2], cmap="viridis", label="scan")
ax.scatter(*places[~free, :2].T, s=4, c="tab:red", marker="s", alpha=0.3, label="blocked")
if len(path):
    ax.plot(path[:, 0], path[:, 1], "k-", lw=1, label="rrt path")
    ax.plot(short[:, 0], short[:, 1], "b-", lw=2, label="shortcut")
ax.plot(*start[:2], "go", label="start")
ax.plot(*goal[:2], "r*", ms=12, label="goal")
ax.set_aspect("equal")
ax.legend(loc="best", fontsize="small")
fig.savefig(args.plot, dpi=120)
print(f"wrote {args.plot}")
