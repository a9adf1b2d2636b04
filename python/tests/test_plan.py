"""Planning from Python equals planning with the command line for the same seed."""

import re

import numpy as np
import pytest

import patchnav

START = [0.6, 2.0, 0.5]
GOAL = [5.4, 2.0, 0.5]


def obj_polyline(path):
    return np.array(
        [[float(c) for c in line.split()[1:]] for line in path.read_text().splitlines() if line.startswith("v ")]
    ).reshape(-1, 3)


@pytest.mark.parametrize("planner", ["rrt", "prm", "rrt-connect", "evasion-rrt"])
@pytest.mark.parametrize("seed", [1, 7])
def test_python_plans_equal_the_cli_plans(cli, room, room_obj, tmp_path, planner, seed):
    map_file = tmp_path / "room.pmap"
    cli("map", "build", room_obj, "--backend", "bbox6d", "--out", map_file)
    path_file = tmp_path / "path.obj"
    text = cli(
        "plan", map_file, "--start", ",".join(map(str, START)), "--goal", ",".join(map(str, GOAL)),
        "--radius", 0.3, "--planner", planner, "--seed", seed, "--iterations", 3000,
        "--path-out", path_file,
    )
    world = patchnav.Map.load(map_file)
    path, stats = patchnav.plan(world, START, [GOAL], planner, 0.3, seed=seed, iterations=3000)
    assert stats["planner"] in text
    assert f"samples:          {stats['samples']}" in text
    assert f"vertices:         {stats['vertices']}" in text
    assert f"status:           {stats['status']}" in text
    if stats["reached"][0]:
        cli_path = obj_polyline(path_file)
        assert path.shape == cli_path.shape
        assert np.allclose(path, cli_path, atol=1e-12, rtol=0)
        assert re.search(rf"reached, path of {len(path)} vertices, {stats['lengths'][0]:.3f} m", text)
    else:
        assert "not reached" in text and path.shape == (0, 3)


def test_the_path_goes_through_the_doorway_and_is_free(room):
    world = patchnav.Map.from_mesh(*room)
    path, stats = patchnav.plan(
        world, START, GOAL, "rrt", 0.3, seed=2, iterations=5000, shortcut=True, roadmap=True
    )
    assert stats["reached"] == [True]
    assert np.allclose(path[0], START) and np.linalg.norm(path[-1] - GOAL) <= 0.5
    assert world.is_free(path[:-1], path[1:], 0.3).all()
    short = stats["shortcuts"][0]
    assert world.is_free(short[:-1], short[1:], 0.3).all()
    v, e = stats["roadmap_vertices"], stats["roadmap_edges"]
    assert v.shape[1] == 3 and e.shape == (stats["edges"], 2) and e.max() < len(v)


def test_the_same_seed_gives_the_same_path_on_any_thread(room):
    import concurrent.futures

    world = patchnav.Map.from_mesh(*room)
    first, _ = patchnav.plan(world, START, GOAL, "rrt", 0.3, seed=11)
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        runs = list(pool.map(lambda _: patchnav.plan(world, START, GOAL, "rrt", 0.3, seed=11)[0], range(4)))
    for path in runs:
        assert np.array_equal(path, first)


def test_the_cross_checked_runs_reach_the_goal(room):
    # The CLI comparison above compares whole paths only when the goal is reached.
    world = patchnav.Map.from_mesh(*room)
    for planner in ["rrt", "prm", "rrt-connect", "evasion-rrt"]:
        for seed in [1, 7]:
            _, stats = patchnav.plan(world, START, [GOAL], planner, 0.3, seed=seed, iterations=3000)
            assert stats["reached"] == [True], (planner, seed, stats["status"])
