"""Type stubs of the extension module ``patchnav._patchnav`` (re-exported by ``patchnav``)."""

from os import PathLike
from typing import Any, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
"""Any array-like of numbers: numpy arrays of any dtype castable to float64 and any strides,
nested lists, tuples."""

Path = Union[str, "PathLike[str]"]

__version__: str

class Map:
    """A map a robot plans on, of any backend. Immutable; safe to share between threads."""

    @staticmethod
    def from_mesh(
        vertices: ArrayLike,
        triangles: ArrayLike,
        backend: str = "bbox6d",
        spacing: Optional[float] = None,
    ) -> Map:
        """Coplanar faces of a triangle mesh (V x 3 vertices, M x 3 vertex indices) become
        planar patches of a map of ``backend`` (``spacing``: needed by ``pointcloud``)."""
    @staticmethod
    def load(path: Path) -> Map:
        """Reads a map file of any backend."""
    def save(self, path: Path) -> int:
        """Writes the map file atomically; returns its size in bytes."""
    def is_free(self, starts: ArrayLike, ends: ArrayLike, radius: float) -> npt.NDArray[np.bool_]:
        """Per step (N x 3 starts and ends, or one point each): whether a sphere of
        ``radius`` moves from start to end without touching the map."""
    @property
    def backend(self) -> str:
        """The backend's name."""
    @property
    def bounds(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``(min, max)`` corners of the box around the map."""
    def counts(self) -> Dict[str, int]:
        """``planar_patches``, ``trimesh_patches``, ``triangles``, ``points``,
        ``memory_bytes``."""

def extract(
    scans: Union[ArrayLike, List[ArrayLike]],
    sensor: str = "alrf",
    pose: Union[None, ArrayLike, List[ArrayLike]] = None,
    *,
    hybrid: bool = False,
    merge: bool = True,
    second_pass: bool = True,
    carve: bool = False,
    slab_thickness: Optional[float] = None,
    backend: str = "bbox6d",
    spacing: Optional[float] = None,
    threads: Optional[int] = None,
) -> Map:
    """Patches from one scan (N x 3, or organised H x W x 3 with NaN for missing pixels) or
    a list of scans, each with its 4 x 4 ``world_from_sensor`` pose, merged across scans."""

def plan(
    map: Map,
    start: ArrayLike,
    goals: ArrayLike,
    planner: str,
    radius: float,
    seed: int = 0,
    iterations: int = 10_000,
    *,
    step: float = 1.0,
    goal_tolerance: float = 0.5,
    explore: bool = False,
    shortcut: bool = False,
    roadmap: bool = False,
) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]:
    """One planning run: the path to the first goal (K x 3, empty when unreached) and the
    statistics (``status``, ``samples``, ``vertices``, ``edges``, ``collision_checks``,
    ``collision_time_s``, ``reached``, ``paths``, ``lengths``; ``shortcuts`` with
    ``shortcut=True``; ``roadmap_vertices`` and ``roadmap_edges`` with ``roadmap=True``)."""

def read_cloud(
    path: Path, *, skip_non_finite: bool = False, depth: Optional[str] = None
) -> Tuple[
    npt.NDArray[np.float64],
    Dict[str, npt.NDArray[np.float64]],
    Optional[Tuple[int, int]],
    Optional[npt.NDArray[np.float64]],
]:
    """Points, attributes, organised shape and pose (``patchnav.read_cloud`` wraps them in a
    ``Cloud``)."""

def classify_terrain(
    points: ArrayLike,
    *,
    resolution: float = 15.0,
    method: str = "ground-ahead",
    axes: Optional[Literal["lidar", "camera"]] = None,
    sensor_height: Optional[float] = None,
    pitch: Optional[float] = None,
    max_range: Optional[float] = None,
    sectors: Optional[int] = None,
) -> Dict[str, Any]:
    """The terrain class (``class``), ``drivable``, ``passable``, ``rule``, ``step``,
    ``points``, ``axes``, ``mount`` (height m, pitch and roll degrees),
    ``mount_estimated``, ``seconds`` and ``sectors`` ([(class, drivable)])."""

def ground_points(
    points: ArrayLike,
    *,
    axes: Optional[Literal["lidar", "camera"]] = None,
    mount: Optional[Tuple[float, float, float]] = None,
    settings: Optional[Mapping[str, float]] = None,
) -> npt.NDArray[np.bool_]:
    """Per point (N) or pixel (H x W): drivable ground. ``mount`` is (height m, pitch
    degrees down, roll degrees); ``settings`` overrides fields of the segmentation
    (``max_step``, ``max_slope``, ``min_cell``, ...)."""

def tof_filter(
    range: ArrayLike,
    amplitude: ArrayLike,
    meta: Union[Mapping[str, Any], Path],
    *,
    method: str = "regions",
    at: float = 160.0,
    aat: Optional[float] = None,
    unwrap: bool = False,
    low_at: Optional[float] = None,
    radial: bool = False,
    intensity: Optional[ArrayLike] = None,
) -> Dict[str, Any]:
    """Filters an H x W ToF frame (range in metres, 0 = none): ``range`` (filtered radial
    range, 0 where dropped), ``outcome`` (0 kept, 1 unwrapped, 2 dropped), ``points``
    (H x W x 3, NaN where dropped), ``kept``, ``unwrapped``, ``dropped``, ``method``."""

def names(vocabulary: str) -> List[str]:
    """The names ``backend``, ``planner``, ``sensor``, ``terrain_method``, ``tof_method`` or
    ``axes`` accept."""
