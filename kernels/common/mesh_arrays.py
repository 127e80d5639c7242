"""A triangle mesh as plain numpy arrays: what crosses between Blender (the bridge) and the kernels."""

from dataclasses import dataclass, field

import numpy as np

from .errors import InvalidInputError


@dataclass
class MeshArrays:
    """Triangle mesh with attributes by domain.

    positions: (V, 3) float32.
    triangles: (T, 3) int32, counter-clockwise.
    corner_normals: (T, 3, 3) float32 unit normals per face corner, or None.
    point_normals: (V, 3) float32 unit normals per vertex, or None (used where ``corner_normals`` is None).
    point_attributes: name -> (V, ...) float32 (e.g. a colour attribute on points).
    corner_attributes: name -> (T, 3, ...) float32 (UV maps, corner colours).
    face_attributes: name -> (T, ...) any dtype, copied, never interpolated (material index, flags).
    attribute_types: name -> opaque type tag kept for the writer (Blender's data type); kernels ignore it.
    """

    positions: np.ndarray
    triangles: np.ndarray
    corner_normals: np.ndarray | None = None
    point_normals: np.ndarray | None = None
    point_attributes: dict = field(default_factory=dict)
    corner_attributes: dict = field(default_factory=dict)
    face_attributes: dict = field(default_factory=dict)
    attribute_types: dict = field(default_factory=dict)

    def validate(self):
        """Check shapes and finiteness; raise `InvalidInputError` with the first problem found."""
        v, t = len(self.positions), len(self.triangles)
        if self.positions.shape != (v, 3):
            raise InvalidInputError(f"positions must have shape (V, 3); got {self.positions.shape}")
        if not np.all(np.isfinite(self.positions)):
            raise InvalidInputError("The mesh has vertex positions that are NaN or infinite")
        if self.corner_normals is not None and self.corner_normals.shape != (t, 3, 3):
            raise InvalidInputError(f"corner_normals must have shape ({t}, 3, 3); got {self.corner_normals.shape}")
        if self.point_normals is not None and self.point_normals.shape != (v, 3):
            raise InvalidInputError(f"point_normals must have shape ({v}, 3); got {self.point_normals.shape}")
        for name, values in self.point_attributes.items():
            if len(values) != v:
                raise InvalidInputError(f"Point attribute {name!r} has {len(values)} rows for {v} vertices")
        for name, values in self.corner_attributes.items():
            if values.shape[:2] != (t, 3):
                raise InvalidInputError(f"Corner attribute {name!r} has shape {values.shape}; expected ({t}, 3, ...)")
        for name, values in self.face_attributes.items():
            if len(values) != t:
                raise InvalidInputError(f"Face attribute {name!r} has {len(values)} rows for {t} triangles")
        return self
