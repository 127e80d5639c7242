"""Whole-mesh tessellation: levels -> refinement -> evaluated positions, normals and attributes.

The refinement pattern is shared by every method; a method only decides where the new vertices go:

``LINEAR``
    On the flat input triangles (the geometry is unchanged; a base for displacement, and an oracle).
``PHONG``
    Phong tessellation with shape factor alpha (a constant, or per vertex from a point attribute).
``PN``
    PN triangles: cubic Bézier geometry, quadratic (or linear) normals.

Curved methods need one normal per vertex for the geometry; `kernels.tessellation.normals` explains the two
hard-edge policies. Attributes (UVs, colours) are interpolated linearly, as in the seeds.
"""

from dataclasses import dataclass, field

import numpy as np

from ..common import workers
from ..common.budget import Estimate
from ..common.errors import InvalidInputError
from ..common.mesh_arrays import MeshArrays
from ..common.normals import shared_vertex_normals
from ..common.topology import MeshTopology, mesh_topology
from . import patches
from .interpolate import corner_values, face_values, normalized, point_values
from .mesh_levels import carried_levels, mesh_levels
from .normals import NORMAL_MODES, split_by_normals, split_corners
from .refine import refine, refinement_counts
from .surface_eval import evaluate_corners, evaluate_corners_by_class, evaluate_surface

METHODS = ("LINEAR", "PHONG", "PN")
NORMAL_FIELDS = ("QUADRATIC", "LINEAR")


@dataclass(frozen=True)
class SurfaceOptions:
    """How the curved methods shape the surface.

    alpha: Phong shape factor (0 flat, 1 [Nunes 2011], 0.75 the paper's default); alpha_attribute: name of a
    float point attribute holding a per-vertex factor instead (or None); normal_mode: one of
    `kernels.tessellation.normals.NORMAL_MODES`; pn_normals: ``QUADRATIC`` (Vlachos's normal patch) or ``LINEAR``.
    """

    alpha: float = 0.75
    alpha_attribute: str | None = None
    normal_mode: str = "WATERTIGHT"
    pn_normals: str = "QUADRATIC"


@dataclass
class Tessellation:
    """What `tessellate` returns: the mesh, its refinement, and notes for the user.

    opened_edges: input edges the ``SPLIT`` normal mode cut open (0 in ``WATERTIGHT``).
    """

    mesh: MeshArrays
    refinement: object
    opened_edges: int = 0
    notes: list = field(default_factory=list)

#: Bytes per output triangle and per output vertex at peak, measured loosely from the arrays the
#: refinement, the interpolation and Blender's mesh hold at once (documented in README "Memory guard").
BYTES_PER_TRIANGLE = 320
BYTES_PER_VERTEX = 64
BYTES_PER_CHANNEL = 4


def uniform_levels(mesh, level, topology=None):
    """One level for every edge of ``mesh``: (E,) float64. topology: its `MeshTopology`, if built already."""
    topology = topology or mesh_topology(mesh.triangles, len(mesh.positions))
    return np.full(len(topology.edges), float(level))


def estimate(mesh, edge_levels, inner_levels=None, spacing="EQUAL"):
    """Counts and peak-memory estimate for `tessellate` with the same arguments (``edge_levels`` may be a carried
    `MeshLevels`, as in `refine`). Returns `Estimate`."""
    n_vertices, n_triangles = refinement_counts(
        mesh.triangles, len(mesh.positions), edge_levels, inner_levels, spacing
    )
    corner_channels = sum(int(np.prod(a.shape[2:])) for a in mesh.corner_attributes.values()) + 3
    point_channels = sum(int(np.prod(a.shape[1:])) for a in mesh.point_attributes.values())
    size = n_triangles * (BYTES_PER_TRIANGLE + 3 * BYTES_PER_CHANNEL * corner_channels)
    size += n_vertices * (BYTES_PER_VERTEX + BYTES_PER_CHANNEL * point_channels)
    return Estimate(vertices=n_vertices, triangles=n_triangles, bytes=int(size))


def _check_options(method, options):
    if method not in METHODS:
        raise InvalidInputError(f"Unknown tessellation method {method!r}; expected one of {', '.join(METHODS)}")
    if options.normal_mode not in NORMAL_MODES:
        raise InvalidInputError(f"Unknown normal mode {options.normal_mode!r}; expected {', '.join(NORMAL_MODES)}")
    if options.pn_normals not in NORMAL_FIELDS:
        raise InvalidInputError(f"Unknown PN normal field {options.pn_normals!r}; expected {', '.join(NORMAL_FIELDS)}")
    if not np.isfinite(options.alpha):
        raise InvalidInputError("The Phong shape factor must be a finite number")


