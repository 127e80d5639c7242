"""Tubes around polylines (seed 000 §4): rings on rotation-minimising frames, LOD, anti-aliasing clamp, caps.

Ring ``k`` of a tube with ``n`` sides has vertices ``P_k + r_k (cos θ_j N_k + sin θ_j B_k)``, θ_j = 2πj/n,
with radial unit normals (seed eq. 4-2, 4-8). Rings are welded around (no duplicate seam vertex; the UV seam
is carried by corner UVs) and along the tube; closed curves join their last ring to the first. Faces are
quads (outward, counter-clockwise), caps are n-gons (FLAT) or hemispheres (ROUND).

The seed's anti-aliasing clamp keeps a tube at least one pixel in radius: r_eff = max(r, s_pix), where
s_pix is the world size of one pixel at the point's depth, found by unprojecting NDC offsets (eq. 4-5).
Here the clamp is applied to the polygon's inscribed radius (s_pix / cos(π/n)), so the tessellated tube,
not only the ideal cylinder, covers two pixels; an optional maximum caps the inflation.
"""

from dataclasses import dataclass, field

import numpy as np

from .curve_refine import catmull_rom, select_points
from .errors import InvalidInputError
from .frames import rotation_minimizing_frames
from .polylines import arc_lengths, chunks, drop_duplicates, next_index, take_curves

CAPS = ("NONE", "FLAT", "ROUND")
SIDES_MODES = ("FIXED", "CAMERA")


@dataclass(frozen=True)
class TubeSettings:
    """Options of `build_tubes`.

    sides: ring vertices for FIXED; min_sides / max_sides bound CAMERA, which picks per tube
    ceil(π · projected diameter / edge_pixels); refine: Catmull-Rom subdivisions per segment (1 = off);
    select_angle: tolerance in radians for point selection (0 = keep all); aa_clamp: keep one pixel of radius
    for the camera; max_radius: cap of that inflation (0 = none); caps: NONE / FLAT / ROUND; uvs: corner UVs.
    """

    sides: int = 8
    sides_mode: str = "FIXED"
    min_sides: int = 3
    max_sides: int = 32
    edge_pixels: float = 8.0
    refine: int = 1
    refine_kind: str = "CENTRIPETAL"
    select_angle: float = 0.0
    aa_clamp: bool = False
    max_radius: float = 0.0
    caps: str = "NONE"
    uvs: bool = True

    def validate(self, camera):
        if self.caps not in CAPS:
            raise InvalidInputError(f"Caps must be one of {CAPS}; got {self.caps!r}")
        if self.sides_mode not in SIDES_MODES:
            raise InvalidInputError(f"Sides mode must be one of {SIDES_MODES}; got {self.sides_mode!r}")
        if not 3 <= self.sides <= 1024 or not 3 <= self.min_sides <= self.max_sides <= 1024:
            raise InvalidInputError("Tubes need 3 to 1024 sides, with min_sides <= max_sides")
        if (self.sides_mode == "CAMERA" or self.aa_clamp) and camera is None:
            raise InvalidInputError("Level of detail from the camera and the anti-aliasing clamp need a camera")
        if self.edge_pixels <= 0:
            raise InvalidInputError("Edge length in pixels must be positive")


@dataclass
class PolygonMesh:
    """A polygon mesh as flat arrays.

    positions: (V, 3) float32; face_sizes: (F,) int32; corner_verts: (L,) int32 (faces consecutive);
    edges: (E, 2) int32 and corner_edges: (L,) int32 when known (the writer then skips edge computation);
    point_normals: (V, 3) float32 or corner_normals: (L, 3) float32; corner_uvs: (L, 2) float32 or None;
    face_material: (F,) int32.
    """

    positions: np.ndarray
    face_sizes: np.ndarray
    corner_verts: np.ndarray
    edges: np.ndarray = None
    corner_edges: np.ndarray = None
    point_normals: np.ndarray = None
    corner_normals: np.ndarray = None
    corner_uvs: np.ndarray = None
    face_material: np.ndarray = None
    notes: list = field(default_factory=list)

    @property
    def face_offsets(self):
        return np.concatenate(([0], np.cumsum(self.face_sizes, dtype=np.int64)))


