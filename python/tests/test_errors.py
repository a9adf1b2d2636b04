"""Bad input gives typed exceptions with clear messages, never a crash."""

import numpy as np
import pytest

import patchnav
from patchnav.errors import InvalidInputError, PatchnavError, ReadError


@pytest.fixture(scope="module")
def world(room):
    return patchnav.Map.from_mesh(*room)


def test_the_exception_classes():
    assert issubclass(InvalidInputError, ValueError) and issubclass(InvalidInputError, PatchnavError)
    assert issubclass(ReadError, OSError) and issubclass(ReadError, PatchnavError)


@pytest.mark.parametrize(
    "starts, ends, message",
    [
        (np.zeros((3, 2)), np.zeros((3, 3)), "N × 3"),
        (np.zeros((3, 3)), np.zeros((4, 3)), "one end per start"),
        (np.zeros((2, 3, 3)), np.zeros((2, 3)), "N × 3"),
        ([[0, 0, np.nan]], [[1, 1, 1]], "row 0 is not finite"),
        ([[0, 0, np.inf]], [[1, 1, 1]], "not finite"),
        ([["a", "b", "c"]], [[1, 1, 1]], "not an array of numbers"),
        (None, [[1, 1, 1]], "N × 3"),
        (np.zeros((0, 3)), np.zeros((1, 3)), "one end per start"),
    ],
)
def test_bad_steps(world, starts, ends, message):
    with pytest.raises(InvalidInputError, match=message):
        world.is_free(starts, ends, 0.3)


@pytest.mark.parametrize("radius", [0.0, -1.0, float("nan"), float("inf")])
def test_absurd_radius(world, radius):
    with pytest.raises(InvalidInputError, match="radius"):
        world.is_free([[0, 0, 0]], [[1, 1, 1]], radius)


def test_no_steps_is_no_answers(world):
    assert world.is_free(np.zeros((0, 3)), np.zeros((0, 3)), 0.3).shape == (0,)


def test_bad_meshes(room):
    vertices, triangles = room
    with pytest.raises(InvalidInputError, match="row 0 names vertex"):
        patchnav.Map.from_mesh(vertices, [[0, 1, len(vertices)]])
    with pytest.raises(InvalidInputError, match="whole numbers"):
        patchnav.Map.from_mesh(vertices, [[0, 1, 2.5]])
    with pytest.raises(InvalidInputError, match="M × 3"):
        patchnav.Map.from_mesh(vertices, triangles[:, :2])
    with pytest.raises(InvalidInputError, match="unknown backend"):
        patchnav.Map.from_mesh(vertices, triangles, backend="octree")


def test_damaged_and_missing_files(room, tmp_path):
    path = tmp_path / "room.pmap"
    patchnav.Map.from_mesh(*room).save(path)
    data = path.read_bytes()
    (tmp_path / "cut.pmap").write_bytes(data[: len(data) // 2])
    with pytest.raises(ReadError):
        patchnav.Map.load(tmp_path / "cut.pmap")
    flipped = bytearray(data)
    flipped[len(data) // 2] ^= 0xFF
    (tmp_path / "flipped.pmap").write_bytes(bytes(flipped))
    with pytest.raises(PatchnavError):
        patchnav.Map.load(tmp_path / "flipped.pmap")
    with pytest.raises(ReadError, match="No such file"):
        patchnav.Map.load(tmp_path / "missing.pmap")
    (tmp_path / "junk.ply").write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n")
    with pytest.raises(ReadError):
        patchnav.read_cloud(tmp_path / "junk.ply")


def test_bad_plans(world):
    with pytest.raises(InvalidInputError, match="unknown planner"):
        patchnav.plan(world, [0, 0, 0], [1, 1, 1], "astar", 0.3)
    with pytest.raises(InvalidInputError, match="start"):
        patchnav.plan(world, [0, 0], [1, 1, 1], "rrt", 0.3)
    with pytest.raises(InvalidInputError, match="not finite"):
        patchnav.plan(world, [0, 0, np.nan], [1, 1, 1], "rrt", 0.3)
    with pytest.raises(patchnav.PlanError, match="radius"):
        patchnav.plan(world, [1, 1, 1], [2, 2, 1], "rrt", -0.3)
    with pytest.raises(patchnav.PlanError, match="goal"):
        patchnav.plan(world, [1, 1, 1], np.zeros((0, 3)), "rrt", 0.3)


def test_bad_scans():
    with pytest.raises(InvalidInputError, match="empty"):
        patchnav.extract([])
    with pytest.raises(InvalidInputError, match="N × 3 points or an organised"):
        patchnav.extract(np.zeros((10, 4)))
    with pytest.raises(InvalidInputError, match="row 1 is not finite"):
        patchnav.extract(np.array([[0, 0, 1], [np.nan, 0, 1.0]]))
    with pytest.raises(InvalidInputError, match="rigid"):
        patchnav.extract(np.ones((10, 3)), pose=np.ones((4, 4)))
    with pytest.raises(InvalidInputError, match="4 × 4"):
        patchnav.extract(np.ones((10, 3)), pose=np.eye(3))
    with pytest.raises(InvalidInputError, match="2 poses for 1 scans"):
        patchnav.extract([np.ones((10, 3))], pose=[np.eye(4), np.eye(4)])
    with pytest.raises(InvalidInputError, match="unknown sensor preset"):
        patchnav.extract(np.ones((10, 3)), "lidar")
    with pytest.raises(InvalidInputError, match="hybrid"):
        patchnav.extract(np.ones((10, 3)), carve=True)
    with pytest.raises(InvalidInputError, match="threads"):
        patchnav.extract(np.ones((10, 3)), threads=0)


def test_an_organised_scan_with_no_measurement_is_no_map():
    empty = np.full((20, 30, 3), np.nan)
    world = patchnav.extract(empty)
    assert world.counts()["planar_patches"] == 0


def test_bad_terrain_input():
    with pytest.raises(patchnav.TerrainError, match="no points"):
        patchnav.classify_terrain(np.zeros((0, 3)))
    with pytest.raises(patchnav.PatchnavError, match="resolution"):
        patchnav.classify_terrain(np.ones((10, 3)), resolution=0)
    with pytest.raises(InvalidInputError, match="unknown axes"):
        patchnav.classify_terrain(np.ones((10, 3)), axes="up")
    with pytest.raises(InvalidInputError, match="unknown key"):
        patchnav.ground_points(np.ones((10, 3)), settings={"max_stpe": 0.1})
    with pytest.raises(InvalidInputError, match="whole number"):
        patchnav.ground_points(np.ones((10, 3)), settings={"min_points": 2.5})


def test_bad_tof_input():
    meta = {"width": 176, "height": 144, "range_kind": "depth", "metres_per_unit": 0.001, "camera": "sr3000"}
    good = np.ones((144, 176))
    with pytest.raises(InvalidInputError, match="144 × 176"):
        patchnav.tof_filter(np.ones((10, 10)), good, meta)
    bad = good.copy()
    bad[3, 4] = np.nan
    with pytest.raises(InvalidInputError, match="range"):
        patchnav.tof_filter(bad, good, meta)
    with pytest.raises(InvalidInputError, match="meta"):
        patchnav.tof_filter(good, good, {"width": -1})
    with pytest.raises(InvalidInputError, match="meta"):
        patchnav.tof_filter(good, good, 42)
    with pytest.raises(ReadError):
        patchnav.tof_filter(good, good, "/nonexistent/meta.json")
    with pytest.raises(InvalidInputError, match="two-freq"):
        patchnav.tof_filter(good, good, meta, method="two-freq")
