"""Loop subdivision of a mesh as Blender gives it, shared by ``tessera.loop_subdivide`` and the viewport preview:
the kernel with the mesh's creases, and the baked lighting (HCE) decoded at the result's level."""

from dataclasses import dataclass, field

import numpy as np

from ...kernels.common.errors import TesseraError
from ...kernels.subdivision import hce
from ...kernels.subdivision.loop import loop_subdivide
from ...kernels.subdivision.loop_rules import crease_to_sharpness

HCE_PROPERTY = "tessera_hce"  # the mesh's custom property holding the packed HCE (bytes, saved with the .blend)


@dataclass
class LoopBuild:
    """result: `kernels.subdivision.loop.LoopResult`; baked: (V, 4) float32 vertex colours from the mesh's HCE or
    None; notes: what the user should know (a stale bake)."""

    result: object
    baked: np.ndarray | None = None
    notes: list = field(default_factory=list)


def subdivide(arrays, marks, settings, hce_blob=None, budget_bytes=0, progress=None):
    """Loop-subdivide `MeshArrays` ``arrays`` with the `bridge.EdgeMarks` ``marks`` as ``settings`` (an object with
    levels, boundary, use_creases, use_baked_lighting) say; ``hce_blob``: the mesh's stored HCE or None."""
    arrays.point_attributes.pop("crease_vert", None)  # a crease, not data to smooth
    creases = settings.use_creases
    result = loop_subdivide(
        arrays.positions, arrays.triangles, settings.levels,
        creases=(marks.pairs, crease_to_sharpness(marks.crease)) if creases else None,
        vertex_sharpness=crease_to_sharpness(marks.vertex_crease) if creases and marks.vertex_crease is not None
        else None,
        boundary=settings.boundary, point_data=arrays.point_attributes, corner_data=arrays.corner_attributes,
        budget_bytes=budget_bytes, progress=progress,
    )
    build = LoopBuild(result)
    if hce_blob is not None and settings.use_baked_lighting:
        try:
            packed = hce.unpack_container(hce_blob, arrays.triangles)
        except TesseraError as err:
            build.notes.append(f"Baked lighting not used: {err}")
            return build
        normals = hce.face_normals(result.positions, result.triangles)
        roots = hce.face_normals(arrays.positions, arrays.triangles)
        faces = hce.select_colours(packed, result.levels, roots, normals)
        build.baked = hce.vertex_colours(result.triangles, faces, len(result.positions))
    return build


def vertex_normals(positions, triangles):
    """Area-weighted unit vertex normals (V, 3) float32 of a triangle mesh, for drawing."""
    p = np.asarray(positions, np.float64)
    t = np.asarray(triangles)
    n = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])
    out = np.zeros_like(p)
    for k in range(3):
        for c in range(3):
            out[:, c] += np.bincount(t[:, k], n[:, c], len(p))
    length = np.linalg.norm(out, axis=1, keepdims=True)
    return np.divide(out, length, out=np.zeros_like(out), where=length > 0).astype(np.float32)