def _split_mesh(mesh, edge_levels, topology=None):
    """SPLIT mode: one vertex per distinct corner normal. Returns (mesh', its `MeshTopology`, vertex normals,
    levels', opened)."""
    tris, source, normals = split_by_normals(mesh.triangles, mesh.corner_normals, len(mesh.positions))
    old_edges = (topology or mesh_topology(mesh.triangles, len(mesh.positions))).edges
    split_topology = mesh_topology(tris, len(source))
    new_edges = split_topology.edges
    n = len(mesh.positions)
    old_keys = old_edges[:, 0].astype(np.int64) * n + old_edges[:, 1]
    a, b = source[new_edges[:, 0]], source[new_edges[:, 1]]
    keys = np.minimum(a, b) * n + np.maximum(a, b)
    levels = np.asarray(edge_levels, np.float64)[np.searchsorted(old_keys, keys)]
    split = MeshArrays(
        positions=mesh.positions[source], triangles=tris, corner_normals=mesh.corner_normals,
        point_attributes={k: v[source] for k, v in mesh.point_attributes.items()},
        corner_attributes=mesh.corner_attributes, face_attributes=mesh.face_attributes,
        attribute_types=mesh.attribute_types,
    )
    return split, split_topology, normals, levels, len(new_edges) - len(old_edges)


def _alpha_values(mesh, options):
    """Per-vertex shape factors (V,) float64, or None for a constant factor."""
    name = options.alpha_attribute
    if not name:
        return None
    values = mesh.point_attributes.get(name)
    if values is None or values.ndim != 1:
        raise InvalidInputError(f"The shape-factor attribute {name!r} must be a float attribute on points")
    values = np.asarray(values, np.float64)
    if not np.all(np.isfinite(values)):
        raise InvalidInputError(f"The shape-factor attribute {name!r} has NaN or infinite values")
    return values


@dataclass
class SurfaceInputs:
    """What a curved surface is built from, after the sharp-edge policy (shared by the CPU and GPU paths).

    mesh: the mesh the surface is built on (``SPLIT`` mode: split along sharp edges); positions: (V, 3) float64;
    vertex_normals: (V, 3) one geometry normal per vertex; split: (T, 3) bool corners whose shading normal
    differs from the vertex normal, or None; edge_levels: (E,) for ``mesh``'s edges; alpha: (V,) per-vertex
    Phong factors, or None for ``options.alpha``; opened_edges: edges ``SPLIT`` cut open; topology: ``mesh``'s
    `MeshTopology` where it was built (None: not yet).
    """

    mesh: MeshArrays
    positions: np.ndarray
    vertex_normals: np.ndarray
    split: np.ndarray | None
    edge_levels: np.ndarray
    alpha: np.ndarray | None
    opened_edges: int = 0
    topology: MeshTopology | None = None

    def shading_normals(self):
        """Per-corner shading normals (T, 3, 3) float64: a split face keeps all its own corner normals."""
        tris = self.mesh.triangles
        out = np.asarray(self.vertex_normals, np.float64)[tris]
        if self.split is not None:
            faces = self.split.any(axis=1)
            out[faces] = np.asarray(self.mesh.corner_normals, np.float64)[faces]
        return out


def surface_inputs(mesh, edge_levels, method, options, topology=None):
    """Apply ``options.normal_mode`` to ``mesh`` for ``method`` (PHONG or PN): a `SurfaceInputs`. topology: the
    mesh's `MeshTopology`, if built already."""
    positions = np.asarray(mesh.positions, np.float64)
    if options.normal_mode == "SPLIT" and mesh.corner_normals is not None:
        source, topology, vertex_normals, edge_levels, opened = _split_mesh(mesh, edge_levels, topology)
        alpha = _alpha_values(source, options) if method == "PHONG" else None
        return SurfaceInputs(source, np.asarray(source.positions, np.float64), vertex_normals, None,
                             np.asarray(edge_levels, np.float64), alpha, opened, topology)
    vertex_normals = shared_vertex_normals(positions, mesh.triangles, mesh.corner_normals)
    split = None if mesh.corner_normals is None else split_corners(mesh.triangles, mesh.corner_normals,
                                                                   vertex_normals)
    alpha = _alpha_values(mesh, options) if method == "PHONG" else None
    return SurfaceInputs(mesh, positions, vertex_normals, split, np.asarray(edge_levels, np.float64), alpha,
                         topology=topology)


