"""patchnav: range scans to patch maps a robot plans on.

The functions take and give numpy arrays (any array-like of numbers is accepted; points are
N x 3, organised scans H x W x 3 with NaN where a pixel has no measurement) and raise the
exceptions of :mod:`patchnav.errors`. Long calls release the GIL.

>>> import numpy as np, patchnav
>>> v = np.array([[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], float)
>>> floor = patchnav.Map.from_mesh(v, [[0, 1, 2], [0, 2, 3]])
>>> floor.is_free([[1, 1, 0.5]], [[3, 3, 0.5]], radius=0.3).tolist()
[True]
"""

from typing import Any, Dict, Iterator, Optional, Tuple

import numpy as np

from . import errors
from ._patchnav import Map, __version__, classify_terrain, extract, ground_points, names, plan
from ._patchnav import read_cloud as _read_cloud
from ._patchnav import tof_filter
from .errors import (
    InvalidInputError,
    MapError,
    PatchnavError,
    PlanError,
    ReadError,
    TerrainError,
    TofError,
)


class Cloud:
    """A cloud as :func:`read_cloud` gives it.

    Unpacks as ``points, attributes, shape``; ``pose`` is the sensor's ``world_from_sensor``
    4 x 4 transform when the file has one.

    * ``points``: N x 3 (organised clouds: H*W x 3 in row-major pixel order, NaN rows for
      pixels without a measurement; :meth:`organised` gives the H x W x 3 array that
      :func:`extract` takes).
    * ``attributes``: per point (or pixel) float64 arrays: ``intensity``, ``label``,
      ``ring``, ``normal`` (N x 3) and every extra field of the file, NaN where a pixel has
      no measurement.
    * ``shape``: ``(H, W)`` of an organised cloud, else ``None``.
    """

    __slots__ = ("points", "attributes", "shape", "pose")

    def __init__(
        self,
        points: np.ndarray,
        attributes: Dict[str, np.ndarray],
        shape: Optional[Tuple[int, int]],
        pose: Optional[np.ndarray] = None,
    ) -> None:
        self.points = points
        self.attributes = attributes
        self.shape = shape
        self.pose = pose

    def __iter__(self) -> Iterator[Any]:
        return iter((self.points, self.attributes, self.shape))

    def __repr__(self) -> str:
        return (
            f"Cloud({len(self.points)} points, attributes={sorted(self.attributes)}, "
            f"shape={self.shape}, pose={'yes' if self.pose is not None else 'no'})"
        )

    def organised(self) -> np.ndarray:
        """The points as H x W x 3 (organised clouds) or N x 3."""
        if self.shape is None:
            return self.points
        return self.points.reshape(self.shape[0], self.shape[1], 3)

    def world_points(self) -> np.ndarray:
        """The points in the world frame (``pose`` applied; the points as they are without
        one), N x 3 with the NaN rows kept."""
        if self.pose is None:
            return self.points
        return self.points @ self.pose[:3, :3].T + self.pose[:3, 3]


def read_cloud(path: Any, *, skip_non_finite: bool = False, depth: Optional[str] = None) -> Cloud:
    """Reads a cloud, range image or scan file in any format ``patchnav`` reads.

    ``skip_non_finite`` drops NaN points of unorganised clouds instead of failing; ``depth``
    names the convention of a 16-bit PNG depth image (``"tum"`` or ``"openni"``).
    """
    points, attributes, shape, pose = _read_cloud(
        path, skip_non_finite=skip_non_finite, depth=depth
    )
    return Cloud(points, attributes, shape, pose)


__all__ = [
    "Cloud",
    "Map",
    "__version__",
    "classify_terrain",
    "errors",
    "extract",
    "ground_points",
    "names",
    "plan",
    "read_cloud",
    "tof_filter",
    "InvalidInputError",
    "MapError",
    "PatchnavError",
    "PlanError",
    "ReadError",
    "TerrainError",
    "TofError",
]
