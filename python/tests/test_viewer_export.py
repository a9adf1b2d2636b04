"""`patchnav map export --mcap` and `patchnav plan --mcap` decoded by the official MCAP
reader with its ROS 2 decoder, as a robot viewer (Foxglove, RViz through `ros2 bag play`)
reads them.

Needs the PyPI packages `mcap`, `mcap-ros2-support` and `pytest`, and the CLI built
(`cargo build -p patchnav`); `PATCHNAV_CLI` names the binary, else
`<repo>/target/debug/patchnav` is used:

    python3 -m venv /tmp/viz-venv
    /tmp/viz-venv/bin/pip install mcap mcap-ros2-support pytest
    PATCHNAV_CLI=target/debug/patchnav /tmp/viz-venv/bin/pytest python/tests/test_viewer_export.py
"""

import os
import pathlib
import subprocess
from collections import Counter

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

REPO = pathlib.Path(__file__).resolve().parents[2]

MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"
POINT_CLOUD2 = "sensor_msgs/msg/PointCloud2"
LINE_STRIP, LINE_LIST, TRIANGLE_LIST = 4, 5, 11
# The colour of each namespace (patch_pipeline::viewer's constants).
COLOURS = {
    "planar": (0.40, 0.65, 0.90, 1.0),
    "trimesh": (0.95, 0.60, 0.20, 1.0),
    "roadmap": (0.55, 0.55, 0.55, 0.8),
    "path": (0.10, 0.80, 0.25, 1.0),
}

# A 10 × 10 m floor and a 2 × 2 × 1 m box on it (no bottom): six planar quads, 12 triangles.
OBJ = """\
v 0 0 0
v 10 0 0
v 10 10 0
v 0 10 0
v 4 4 0
v 6 4 0
v 6 6 0
v 4 6 0
v 4 4 1
v 6 4 1
v 6 6 1
v 4 6 1
f 1 2 3 4
f 9 10 11 12
f 5 6 10 9
f 6 7 11 10
f 7 8 12 11
f 8 5 9 12
"""
TRIANGLES = 12


def cli():
    path = pathlib.Path(os.environ.get("PATCHNAV_CLI") or REPO / "target" / "debug" / "patchnav")
    if not path.is_file():
        pytest.fail(f"no patchnav binary at {path}: run `cargo build -p patchnav` or set PATCHNAV_CLI")
    return path