def _edge_data(ref, positions, normals):
    lo, hi = ref.edges[:, 0], ref.edges[:, 1]
    return positions[lo], positions[hi], normals[lo], normals[hi]


def _phong_positions(ref, positions, normals, alpha):
    pa, pb, na, nb = _edge_data(ref, positions, normals)
    p, n = positions[ref.faces], normals[ref.faces]
    if alpha is None or np.ndim(alpha) == 0:
        a = 0.75 if alpha is None else float(alpha)
        return evaluate_surface(ref, positions, patches.phong_edge_control(pa, pb, na, nb, a, a),
                                patches.quadratic_edge_basis, patches.phong_control(p, n, a), patches.quadratic_basis)
    linear = point_values(ref, positions, "numpy").astype(np.float64)
    offset = evaluate_surface(ref, np.zeros_like(positions), patches.phong_edge_offset_control(pa, pb, na, nb),
                              patches.quadratic_edge_basis, patches.phong_offset_control(p, n), patches.quadratic_basis)
    factor = point_values(ref, alpha, "numpy").astype(np.float64)
    out = linear + factor[:, None] * offset
    out[: ref.n_corners] = positions
    return out.astype(np.float32)


def _pn_positions(ref, positions, normals):
    pa, pb, na, nb = _edge_data(ref, positions, normals)
    p, n = positions[ref.faces], normals[ref.faces]
    return evaluate_surface(ref, positions, patches.pn_edge_control(pa, pb, na, nb), patches.cubic_edge_basis,
                            patches.pn_control(p, n), patches.cubic_basis)


def _normal_field(method, options):
    """(edge control fn, edge basis, face control fn, face basis) of the shading-normal field."""
    if method == "PN" and options.pn_normals == "QUADRATIC":
        return (patches.pn_edge_normal_control, patches.quadratic_edge_basis,
                patches.pn_normal_control, patches.quadratic_basis)
    return (lambda pa, pb, na, nb: np.stack([na, nb], axis=1), patches.linear_edge_basis,
            lambda p, n: np.asarray(n, np.float64), patches.linear_basis)


def _shading_normals(ref, method, options, positions, vertex_normals, corner_normals, split, points=None):
    """Unit shading normals: (point normals (n_vertices, 3), corner normals (M, 3, 3) or None).

    points: the point normals when another path (the GPU) evaluated them already."""
    edge_fn, edge_basis, face_fn, face_basis = _normal_field(method, options)
    if points is None:
        pa, pb, na, nb = _edge_data(ref, positions, vertex_normals)
        points = evaluate_surface(ref, normalized(vertex_normals), edge_fn(pa, pb, na, nb), edge_basis,
                                  face_fn(positions[ref.faces], vertex_normals[ref.faces]), face_basis, unit=True)
    if split is None or not split.any():
        return points, None
    faces = np.flatnonzero(split.any(axis=1))
    own = face_fn(positions[ref.faces[faces]], corner_normals[faces])  # the split faces' own normal fields
    if ref.classes:  # once per vertex slot of each split face, stamped onto its corners
        every = len(faces) == len(ref.faces)  # flat shading: no corner takes the point normal
        corners = np.empty((ref.n_triangles, 3, points.shape[1]), np.float32) if every else points[ref.triangles]
        evaluate_corners_by_class(ref, faces, own, face_basis, corners, unit=True)
        return points, corners
    corners = points[ref.triangles]
    control = np.zeros((len(ref.faces),) + own.shape[1:])
    control[faces] = own
    out_tris = np.flatnonzero(np.isin(ref.triangle_face, faces))
    evaluate_corners(ref, out_tris, control, face_basis, corners, unit=True)
    return points, corners


