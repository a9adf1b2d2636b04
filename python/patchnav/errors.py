"""The exceptions patchnav raises.

Every error of the library is a :class:`PatchnavError`. A bad argument (an array of the
wrong shape, a non-finite value, an unknown name, a parameter out of range) is also a
``ValueError``; a file that cannot be read or written is also an ``OSError``.
"""


class PatchnavError(Exception):
    """Any error patchnav reports."""


class InvalidInputError(PatchnavError, ValueError):
    """A bad argument: array shape, non-finite value, unknown name, absurd parameter."""


class ReadError(PatchnavError, OSError):
    """A file that cannot be read or written (missing, truncated, damaged, wrong format)."""


class MapError(PatchnavError):
    """A map that cannot be built from the given patches, scans or mesh."""


class PlanError(PatchnavError):
    """A planning run that cannot start (empty map, planner the backend cannot serve)."""


class TerrainError(PatchnavError):
    """A frame that cannot be classified or segmented (no points ahead, no ground plane)."""


class TofError(PatchnavError):
    """A time-of-flight frame that cannot be filtered (no AAT parameters, bad sidecar)."""


__all__ = [
    "PatchnavError",
    "InvalidInputError",
    "ReadError",
    "MapError",
    "PlanError",
    "TerrainError",
    "TofError",
]
