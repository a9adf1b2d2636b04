"""Maps from meshes and files, and the vectorised collision test, against the command line."""

import numpy as np
import pytest

import patchnav
from conftest import random_steps, same_content


@pytest.mark.parametrize("backend", ["polygon", "bbox6d", "trimesh", "rapier"])
def test_a_map_from_the_cli_and_from_arrays_answer_alike(cli, room, room_obj, tmp_path, backend):
    out = tmp_path / f"room-{backend}.pmap"
    cli("map", "build", room_obj, "--backend", backend, "--out", out)
    from_file = patchnav.Map.load(out)
    from_arrays = patchnav.Map.from_mesh(*room, backend=backend)
    assert from_file.backend == from_arrays.backend == backend
    assert same_content(from_file, from_arrays)
    starts, ends = random_steps(2000)
    a = from_file.is_free(starts, ends, 0.3)
    b = from_arrays.is_free(starts, ends, 0.3)
    assert a.dtype == np.bool_ and a.shape == (2000,)
    assert (a == b).all()
    assert 0 < a.sum() < len(a)  # the room has free and blocked steps


def test_is_free_knows_the_room(room):
    world = patchnav.Map.from_mesh(*room)
    free = world.is_free(
        [[0.5, 2.0, 0.5], [2.0, 2.0, 0.5], [0.5, 0.5, 0.5], [0.5, 0.5, 0.25]],
        [[5.5, 2.0, 0.5], [4.0, 0.5, 0.5], [0.5, 0.5, 1.5], [0.5, 0.5, 0.25]],
        radius=0.3,
    )
    # Through the doorway; into the wall; straight up; touching the floor.
    assert free.tolist() == [True, False, True, False]


def test_save_and_load_keep_the_answers(room, tmp_path):
    world = patchnav.Map.from_mesh(*room, backend="trimesh")
    path = tmp_path / "room.pmap"
    size = world.save(path)
    assert size == path.stat().st_size > 0
    again = patchnav.Map.load(str(path))
    starts, ends = random_steps(500, seed=3)
    assert (world.is_free(starts, ends, 0.25) == again.is_free(starts, ends, 0.25)).all()


def test_any_array_layout_gives_the_same_answers(room):
    world = patchnav.Map.from_mesh(*room)
    starts, ends = random_steps(300, seed=5)
    expected = world.is_free(starts, ends, 0.3)
    # Fortran order, strided views, float32 and plain lists.
    wide = np.zeros((300, 6))
    wide[:, ::2] = starts
    assert (world.is_free(np.asfortranarray(starts), ends, 0.3) == expected).all()
    assert (world.is_free(wide[:, ::2], ends, 0.3) == expected).all()
    as32 = world.is_free(starts.astype(np.float32), ends.astype(np.float32), 0.3)
    assert as32.shape == expected.shape
    assert (world.is_free(starts.tolist(), ends.tolist(), 0.3) == expected).all()
    # One step as two points.
    assert world.is_free(starts[0], ends[0], 0.3).tolist() == [expected[0]]


def test_a_pointcloud_map_needs_a_spacing(room):
    with pytest.raises(patchnav.MapError, match="spacing"):
        patchnav.Map.from_mesh(*room, backend="pointcloud")
    world = patchnav.Map.from_mesh(*room, backend="pointcloud", spacing=0.1)
    assert world.counts()["points"] > 1000


def test_map_properties(room):
    world = patchnav.Map.from_mesh(*room)
    lo, hi = world.bounds
    assert np.allclose(lo, [0, 0, -0.1]) and np.allclose(hi, [6, 4, 2])
    assert "bbox6d" in repr(world)
    assert set(patchnav.names("backend")) >= {"polygon", "bbox6d", "trimesh", "rapier", "pointcloud"}