def tessellate(mesh, edge_levels, inner_levels=None, spacing="EQUAL", method="LINEAR", backend="auto",
               progress=None, options=None, surface=None):
    """Tessellate a `MeshArrays` and return a `Tessellation`.

    edge_levels: (E,) float, one per edge of `kernels.common.topology.triangle_edges`, or a carried `MeshLevels` (as in
    `refine`); inner_levels: (T,) float or None; spacing: see `kernels.common.partition`; method: one of `METHODS`;
    backend: see `kernels.tessellation.interpolate.gather_weighted`; progress: optional callable ``(fraction)``;
    options: `SurfaceOptions` for PHONG and PN; surface: for PHONG and PN, an optional evaluator
    ``(refinement, SurfaceInputs) -> (positions (N, 3), unit point normals (N, 3))`` that replaces the numpy
    surface (the GPU compute path). Face attributes of the output are per output triangle. Curved
    methods write unit ``point_normals`` (and ``corner_normals`` where the input has split normals).
    """
    options = options or SurfaceOptions()
    _check_options(method, options)
    mesh.validate()
    levels = carried_levels(mesh.triangles, len(mesh.positions), edge_levels, inner_levels, spacing)
    with workers.parallel_section():
        return _tessellate(mesh, levels, method, backend, progress or (lambda fraction: None), options, surface)


def _tessellate(mesh, levels, method, backend, report, options, surface):
    result = Tessellation(mesh=None, refinement=None)
    if method == "LINEAR":
        ref = refine(mesh.triangles, len(mesh.positions), levels)
        report(0.4)
        attributes = workers.submit(_attributes, ref, mesh, backend)
        edges = _output_edges_job(ref)
        out = MeshArrays(positions=point_values(ref, mesh.positions, backend), triangles=ref.triangles,
                         attribute_types=dict(mesh.attribute_types))
        if mesh.corner_normals is not None:
            out.corner_normals = normalized(corner_values(ref, mesh.corner_normals, backend))
    else:
        inputs = surface_inputs(mesh, levels.edge_level, method, options, levels.topology)
        source, positions, vertex_normals, split, alpha = (
            inputs.mesh, inputs.positions, inputs.vertex_normals, inputs.split, inputs.alpha)
        result.opened_edges = inputs.opened_edges
        if result.opened_edges:
            result.notes.append(f"Split normals opened {result.opened_edges} edge(s): the surface has gaps there")
        if source is not mesh:  # SPLIT: the levels of the split mesh's own edges, the same inner levels
            levels = mesh_levels(inputs.topology, inputs.edge_levels, levels.inner_level, levels.spacing)
        ref = refine(source.triangles, len(source.positions), levels)
        report(0.4)
        # Four independent parts, longest first, on the two workers (this thread waits).
        attributes = workers.submit(_attributes, ref, source, backend)
        corner_normals = None if mesh.corner_normals is None else np.asarray(mesh.corner_normals, np.float64)
        shading = (positions, vertex_normals, corner_normals, split)
        points = None
        if surface is not None:
            out_positions, points = surface(ref, inputs)
        normals = workers.submit(_shading_normals, ref, method, options, *shading, points)
        triangles = workers.submit(lambda: ref.triangles)
        edges = _output_edges_job(ref)
        if surface is None and method == "PN":
            out_positions = workers.submit(_pn_positions, ref, positions, vertex_normals).result()
        elif surface is None:
            out_positions = workers.submit(_phong_positions, ref, positions, vertex_normals,
                                           options.alpha if alpha is None else alpha).result()
        report(0.6)
        out = MeshArrays(positions=out_positions, triangles=triangles.result(),
                         attribute_types=dict(mesh.attribute_types))
        out.point_normals, out.corner_normals = normals.result()
    report(0.8)
    out.point_attributes, out.corner_attributes, out.face_attributes = attributes.result()
    if edges is not None:
        edges.result()
    report(1.0)
    result.mesh, result.refinement = out, ref
    return result


def _output_edges_job(ref):
    """The per-face path's output edges on a worker (a few long array passes, beside the surface work), or None:
    the class path's (a Python loop per class) measured slower on a worker than after it, so the writer builds
    those, and the general path has none."""
    return workers.submit(ref.output_edges) if ref.has_output_edges and not ref.classes else None


def _attributes(ref, mesh, backend):
    """The mesh's point, corner and face attributes on the refinement: three dicts of arrays."""
    return ({k: point_values(ref, v, backend) for k, v in mesh.point_attributes.items()},
            {k: corner_values(ref, v, backend) for k, v in mesh.corner_attributes.items()},
            {k: face_values(ref, v) for k, v in mesh.face_attributes.items()})

