"""Shared fixtures: the `patchnav` binary the package is cross-checked against, and a small
room written as an OBJ mesh by the tests themselves."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def cli_path() -> Path:
    """The command line program: `PATCHNAV_CLI`, else the workspace's debug build."""
    return Path(os.environ.get("PATCHNAV_CLI", REPO / "target" / "debug" / "patchnav"))


@pytest.fixture(scope="session")
def cli():
    """Runs `patchnav ARGS...` and returns its standard output; fails the test on an error."""
    path = cli_path()
    if not path.exists():
        pytest.fail(f"{path} is missing: run `cargo build -p patchnav` or set PATCHNAV_CLI")

    def run(*args) -> str:
        done = subprocess.run(
            [str(path), *map(str, args)], capture_output=True, text=True
        )
        assert done.returncode == 0, f"patchnav {' '.join(map(str, args))}:\n{done.stderr}"
        return done.stdout

    return run


def box(lo, hi):
    """The 8 corners and 12 triangles of an axis-aligned box."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = np.array(
        [[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)], dtype=float
    )
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    t = [tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))]
    return v, np.array(t, dtype=np.int64)


@pytest.fixture(scope="session")
def room():
    """A 6 x 4 m floor, a wall across it with a 1.2 m doorway, and a box: (vertices,
    triangles)."""
    parts = [
        box((0, 0, -0.1), (6, 4, 0)),  # floor slab
        box((3, 0, 0), (3.1, 1.4, 2)),  # wall, left of the doorway
        box((3, 2.6, 0), (3.1, 4, 2)),  # wall, right of the doorway
        box((1, 2.8, 0), (1.6, 3.4, 0.8)),  # a box
    ]
    vertices, triangles, base = [], [], 0
    for v, t in parts:
        vertices.append(v)
        triangles.append(t + base)
        base += len(v)
    return np.vstack(vertices), np.vstack(triangles)


@pytest.fixture(scope="session")
def room_obj(room, tmp_path_factory):
    """The room as an OBJ file."""
    vertices, triangles = room
    path = tmp_path_factory.mktemp("room") / "room.obj"
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in triangles]
    path.write_text("\n".join(lines) + "\n")
    return path


def random_steps(n, seed=0):
    """`n` steps of up to 2 m inside the room, starts and ends N x 3."""
    rng = np.random.default_rng(seed)
    starts = rng.uniform((0.2, 0.2, 0.2), (5.8, 3.8, 1.5), size=(n, 3))
    ends = starts + rng.uniform(-1, 1, size=(n, 3)) * (2, 2, 0.5)
    return starts, ends


def same_content(a, b):
    """Whether two maps hold the same patches and points (their bytes in memory differ
    between a loaded map and a built one: vector capacities)."""
    ca, cb = a.counts(), b.counts()
    del ca["memory_bytes"], cb["memory_bytes"]
    return ca == cb
