"""Reading scans, extraction, terrain and ground from arrays, against the command line on the
same files (scans simulated by `patchnav simulate`)."""

import re

import numpy as np
import pytest

import patchnav
from conftest import random_steps, same_content


@pytest.fixture(scope="session")
def lab_scans(cli, tmp_path_factory):
    """Two coarse ALRF scans of the lab (organised, with their poses)."""
    out = tmp_path_factory.mktemp("lab")
    cli("simulate", "lab", "--sensor", "alrf", "--poses", 2, "--step-deg", 2, "--seed", 3, "--out", out)
    return [out / "scan000.ply", out / "scan001.ply"]


@pytest.fixture(scope="session")
def floor_frame(cli, tmp_path_factory):
    """A simulated range-camera frame of a flat floor."""
    out = tmp_path_factory.mktemp("floor")
    cli("simulate", "terrain-floor", "--sensor", "tof", "--poses", 1, "--out", out)
    return out / "scan000.ply"


def test_read_cloud_gives_points_attributes_shape_and_pose(lab_scans):
    cloud = patchnav.read_cloud(lab_scans[0])
    points, attributes, shape = cloud
    assert shape is not None and points.shape == (shape[0] * shape[1], 3)
    valid = np.isfinite(points).all(axis=1)
    assert 0 < valid.sum() < len(points)  # organised: pixels without a return are NaN
    assert cloud.organised().shape == (shape[0], shape[1], 3)
    assert cloud.pose.shape == (4, 4) and np.allclose(cloud.pose[3], [0, 0, 0, 1])
    for name, values in attributes.items():
        assert len(values) == len(points), name
    assert "Cloud(" in repr(cloud)
    world = cloud.world_points()[valid]
    expected = points[valid] @ cloud.pose[:3, :3].T + cloud.pose[:3, 3]
    assert np.allclose(world, expected)


@pytest.mark.parametrize("hybrid", [False, True])
def test_extraction_from_arrays_equals_the_cli(cli, lab_scans, tmp_path, hybrid):
    out = tmp_path / "lab.pmap"
    cli("extract", *lab_scans, "--out", out, *(["--hybrid"] if hybrid else []))
    from_cli = patchnav.Map.load(out)
    clouds = [patchnav.read_cloud(p) for p in lab_scans]
    ours = patchnav.extract(
        [c.organised() for c in clouds], "alrf", [c.pose for c in clouds], hybrid=hybrid
    )
    assert same_content(ours, from_cli)
    lo, hi = from_cli.bounds
    rng = np.random.default_rng(1)
    starts = rng.uniform(lo, hi, size=(1000, 3))
    ends = starts + rng.uniform(-1, 1, size=(1000, 3))
    assert (ours.is_free(starts, ends, 0.3) == from_cli.is_free(starts, ends, 0.3)).all()


def test_extraction_threads_do_not_change_the_map(lab_scans):
    clouds = [patchnav.read_cloud(p) for p in lab_scans]
    scans, poses = [c.organised() for c in clouds], [c.pose for c in clouds]
    one = patchnav.extract(scans, "alrf", poses, threads=1)
    two = patchnav.extract(scans, "alrf", poses, threads=2)
    starts, ends = random_steps(500)
    assert one.counts() == two.counts()  # both in memory: the same bytes too
    assert (one.is_free(starts, ends, 0.3) == two.is_free(starts, ends, 0.3)).all()


def test_an_unorganised_scan_extracts_too(lab_scans):
    cloud = patchnav.read_cloud(lab_scans[0])
    points = cloud.points[np.isfinite(cloud.points).all(axis=1)]
    world = patchnav.extract(points, "alrf", cloud.pose)
    assert world.counts()["planar_patches"] > 5


def test_terrain_from_arrays_equals_the_cli(cli, floor_frame):
    text = cli("terrain", floor_frame, "--resolution", 45)
    cloud = patchnav.read_cloud(floor_frame)
    result = patchnav.classify_terrain(cloud.organised(), resolution=45)
    assert re.search(rf"class:\s+{result['class']}\b", text)
    assert result["class"] == "floor" and result["drivable"]
    assert result["axes"] == "camera" and result["mount_estimated"]
    assert abs(result["mount"][0] - 0.5) < 0.02
    thesis = patchnav.classify_terrain(cloud.organised(), resolution=45, method="thesis", sectors=3)
    assert len(thesis["sectors"]) == 3


def test_ground_points_label_a_floor_and_not_a_box():
    rng = np.random.default_rng(0)
    # A lidar 1 m above a floor, with the front face of a 0.6 m box 4 m ahead.
    floor = np.column_stack([rng.uniform(1, 12, 20000), rng.uniform(-6, 6, 20000), np.full(20000, -1.0)])
    face = np.column_stack([np.full(2000, 4.0), rng.uniform(-0.5, 0.5, 2000), rng.uniform(-1, -0.4, 2000)])
    points = np.vstack([floor, face])
    labels = patchnav.ground_points(points, axes="lidar", mount=(1.0, 0.0, 0.0))
    assert labels.shape == (len(points),) and labels.dtype == np.bool_
    assert labels[: len(floor)].mean() > 0.95
    # The band of a wide far cell reaches up the face's foot (0.28 m here); above it, none.
    high = face[:, 2] > -0.6
    assert not labels[len(floor):][high].any()
    strict = patchnav.ground_points(points, axes="lidar", mount=(1.0, 0.0, 0.0), settings={"max_step": 0.05})
    assert strict.shape == labels.shape


def test_ground_points_of_an_organised_frame_are_an_image(floor_frame):
    cloud = patchnav.read_cloud(floor_frame)
    labels = patchnav.ground_points(cloud.organised())
    assert labels.shape == cloud.shape
    valid = np.isfinite(cloud.organised()).all(axis=2)
    assert not labels[~valid].any() and labels[valid].mean() > 0.9


def sr3000_meta():
    return {
        "width": 176,
        "height": 144,
        "range_kind": "depth",
        "metres_per_unit": 0.001,
        "camera": "sr3000",
    }


def test_tof_filter_of_a_frame_in_memory():
    meta = sr3000_meta()
    try:
        depth = np.full((144, 176), 2.0)
        amplitude = np.full((144, 176), 3000.0)
        amplitude[60:80, 80:100] = 10.0  # dark: the AAT drops or unwraps them
        out = patchnav.tof_filter(depth, amplitude, meta, method="aat")
    except patchnav.InvalidInputError as e:
        pytest.fail(f"the sidecar layout changed: {e}")
    assert out["range"].shape == (144, 176) and out["outcome"].shape == (144, 176)
    assert out["points"].shape == (144, 176, 3)
    assert out["kept"] + out["unwrapped"] + out["dropped"] == 144 * 176
    dark = np.zeros((144, 176), bool)
    dark[60:80, 80:100] = True
    assert (out["outcome"][~dark] == 0).all()
    assert (out["outcome"][dark] != 0).all()
    regions = patchnav.tof_filter(depth, amplitude, meta)
    assert regions["method"].startswith("regions")