def pixel_world_size(points, camera):
    """World length of one pixel at each point's depth (seed eq. 4-3..4-5): (P,) float64; inf behind the eye.

    Unprojects NDC (0, 0, z) and (2 / width, 0, z) at the point's NDC depth through ViewProjection⁻¹.
    """
    vp = np.asarray(camera.projection, np.float64) @ np.asarray(camera.view, np.float64)
    clip = points @ vp[:3, :3].T + vp[:3, 3]
    w = points @ vp[3, :3] + vp[3, 3]
    in_front = w > 1e-12
    z = np.where(in_front, clip[:, 2] / np.where(in_front, w, 1.0), 0.0)
    inv = np.linalg.inv(vp)

    def unproject(x):
        h = inv[:, 0] * x + inv[:, 2] * z[:, None] + inv[:, 3]  # (P, 4) for NDC (x, 0, z, 1)
        return h[:, :3] / h[:, 3:4]

    size = np.linalg.norm(unproject(np.zeros((len(z), 1))) - unproject(np.full((len(z), 1), 2.0 / camera.width)),
                          axis=1)
    return np.where(in_front, size, np.inf)


def tube_sides(lines, settings, pixel_size):
    """Sides per curve (C,) int: fixed, or from the largest projected diameter (pixels) along the tube."""
    if settings.sides_mode == "FIXED":
        return np.full(lines.n_curves, settings.sides, np.int64)
    diameter_px = np.where(np.isfinite(pixel_size), 2.0 * lines.radius / pixel_size, 0.0)
    biggest = np.zeros(lines.n_curves)
    np.maximum.at(biggest, lines.curve_of_point(), diameter_px)
    sides = np.ceil(np.pi * biggest / settings.edge_pixels)
    return np.clip(sides, settings.min_sides, settings.max_sides).astype(np.int64)


def effective_radius(radius, pixel_size, sides, max_radius=0.0):
    """r_eff = max(r, min(s_pix / cos(π / n), max_radius)) per point: (P,) float64 (max_radius 0 = no cap)."""
    inflate = pixel_size / np.cos(np.pi / sides)
    if max_radius > 0:
        inflate = np.minimum(inflate, max_radius)
    return np.where(np.isfinite(inflate), np.maximum(radius, inflate), radius)


def prepare_lines(lines, settings):
    """Duplicates removed, refined and selected centre lines (the O(n) pre-process)."""
    lines = drop_duplicates(lines)
    if settings.refine > 1:
        lines = drop_duplicates(catmull_rom(lines, settings.refine, settings.refine_kind))
    if settings.select_angle > 0:
        lines = select_points(lines, settings.select_angle)
    return lines


def build_tubes(lines, settings=TubeSettings(), camera=None, progress=None):
    """Tube mesh around every curve of ``lines`` (`polylines.Polylines`). Returns a `PolygonMesh`.

    Works in chunks of whole curves, grouped by side count, so memory stays proportional to the output.
    """
    settings.validate(camera)
    lines = prepare_lines(lines, settings)
    notes = list(lines.notes)
    parts = []
    chunk_list = list(chunks(lines, 1 << 18))
    for i, (c0, c1) in enumerate(chunk_list):
        parts.extend(_build_chunk(take_curves(lines, c0, c1), settings, camera))
        if progress is not None:
            progress((i + 1) / len(chunk_list))
    mesh = _concatenate(parts, settings)
    mesh.notes = notes
    return mesh


def _build_chunk(lines, settings, camera):
    pixel = pixel_world_size(lines.points, camera) if camera is not None else np.full(len(lines.points), np.inf)
    sides = tube_sides(lines, settings, pixel)
    t, nrm, bin_ = rotation_minimizing_frames(lines)
    arc, total = arc_lengths(lines)
    curve = lines.curve_of_point()
    radius = lines.radius
    if settings.aa_clamp:
        radius = effective_radius(radius, pixel, sides[curve], settings.max_radius)
    for n in np.unique(sides):
        keep = sides == n
        sub = lines.select_curves(keep)
        pick = np.repeat(keep, lines.counts)
        yield _tube_group(sub, int(n), t[pick], nrm[pick], bin_[pick], radius[pick], arc[pick], total[keep],
                          settings)


def _ring(n):
    theta = 2.0 * np.pi * np.arange(n) / n
    return np.cos(theta), np.sin(theta)


