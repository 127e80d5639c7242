"""Per-edge and per-face tessellation levels for a whole mesh from the metrics in `kernels.tessellation.metrics`.

Each enabled metric gives an edge level per mesh edge and an inner level per triangle; they combine by
maximum, then `kernels.tessellation.metrics.clamp_and_round` caps and optionally rounds them. Edge levels are
computed once per edge from that edge's own data (endpoints, the two face normals beside it), so they
are identical for both triangles by construction; `face_side_edge_levels` recomputes them per face
side, the way a per-patch GPU shader sees them, so tests can check the two agree bit for bit.

Positions are in world space (the caller applies the object matrix) so camera metrics see real sizes.
"""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from ..common.normals import face_unit_normals, shared_vertex_normals
from ..common.partition import MAX_LEVEL
from ..common.topology import mesh_topology, triangle_edges, validate_triangles
from . import metrics
from .patches import pn_control, pn_edge_control

METRICS = ("DISTANCE", "PROJECTED", "SILHOUETTE", "CURVATURE")
CAMERA_METRICS = ("DISTANCE", "PROJECTED", "SILHOUETTE")


@dataclass(frozen=True)
class AdaptiveSettings:
    """Parameters of the adaptive metrics (units: scene units and pixels).

    metrics: the enabled subset of `METRICS`; max_level: cap ``t_tessmax`` in [1, 64]; power_of_two:
    ``NONE``/``CEIL``/``FLOOR``/``NEAREST``; distance_map ``LINEAR``/``INVERSE`` with near/far distances;
    edge_pixels: target on-screen edge length ``e_max``; silhouette_beta: inner ramp width;
    curvature_gain: the factor 10 of Eq. 4.5; boundary_silhouette: open-boundary edges count as silhouettes.
    """

    metrics: tuple = ("PROJECTED",)
    max_level: float = 16.0
    power_of_two: str = "NONE"
    distance_map: str = "LINEAR"
    near: float = 1.0
    far: float = 20.0
    edge_pixels: float = 10.0
    silhouette_beta: float = 0.25
    curvature_gain: float = 10.0
    boundary_silhouette: bool = True

    def validate(self):
        unknown = [m for m in self.metrics if m not in METRICS]
        if unknown or not self.metrics:
            raise InvalidInputError(f"Choose at least one metric from {', '.join(METRICS)}; got {self.metrics}")
        if not 1 <= self.max_level <= MAX_LEVEL:
            raise InvalidInputError(f"The maximum level must lie in [1, {MAX_LEVEL}]")
        return self


def _edge_faces(face_edges, n_edges):
    """First and last face of each edge (the two faces of a manifold edge; equal on a boundary).

    Returns ``(first (E,), last (E,), uses (E,))`` int64.
    """
    flat = face_edges.ravel()
    order = np.argsort(flat, kind="stable")
    uses = np.bincount(flat, minlength=n_edges)
    starts = np.cumsum(uses) - uses
    first = order[starts] // 3
    last = order[starts + uses - 1] // 3
    return first, last, uses


def _silhouette(positions, tris, edges, face_edges, camera, settings):
    normals = face_unit_normals(positions, tris)
    first, last, uses = _edge_faces(face_edges, len(edges))
    a, b = positions[edges[:, 0]], positions[edges[:, 1]]
    if camera.orthographic:
        eye = (a + b) * 0.5 + camera.backward  # direction only: v = backward for every edge
    else:
        eye = camera.eye
    u, u_hat = metrics.silhouette_products(a, b, normals[first], normals[last], eye)
    if settings.boundary_silhouette:
        u = np.where(uses == 1, -1.0, u)
        u_hat = np.where(uses == 1, 0.0, u_hat)
    t_max = settings.max_level
    edge = metrics.silhouette_edge_levels(u, t_max)
    inner = metrics.silhouette_inner_levels(u[face_edges], u_hat[face_edges], t_max, settings.silhouette_beta)
    return edge, inner


def _curvature(positions, tris, edges, vertex_normals, settings):
    a, b = edges[:, 0], edges[:, 1]
    curve = pn_edge_control(positions[a], positions[b], vertex_normals[a], vertex_normals[b])
    t_max = settings.max_level
    edge = metrics.curvature_level(metrics.curve_kappa(curve), gain=settings.curvature_gain, t_max=t_max, minimum=1)
    net = pn_control(positions[tris], vertex_normals[tris])
    inner = metrics.curvature_level(metrics.pn_inner_kappa(net), gain=settings.curvature_gain, t_max=t_max, minimum=1)
    return edge, inner


