"""Whole-mesh tessellation: levels -> refinement -> evaluated positions and attributes.

The refinement pattern is shared by every method; a method only decides where the new vertices go.
``LINEAR`` keeps them on the flat input triangles (the geometry is unchanged; useful as a base for
displacement, and as the oracle for the GPU path). PN and Phong plug in here as further methods.
"""

from dataclasses import dataclass

import numpy as np

from .errors import BudgetError, InvalidInputError
from .interpolate import corner_values, face_values, normalized, point_values
from .mesh_arrays import MeshArrays
from .refine import refine, refinement_counts
from .topology import triangle_edges, validate_triangles

METHODS = ("LINEAR",)

#: Bytes per output triangle and per output vertex at peak, measured loosely from the arrays the
#: refinement, the interpolation and Blender's mesh hold at once (documented in README "Memory guard").
BYTES_PER_TRIANGLE = 320
BYTES_PER_VERTEX = 64
BYTES_PER_CHANNEL = 4


@dataclass(frozen=True)
class Estimate:
    """Output size of a tessellation, computed without running it."""

    vertices: int
    triangles: int
    bytes: int


def uniform_levels(mesh, level):
    """One level for every edge of ``mesh``: (E,) float64."""
    tris = validate_triangles(mesh.triangles, len(mesh.positions))
    edges, _, _ = triangle_edges(tris)
    return np.full(len(edges), float(level))


def estimate(mesh, edge_levels, inner_levels=None, spacing="EQUAL"):
    """Counts and peak-memory estimate for `tessellate` with the same arguments. Returns `Estimate`."""
    n_vertices, n_triangles = refinement_counts(
        mesh.triangles, len(mesh.positions), edge_levels, inner_levels, spacing
    )
    corner_channels = sum(int(np.prod(a.shape[2:])) for a in mesh.corner_attributes.values()) + 3
    point_channels = sum(int(np.prod(a.shape[1:])) for a in mesh.point_attributes.values())
    size = n_triangles * (BYTES_PER_TRIANGLE + 3 * BYTES_PER_CHANNEL * corner_channels)
    size += n_vertices * (BYTES_PER_VERTEX + BYTES_PER_CHANNEL * point_channels)
    return Estimate(vertices=n_vertices, triangles=n_triangles, bytes=int(size))


def check_budget(est, budget_bytes):
    """Raise `BudgetError` when an `Estimate` exceeds ``budget_bytes`` (0 or None: no limit)."""
    if budget_bytes and est.bytes > budget_bytes:
        raise BudgetError(
            f"The result would have {est.triangles:,} triangles and need about {est.bytes / 2**20:,.0f} MiB, "
            f"over the memory budget of {budget_bytes / 2**20:,.0f} MiB. Lower the level, or raise the "
            f"budget in the Tessera preferences."
        )


def tessellate(mesh, edge_levels, inner_levels=None, spacing="EQUAL", method="LINEAR", backend="auto",
               progress=None):
    """Tessellate a `MeshArrays` and return a new `MeshArrays` (plus the `Refinement`).

    edge_levels: (E,) float, one per edge of `kernels.topology.triangle_edges`; inner_levels: (T,) float or
    None; spacing: see `kernels.partition`; method: one of `METHODS`; backend: see
    `kernels.interpolate.gather_weighted`; progress: optional callable ``(fraction)`` for long jobs.
    Returns ``(MeshArrays, Refinement)``; face attributes of the output are per output triangle.
    """
    if method not in METHODS:
        raise InvalidInputError(f"Unknown tessellation method {method!r}; expected one of {', '.join(METHODS)}")
    mesh.validate()
    report = progress or (lambda fraction: None)
    ref = refine(mesh.triangles, len(mesh.positions), edge_levels, inner_levels, spacing)
    report(0.4)
    out = MeshArrays(
        positions=point_values(ref, mesh.positions, backend),
        triangles=ref.triangles,
        attribute_types=dict(mesh.attribute_types),
    )
    report(0.6)
    if mesh.corner_normals is not None:
        out.corner_normals = normalized(corner_values(ref, mesh.corner_normals, backend))
    out.point_attributes = {k: point_values(ref, v, backend) for k, v in mesh.point_attributes.items()}
    report(0.8)
    out.corner_attributes = {k: corner_values(ref, v, backend) for k, v in mesh.corner_attributes.items()}
    out.face_attributes = {k: face_values(ref, v) for k, v in mesh.face_attributes.items()}
    report(1.0)
    return out, ref
