"""Loop subdivision of a mesh as Blender gives it, shared by ``tessera.loop_subdivide`` and the viewport preview:
the kernel with the mesh's creases, and the baked lighting (HCE) decoded at the result's level."""

from dataclasses import dataclass, field

import numpy as np

from ...kernels.common.errors import TesseraError
from ...kernels.common.normals import face_unit_normals
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
    point_data = {k: v for k, v in arrays.point_attributes.items() if k != "crease_vert"}  # a crease, not data
    creases = settings.use_creases
    result = loop_subdivide(
        arrays.positions, arrays.triangles, settings.levels,
        creases=(marks.pairs, crease_to_sharpness(marks.crease)) if creases else None,
        vertex_sharpness=crease_to_sharpness(marks.vertex_crease) if creases and marks.vertex_crease is not None
        else None,
        boundary=settings.boundary, point_data=point_data, corner_data=arrays.corner_attributes,
        budget_bytes=budget_bytes, progress=progress,
    )
    build = LoopBuild(result)
    if hce_blob is not None and settings.use_baked_lighting:
        try:
            packed = hce.unpack_container(hce_blob, arrays.triangles)
        except TesseraError as err:
            build.notes.append(f"Baked lighting not used: {err}")
            return build
        normals = face_unit_normals(result.positions, result.triangles)
        roots = face_unit_normals(arrays.positions, arrays.triangles)
        faces = hce.select_colours(packed, result.levels, roots, normals)
        build.baked = hce.vertex_colours(result.triangles, faces, len(result.positions))
    return build