def adaptive_levels(positions, triangles, settings, camera=None, corner_normals=None, topology=None):
    """Edge and inner levels for a mesh.

    positions: (V, 3) world space; triangles: (T, 3) int; settings: `AdaptiveSettings`; camera:
    `kernels.common.camera.Camera` (needed by DISTANCE, PROJECTED, SILHOUETTE); corner_normals: (T, 3, 3) or None,
    used by CURVATURE through the same shared vertex normals the PN geometry uses.
    Returns ``(edge_levels (E,), inner_levels (T,))`` float64 in ``[1, max_level]``, edges as in
    `kernels.common.topology.triangle_edges`. Inner levels are at least the face's largest edge level. topology: the
    mesh's `kernels.common.topology.MeshTopology`, if built already.
    """
    settings.validate()
    positions = np.asarray(positions, np.float64)
    topology = topology or mesh_topology(triangles, len(positions))
    tris, edges, face_edges = topology.triangles, topology.edges, topology.face_edges
    if camera is None and any(m in CAMERA_METRICS for m in settings.metrics):
        raise InvalidInputError("Distance, projected-edge and silhouette levels need a camera (scene or viewport)")
    t_max = settings.max_level
    edge = np.ones(len(edges))
    inner = np.ones(len(tris))
    a, b = positions[edges[:, 0]], positions[edges[:, 1]]
    for name in settings.metrics:
        if name == "DISTANCE":
            args = (settings.near, settings.far, t_max, settings.distance_map)
            e = metrics.distance_edge_levels(a, b, camera.eye, *args)
            i = metrics.distance_inner_levels(positions[tris], camera.eye, *args)
        elif name == "PROJECTED":
            e = metrics.projected_edge_levels(a, b, camera.view, camera.projection, camera.height,
                                              settings.edge_pixels, t_max)
            i = e[face_edges].max(axis=1)
        elif name == "SILHOUETTE":
            e, i = _silhouette(positions, tris, edges, face_edges, camera, settings)
        else:
            normals = shared_vertex_normals(positions, tris, corner_normals)
            e, i = _curvature(positions, tris, edges, normals, settings)
        edge = np.maximum(edge, e)
        inner = np.maximum(inner, i)
    edge = metrics.clamp_and_round(edge, t_max, settings.power_of_two)
    inner = metrics.clamp_and_round(np.maximum(inner, edge[face_edges].max(axis=1)), t_max, settings.power_of_two)
    return edge, inner


def face_side_edge_levels(positions, triangles, settings, camera=None, corner_normals=None):
    """Edge levels recomputed per face side, in each face's own edge direction, as a per-patch shader would.

    Same arguments as `adaptive_levels`. Returns (T, 3) float64: the level of local edge ``e`` (corner ``e``
    to ``e + 1``) computed from that face's view of the edge (its corners in its order, its own normal
    first). Tests compare it with ``adaptive_levels(...)[0][face_edges]`` bit for bit.
    """
    settings.validate()
    positions = np.asarray(positions, np.float64)
    tris = validate_triangles(triangles, len(positions))
    edges, face_edges, _ = triangle_edges(tris)
    nxt = np.roll(tris, -1, axis=1)
    a, b = positions[tris], positions[nxt]
    t_max = settings.max_level
    out = np.ones(tris.shape)
    for name in settings.metrics:
        if name == "DISTANCE":
            e = metrics.distance_edge_levels(a, b, camera.eye, settings.near, settings.far, t_max,
                                             settings.distance_map)
        elif name == "PROJECTED":
            e = metrics.projected_edge_levels(a, b, camera.view, camera.projection, camera.height,
                                              settings.edge_pixels, t_max)
        elif name == "SILHOUETTE":
            normals = face_unit_normals(positions, tris)
            first, last, uses = _edge_faces(face_edges, len(edges))
            own = np.arange(len(tris))[:, None]
            other = np.where(first[face_edges] == own, last[face_edges], first[face_edges])
            eye = (a + b) * 0.5 + camera.backward if camera.orthographic else camera.eye
            u, _ = metrics.silhouette_products(a, b, normals[own].repeat(3, 1), normals[other], eye)
            if settings.boundary_silhouette:
                u = np.where(uses[face_edges] == 1, -1.0, u)
            e = metrics.silhouette_edge_levels(u, t_max)
        else:
            vn = shared_vertex_normals(positions, tris, corner_normals)
            curve = pn_edge_control(a, b, vn[tris], vn[nxt])
            e = metrics.curvature_level(metrics.curve_kappa(curve), gain=settings.curvature_gain, t_max=t_max,
                                        minimum=1)
        out = np.maximum(out, e)
    return metrics.clamp_and_round(out, t_max, settings.power_of_two)