def _tube_group(lines, n, t, nrm, bin_, radius, arc, total, settings):
    """Body (and caps) of tubes that all have ``n`` sides; vertex ids local to the group."""
    P = len(lines.points)
    cos_t, sin_t = _ring(n)
    radial = (cos_t[None, :, None] * nrm[:, None, :] + sin_t[None, :, None] * bin_[:, None, :]).astype(np.float32)
    pos = lines.points.astype(np.float32)[:, None, :] + radius.astype(np.float32)[:, None, None] * radial
    nxt = next_index(lines)
    seg = np.nonzero(nxt >= 0)[0]
    j = np.arange(n)
    j1 = (j + 1) % n
    a = seg[:, None] * n
    b = nxt[seg][:, None] * n
    quads = np.stack((a + j, a + j1, b + j1, b + j), axis=-1).reshape(-1, 4)  # (S * n, 4)
    # edges: around each ring (k, j)-(k, j+1) for all points, along each segment (k, j)-(k+1, j)
    ring_edges = np.stack((np.arange(P)[:, None] * n + j, np.arange(P)[:, None] * n + j1), axis=-1).reshape(-1, 2)
    long_edges = np.stack((a + j, b + j), axis=-1).reshape(-1, 2)
    n_ring = len(ring_edges)
    # corner edges of quad (a+j, a+j1, b+j1, b+j): ring edge of k at j, long edge at j1, ring edge of k+1 at j,
    # long edge at j
    ring_id = lambda k: (k[:, None] * n + j)  # noqa: E731 - tiny local index helper
    long_id = n_ring + np.arange(len(seg))[:, None] * n
    corner_edges = np.stack((ring_id(seg), long_id + j1, ring_id(nxt[seg]), long_id + j), axis=-1).reshape(-1, 4)

    curve = lines.curve_of_point()
    mat = lines.material_index[curve[seg]]
    group = {
        "positions": pos.reshape(-1, 3), "normals": radial.reshape(-1, 3),
        "faces": [quads], "corner_edges": [corner_edges], "edges": [ring_edges, long_edges],
        "face_material": [np.repeat(mat, n)], "uvs": [], "corner_normals": [],
    }
    if settings.uvs:
        length = np.maximum(total[curve], 1e-300)
        u0 = (arc / length)[seg]
        closing = nxt[seg] <= seg  # the segment that closes a cyclic curve ends at u = 1
        u1 = np.where(closing, 1.0, (arc / length)[nxt[seg]])
        v0, v1 = j / n, (j + 1) / n
        uv = np.empty((len(seg), n, 4, 2), np.float32)
        uv[..., 0] = np.stack((u0, u0, u1, u1), axis=-1)[:, None, :]
        uv[..., 1] = np.stack((v0, v1, v1, v0), axis=-1)[None, :, :]
        group["uvs"].append(uv.reshape(-1, 2))
    if settings.caps == "FLAT":
        group["corner_normals"].append(group["normals"][quads.ravel()])
    if settings.caps != "NONE":
        from .tube_caps import add_caps

        add_caps(group, lines, n, t, nrm, bin_, radius, settings)
    return group


def _concatenate(groups, settings):
    """One `PolygonMesh` from per-group pieces, offsetting vertex and edge ids."""
    positions, normals, faces, sizes, cverts, cedges, edges, mats, uvs, cnormals = ([] for _ in range(10))
    v_base = e_base = 0
    for g in groups:
        for f, ce in zip(g["faces"], g["corner_edges"], strict=True):
            sizes.append(np.full(len(f), f.shape[1], np.int32))
            cverts.append((f + v_base).ravel())
            cedges.append((ce + e_base).ravel())
        e_count = 0
        for e in g["edges"]:
            edges.append(e + v_base)
            e_count += len(e)
        positions.append(g["positions"])
        normals.append(g["normals"])
        mats.extend(g["face_material"])
        uvs.extend(g["uvs"])
        cnormals.extend(g["corner_normals"])
        v_base += len(g["positions"])
        e_base += e_count

    def cat(items, dtype, width=None):
        if items:
            return np.ascontiguousarray(np.concatenate(items), dtype=dtype)
        return np.zeros((0, width) if width else 0, dtype)

    mesh = PolygonMesh(
        positions=cat(positions, np.float32, 3), face_sizes=cat(sizes, np.int32),
        corner_verts=cat(cverts, np.int32), edges=cat(edges, np.int32, 2), corner_edges=cat(cedges, np.int32),
        face_material=cat(mats, np.int32),
    )
    if settings.caps == "FLAT":
        mesh.corner_normals = cat(cnormals, np.float32, 3)
    else:
        mesh.point_normals = cat(normals, np.float32, 3)
    if settings.uvs:
        mesh.corner_uvs = cat(uvs, np.float32, 2)
    return mesh