def run(*args):
    done = subprocess.run([str(cli()), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, f"patchnav {' '.join(map(str, args))}:\n{done.stdout}{done.stderr}"
    return done.stdout + done.stderr


def decode(path):
    """Every message of the file: (topic, schema name, decoded message)."""
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        return [
            (channel.topic, schema.name, msg)
            for schema, channel, _, msg in reader.iter_decoded_messages()
        ]


def check_markers(msg, frame_id):
    for m in msg.markers:
        assert m.header.frame_id == frame_id
        expected = COLOURS[m.ns]
        assert (m.color.r, m.color.g, m.color.b, m.color.a) == pytest.approx(expected, abs=1e-6), m.ns
        if m.type == TRIANGLE_LIST:
            assert len(m.points) % 3 == 0 and m.points, m.ns
        if m.type == LINE_LIST:
            assert len(m.points) % 2 == 0 and m.points, m.ns
        if m.type == LINE_STRIP:
            assert len(m.points) >= 2, m.ns


@pytest.fixture()
def map_file(tmp_path):
    obj = tmp_path / "room.obj"
    obj.write_text(OBJ)
    out = tmp_path / "room.pmap"
    run("map", "build", obj, "--backend", "polygon", "--out", out)
    return out


def test_map_export_decodes_with_the_official_reader(tmp_path, map_file):
    cloud = tmp_path / "cloud.xyz"
    cloud.write_text("".join(f"{x} {y} 0.5\n" for x in range(3) for y in range(4)))
    out = tmp_path / "map.mcap"
    printed = run("map", "export", map_file, "--mcap", out, "--cloud", cloud, "--frame-id", "odom")
    assert "/patchnav/map 1 MarkerArray" in printed

    messages = decode(out)
    assert Counter(t for t, _, _ in messages) == {"/patchnav/map": 1, "/patchnav/cloud": 1}
    schemas = {t: s for t, s, _ in messages}
    assert schemas == {"/patchnav/map": MARKER_ARRAY, "/patchnav/cloud": POINT_CLOUD2}
    msgs = {t: m for t, _, m in messages}

    markers = msgs["/patchnav/map"]
    check_markers(markers, "odom")
    assert [(m.ns, m.type) for m in markers.markers] == [("planar", TRIANGLE_LIST)]
    assert sum(len(m.points) for m in markers.markers) == 3 * TRIANGLES
    zs = {round(p.z, 9) for m in markers.markers for p in m.points}
    assert zs == {0.0, 1.0}

    pc = msgs["/patchnav/cloud"]
    assert pc.header.frame_id == "odom"
    assert pc.width * pc.height == 12
    assert [f.name for f in pc.fields][:3] == ["x", "y", "z"]
    assert len(pc.data) == pc.row_step * pc.height


def test_plan_writes_map_roadmap_and_path(tmp_path, map_file):
    out = tmp_path / "plan.mcap"
    run(
        "plan", map_file, "--start", "1,1,0.5", "--goal", "9,9,0.5", "--radius", "0.2",
        "--planner", "rrt", "--seed", "1", "--mcap", out,
    )
    messages = decode(out)
    assert Counter(t for t, _, _ in messages) == {
        "/patchnav/map": 1,
        "/patchnav/roadmap": 1,
        "/patchnav/path": 1,
    }
    assert {s for _, s, _ in messages} == {MARKER_ARRAY}
    msgs = {t: m for t, _, m in messages}
    for msg in msgs.values():
        check_markers(msg, "map")
    assert sum(len(m.points) for m in msgs["/patchnav/map"].markers) == 3 * TRIANGLES
    (roadmap,) = msgs["/patchnav/roadmap"].markers
    assert roadmap.type == LINE_LIST and roadmap.ns == "roadmap"
    (path,) = msgs["/patchnav/path"].markers
    assert path.type == LINE_STRIP and path.ns == "path" and path.id == 0
    first, last = path.points[0], path.points[-1]
    assert (first.x, first.y, first.z) == pytest.approx((1.0, 1.0, 0.5))
    assert ((last.x - 9) ** 2 + (last.y - 9) ** 2 + (last.z - 0.5) ** 2) ** 0.5 <= 0.5 + 1e-9


def test_a_hybrid_map_has_one_marker_per_patch_kind(tmp_path):
    out = tmp_path / "hybrid.pmap"
    run("map", "build", "--scene", "lab", "--kind", "hybrid", "--backend", "polygon", "--out", out)
    # A polygon map counts the triangles of its trimesh patches only.
    info = dict(line.split(":", 1) for line in run("map", "info", out).splitlines())
    assert int(info["planar patches"]) > 0 and int(info["trimesh patches"]) > 0
    mcap = tmp_path / "hybrid.mcap"
    run("map", "export", out, "--mcap", mcap)
    ((topic, schema, msg),) = decode(mcap)
    assert (topic, schema) == ("/patchnav/map", MARKER_ARRAY)
    check_markers(msg, "map")
    by_ns = {m.ns: m for m in msg.markers}
    assert sorted(by_ns) == ["planar", "trimesh"]
    assert [m.id for m in msg.markers] == [0, 1]
    assert all(m.type == TRIANGLE_LIST for m in msg.markers)
    assert len(by_ns["trimesh"].points) == 3 * int(info["triangles"])
    # Every planar patch gives at least one triangle.
    assert len(by_ns["planar"].points) >= 3 * int(info["planar patches"])
