"""Tubes around polylines ([Nunes 2011, §4]): rings on rotation-minimising frames, LOD, anti-aliasing clamp, caps.

Ring ``k`` of a tube with ``n`` sides has vertices ``P_k + r_k (cos θ_j N_k + sin θ_j B_k)``, θ_j = 2πj/n,
with radial unit normals ([Nunes 2011] eq. 4-2, 4-8). Rings are welded around (no duplicate seam vertex; the UV seam
is carried by corner UVs) and along the tube; closed curves join their last ring to the first. Faces are
quads (outward, counter-clockwise), caps are n-gons (FLAT) or hemispheres (ROUND).

[Nunes 2011]'s anti-aliasing clamp keeps a tube at least one pixel in radius: r_eff = max(r, s_pix), where
s_pix is the world size of one pixel at the point's depth, found by unprojecting NDC offsets (eq. 4-5).
Here the clamp is applied to the polygon's inscribed radius (s_pix / cos(π/n)), so the tessellated tube,
not only the ideal cylinder, covers two pixels; an optional maximum caps the inflation.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from ..common.errors import EmptyResultError, InvalidInputError
from ..common.tolerances import FLOAT64_TINY
from .caps import CapEnds, cap_pieces, cap_sizes
from .curve_refine import catmull_rom, select_points
from .frames import rotation_minimizing_frames, rotation_minimizing_frames_opencl
from .opencl_path import TubeDevice, runtime_for
from .polylines import arc_lengths, chunks, drop_duplicates, take_curves

CAPS = ("NONE", "FLAT", "ROUND")
SIDES_MODES = ("FIXED", "CAMERA")


@dataclass(frozen=True)
class TubeSettings:
    """Options of `build_tubes`.

    sides: ring vertices for FIXED; min_sides / max_sides bound CAMERA, which picks per tube
    ceil(π · projected diameter / edge_pixels); refine: Catmull-Rom subdivisions per segment (1 = off);
    select_angle: tolerance in radians for point selection (0 = keep all); aa_clamp: keep one pixel of radius
    for the camera; max_radius: cap of that inflation (0 = none); caps: NONE / FLAT / ROUND; uvs: corner UVs;
    point_normals: write the exact radial point normals (a mesh writer that lets Blender derive its normals can
    skip them: a sixth of the output bytes; FLAT caps compute them anyway for the body's corners).
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
    point_normals: bool = True

    def validate(self, camera):
        if self.caps not in CAPS:
            raise InvalidInputError(f"Caps must be one of {CAPS}; got {self.caps!r}")
        if self.sides_mode not in SIDES_MODES:
            raise InvalidInputError(f"Sides mode must be one of {SIDES_MODES}; got {self.sides_mode!r}")
        if not 3 <= self.sides <= 1024 or not 3 <= self.min_sides <= self.max_sides <= 1024:
            raise InvalidInputError("Tubes need 3 to 1024 sides, with min_sides <= max_sides")
        if (self.sides_mode == "CAMERA" or self.aa_clamp) and camera is None:
            raise InvalidInputError("Camera sides and the pixel clamp need a camera: set a scene camera, use the "
                                    "viewport camera, or choose Fixed sides without the clamp")
        if self.edge_pixels <= 0:
            raise InvalidInputError("Edge length in pixels must be positive")


@dataclass
class PolygonMesh:
    """A polygon mesh as flat arrays.

    positions: (V, 3) float32; face_offsets: (F + 1,) int32 first corner of every face, then L (faces consecutive,
    the layout of Blender's own face offsets); corner_verts: (L,) int32; edges: (E, 2) int32 and corner_edges: (L,)
    int32 when known (the writer then skips edge computation); point_normals: (V, 3) float32 or corner_normals:
    (L, 3) float32; corner_uvs: (L, 2) float32 or None; face_material: (F,) int32, or None when every face has
    material 0.
    """

    positions: np.ndarray
    face_offsets: np.ndarray
    corner_verts: np.ndarray
    edges: np.ndarray = None
    corner_edges: np.ndarray = None
    point_normals: np.ndarray = None
    corner_normals: np.ndarray = None
    corner_uvs: np.ndarray = None
    face_material: np.ndarray = None
    notes: list = field(default_factory=list)

    @property
    def face_sizes(self):
        """Corners of every face: (F,) int32."""
        return np.diff(self.face_offsets)


@dataclass(frozen=True)
class MeshSizes:
    """Element counts of a tube mesh (bodies and caps), and whether any face has a material index other than 0:
    what an allocator of its `PolygonMesh` needs."""

    vertices: int
    faces: int
    corners: int
    edges: int
    materials: bool = True


def allocate_arrays(sizes, settings):
    """A `PolygonMesh` of new numpy arrays for ``sizes`` (`MeshSizes`) and the arrays ``settings`` asks for.

    The default allocator of `build_tubes`. Another allocator (a mesh writer handing out the memory of the mesh it
    will become) returns the same shapes and dtypes, contiguous; any array may live elsewhere.
    """
    v, f, c, e = sizes.vertices, sizes.faces, sizes.corners, sizes.edges
    mesh = PolygonMesh(
        positions=np.empty((v, 3), np.float32), face_offsets=np.empty(f + 1, np.int32),
        corner_verts=np.empty(c, np.int32), edges=np.empty((e, 2), np.int32), corner_edges=np.empty(c, np.int32),
        point_normals=np.empty((v, 3), np.float32) if settings.point_normals or settings.caps == "FLAT" else None,
        face_material=np.empty(f, np.int32) if sizes.materials else None,
    )
    if settings.caps == "FLAT":
        mesh.corner_normals = np.empty((c, 3), np.float32)
    if settings.uvs:
        mesh.corner_uvs = np.empty((c, 2), np.float32)
    return mesh


def _check_allocation(mesh, sizes, settings):
    """Raise ValueError unless ``mesh`` (from an allocator) has every array ``settings`` needs, shaped for
    ``sizes``, of the right dtype and contiguous."""
    v, f, c, e = sizes.vertices, sizes.faces, sizes.corners, sizes.edges
    want = {"positions": ((v, 3), np.float32), "face_offsets": ((f + 1,), np.int32), "corner_verts": ((c,), np.int32),
            "edges": ((e, 2), np.int32), "corner_edges": ((c,), np.int32)}
    if sizes.materials:
        want["face_material"] = ((f,), np.int32)
    if settings.point_normals or settings.caps == "FLAT":
        want["point_normals"] = ((v, 3), np.float32)
    if settings.caps == "FLAT":
        want["corner_normals"] = ((c, 3), np.float32)
    if settings.uvs:
        want["corner_uvs"] = ((c, 2), np.float32)
    for name, (shape, dtype) in want.items():
        a = getattr(mesh, name)
        if a is None or a.shape != shape or a.dtype != dtype or not a.flags.c_contiguous or not a.flags.writeable:
            raise ValueError(f"The allocator gave {name} as "
                             f"{None if a is None else (a.shape, a.dtype)}; {shape} {np.dtype(dtype)} was needed")


@dataclass
class TubeFrames:
    """Frames and sizes of prepared centre lines (`_frames`).

    Per point: t, n, b (P, 3) float32 unit tangent, normal and binormal (rotation-minimising); radius (P,) float32
    (after the anti-aliasing clamp when it is on); arc (P,) float64 arc length from the curve's start. Per curve:
    total (C,) float64 length (a closed curve's includes its closing segment); sides (C,) int64. Arc and total
    are 0 in chunks of open curves built without UVs (nothing reads them there).
    """

    t: np.ndarray
    n: np.ndarray
    b: np.ndarray
    radius: np.ndarray
    arc: np.ndarray
    total: np.ndarray
    sides: np.ndarray

    @classmethod
    def empty(cls, n_points, n_curves):
        vec = lambda: np.empty((n_points, 3), np.float32)  # noqa: E731
        return cls(t=vec(), n=vec(), b=vec(), radius=np.empty(n_points, np.float32), arc=np.empty(n_points),
                   total=np.empty(n_curves), sides=np.empty(n_curves, np.int64))


@dataclass
class Cursor:
    """Where the next run of tubes is written: its first body vertex, face, corner and edge (``v``, ``f``, ``c``,
    ``e``), and the next free cap vertex and edge (``cap_v``, ``cap_e``: caps are numbered after every body)."""

    v: int = 0
    f: int = 0
    c: int = 0
    e: int = 0
    cap_v: int = 0
    cap_e: int = 0

    def advance(self, n_points, n_segments, sides):
        """Move past a run of ``n_points`` rings and ``n_segments`` segments with ``sides`` sides."""
        self.v += n_points * sides
        self.f += n_segments * sides
        self.c += 4 * n_segments * sides
        self.e += (n_points + n_segments) * sides


@dataclass(frozen=True)
class CurveRun:
    """The points and segments of one run of curves written together (`_run_topology`), in local point ids.

    pick: slice or (P,) int64 of the run's points in the lines; counts, cyclic: (R,) per curve; n_pts: P;
    local: (R + 1,) int64 first local point of each curve; seg: (S,) int64 first point of each segment; nxt: (S,)
    its second point; closing: (S,) bool the segment closes a cyclic curve; curve_of_point: (P,) int64.
    """

    pick: object
    counts: np.ndarray
    cyclic: np.ndarray
    n_pts: int
    local: np.ndarray
    seg: np.ndarray
    nxt: np.ndarray
    closing: np.ndarray
    curve_of_point: np.ndarray


def pixel_world_size(points, camera):
    """World length of one pixel at each point's depth ([Nunes 2011] eq. 4-3..4-5): (P,) float64; inf behind the eye.

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


def build_tubes(lines, settings=TubeSettings(), camera=None, progress=None, backend="auto", allocate=allocate_arrays):
    """Tube mesh around every curve of ``lines`` (`polylines.Polylines`). Returns a `PolygonMesh`.

    Layout: tubes sorted by side count (stable, so FIXED keeps the curve order), bodies first, then caps.
    Output arrays are allocated once at their final size and written in chunks of curves, so memory stays
    close to the output itself. ``backend``: "auto" (OpenCL when a device with doubles exists, else numpy),
    "numpy" or "opencl" (the same numbering; values equal within float32 rounding). Raises `EmptyResultError`
    when no curve has two distinct points (nothing has a length to put a tube around). ``allocate(sizes,
    settings)``: where the output goes (`allocate_arrays`, or memory the caller owns, such as a new mesh's); called
    once, after the input has been checked.
    """
    settings.validate(camera)
    runtime = runtime_for(backend)
    lines = prepare_lines(lines, settings)
    if lines.n_curves == 0 or len(lines.points) == 0:
        raise EmptyResultError("These curves have no length: every curve has fewer than two distinct points, "
                               "so there is no tube to build")
    report = progress or (lambda f: None)
    frames = _frames(lines, settings, camera, runtime)
    report(0.3)
    layout = _Layout(lines, frames.sides, settings)
    mesh = allocate(layout.sizes, settings)
    _check_allocation(mesh, layout.sizes, settings)
    mesh.notes = list(lines.notes)
    caps = []
    cursor = Cursor(cap_v=layout.body_v, cap_e=layout.body_e)
    units = list(layout.units())
    device = TubeDevice(runtime, mesh) if runtime is not None else None
    for i, (n, curves) in enumerate(units):
        _write_body(mesh, lines, frames, n, curves, cursor, settings, caps, device)
        report(0.3 + 0.65 * (i + 1) / len(units))
    if device is not None:
        device.finish()
    _write_caps(mesh, caps, layout, settings)
    mesh.face_offsets[-1] = layout.sizes.corners
    if settings.caps == "FLAT":
        mesh.corner_normals[: layout.body_c] = mesh.point_normals[mesh.corner_verts[: layout.body_c]]
        mesh.point_normals = None
    elif not settings.point_normals:
        mesh.point_normals = None
    report(1.0)
    return mesh


def tube_sections(lines, settings, camera=None):
    """What a GPU draw of the tubes needs: the prepared `Polylines` and their `TubeFrames` (unit N, B and the
    radius before the anti-aliasing clamp, which the shader applies per frame; sides per curve)."""
    lines = prepare_lines(lines, settings)
    frames = _frames(lines, replace(settings, aa_clamp=False), camera, runtime_for("auto"))
    return lines, frames


def lod_sides(lines, settings, camera):
    """Sides per curve (C,) for ``camera`` (prepared lines): what a preview recomputes when the view moves."""
    pixel = pixel_world_size(lines.points, camera) if camera is not None else np.full(len(lines.points), np.inf)
    return tube_sides(lines, settings, pixel)


def _frames(lines, settings, camera, runtime=None):
    """`TubeFrames` of prepared lines, chunked for memory; the frames come from OpenCL when ``runtime`` is given (one
    launch over every curve once the chunks have their arc lengths: it reads the whole arrays in place)."""
    out = TubeFrames.empty(len(lines.points), lines.n_curves)
    for c0, c1 in chunks(lines, 1 << 20):
        sub = take_curves(lines, c0, c1)
        p0, p1 = lines.offsets[c0], lines.offsets[c1]
        pixel = pixel_world_size(sub.points, camera) if camera is not None else np.full(len(sub.points), np.inf)
        sides = tube_sides(sub, settings, pixel)
        out.sides[c0:c1] = sides
        radius = sub.radius
        if settings.aa_clamp:
            radius = effective_radius(radius, pixel, np.repeat(sides, sub.counts), settings.max_radius)
        out.radius[p0:p1] = radius
        if settings.uvs or np.any(sub.cyclic):
            arc, total = arc_lengths(sub)
        else:  # read only by UVs and by closed curves' seam twist
            arc, total = np.zeros(len(sub.points)), np.zeros(sub.n_curves)
        out.arc[p0:p1], out.total[c0:c1] = arc, total
        if runtime is None:
            out.t[p0:p1], out.n[p0:p1], out.b[p0:p1] = rotation_minimizing_frames(sub)
    if runtime is not None:
        rotation_minimizing_frames_opencl(runtime, lines, out.arc, out.total, [out.t, out.n, out.b])
    return out


class _Layout:
    """Sizes of the output and the order in which tubes are written."""

    def __init__(self, lines, sides, settings):
        self.lines, self.sides = lines, sides
        self.order = np.argsort(sides, kind="stable")
        counts = lines.counts
        segs = counts - 1 + lines.cyclic
        self.body_v = int(np.sum(counts * sides))
        self.body_f = int(np.sum(segs * sides))
        self.body_c = 4 * self.body_f
        self.body_e = self.body_v + self.body_f
        open_ = ~lines.cyclic
        cap_v = cap_e = cap_f = cap_c = 0
        if settings.caps != "NONE":
            for n in np.unique(sides[open_]):
                ends = 2 * int(np.sum(open_ & (sides == n)))
                dv, de, df, dc = cap_sizes(settings.caps, int(n))
                cap_v, cap_e, cap_f, cap_c = cap_v + ends * dv, cap_e + ends * de, cap_f + ends * df, cap_c + ends * dc
        self.sizes = MeshSizes(vertices=self.body_v + cap_v, faces=self.body_f + cap_f, corners=self.body_c + cap_c,
                               edges=self.body_e + cap_e, materials=bool(np.any(lines.material_index)))

    def units(self, max_points=1 << 19):
        """``(sides, curve ids)`` runs of equal side count with about ``max_points`` points each."""
        sorted_sides = self.sides[self.order]
        counts = self.lines.counts[self.order]
        bounds = np.concatenate(([0], np.nonzero(np.diff(sorted_sides))[0] + 1, [len(self.order)]))
        for g0, g1 in zip(bounds[:-1], bounds[1:], strict=True):
            csum = np.cumsum(counts[g0:g1])
            start = 0
            while start < g1 - g0:
                base = csum[start - 1] if start else 0
                stop = int(np.searchsorted(csum, base + max_points, side="right"))
                stop = min(max(stop, start + 1), g1 - g0)
                yield int(sorted_sides[g0]), self.order[g0 + start:g0 + stop]
                start = stop


def _unit_points(lines, curves):
    """Point ids of ``curves`` in order: a slice when they are consecutive, else an index array."""
    counts = lines.counts[curves]
    if len(curves) and np.all(np.diff(curves) == 1):
        return slice(int(lines.offsets[curves[0]]), int(lines.offsets[curves[-1] + 1])), counts
    starts = lines.offsets[curves]
    local = np.concatenate(([0], np.cumsum(counts)))
    idx = np.arange(local[-1]) - np.repeat(local[:-1] - starts, counts)
    return idx, counts


def _run_topology(lines, curves):
    """Points and segments of one run of curves: a `CurveRun`."""
    pick, counts = _unit_points(lines, curves)
    cyclic = lines.cyclic[curves]
    n_pts = int(counts.sum())
    local = np.concatenate(([0], np.cumsum(counts)))
    last = local[1:] - 1
    # segments: every point but the last of an open curve; the last of a cyclic curve closes it
    has_seg = np.ones(n_pts, bool)
    has_seg[last[~cyclic]] = False
    seg = np.nonzero(has_seg)[0]
    nxt = seg + 1
    closing = np.isin(seg, last[cyclic])
    nxt[closing] = local[:-1][cyclic]
    curve_of_point = np.repeat(np.arange(len(curves)), counts)
    return CurveRun(pick=pick, counts=counts, cyclic=cyclic, n_pts=n_pts, local=local, seg=seg, nxt=nxt,
                    closing=closing, curve_of_point=curve_of_point)


def _segment_u(frames, curves, run):
    """UV u at both ends of every segment: (S,) float32 each (a closing segment ends at u = 1)."""
    arc = frames.arc[run.pick]
    total = frames.total[curves][run.curve_of_point]
    u = arc / np.maximum(total, FLOAT64_TINY)
    return u[run.seg].astype(np.float32), np.where(run.closing, 1.0, u[run.nxt]).astype(np.float32)


def _write_body(mesh, lines, frames, n, curves, cursor, settings, caps, device=None):
    """Write the rings, quads and edges of ``curves`` (all with ``n`` sides) at the cursor; advance it."""
    run = _run_topology(lines, curves)
    u_ends = _segment_u(frames, curves, run) if settings.uvs else None
    if device is not None:
        device.write_body(lines, frames, n, curves, run, cursor, u_ends, np.stack(_ring(n), axis=1))
    else:
        _write_body_numpy(mesh, lines, frames, n, curves, run, cursor, u_ends)
    if settings.caps != "NONE":
        _collect_caps(lines, frames, n, curves, run, cursor, settings, caps)
    cursor.advance(run.n_pts, len(run.seg), n)


def _write_body_numpy(mesh, lines, frames, n, curves, run, cursor, u_ends):
    pick, n_pts, seg, nxt = run.pick, run.n_pts, run.seg, run.nxt
    v0, f0, c0, e0 = cursor.v, cursor.f, cursor.c, cursor.e

    # vertices: radial directions (the normals), then centre + radius * radial
    cos_t, sin_t = (x.astype(np.float32) for x in _ring(n))
    nrm_out = (mesh.point_normals[v0:v0 + n_pts * n].reshape(n_pts, n, 3) if mesh.point_normals is not None
               else np.empty((n_pts, n, 3), np.float32))  # the radial directions, kept only when asked for
    pos_out = mesh.positions[v0:v0 + n_pts * n].reshape(n_pts, n, 3)
    np.multiply(cos_t[None, :, None], frames.n[pick][:, None, :], out=nrm_out)
    np.multiply(sin_t[None, :, None], frames.b[pick][:, None, :], out=pos_out)
    nrm_out += pos_out
    np.multiply(nrm_out, frames.radius[pick][:, None, None], out=pos_out)
    pos_out += lines.points[pick].astype(np.float32)[:, None, :]

    n_seg = len(seg)
    j = np.arange(n, dtype=np.int64)
    j1 = (j + 1) % n
    ring = (v0 + seg * n)[:, None]
    ring_next = (v0 + nxt * n)[:, None]
    cv = mesh.corner_verts[c0:c0 + 4 * n_seg * n].reshape(n_seg, n, 4)
    cv[..., 0], cv[..., 1], cv[..., 2], cv[..., 3] = ring + j, ring + j1, ring_next + j1, ring_next + j
    # edges: ring edges of every point (p*n + j: side j to j+1), then the edges along every segment
    ring_e = mesh.edges[e0:e0 + n_pts * n].reshape(n_pts, n, 2)
    first = (v0 + np.arange(n_pts) * n)[:, None]
    ring_e[..., 0], ring_e[..., 1] = first + j, first + j1
    long_e = mesh.edges[e0 + n_pts * n:e0 + (n_pts + n_seg) * n].reshape(n_seg, n, 2)
    long_e[..., 0], long_e[..., 1] = ring + j, ring_next + j
    ce = mesh.corner_edges[c0:c0 + 4 * n_seg * n].reshape(n_seg, n, 4)
    along = (e0 + (n_pts + np.arange(n_seg)) * n)[:, None]
    ce[..., 0], ce[..., 1] = (e0 + seg * n)[:, None] + j, along + j1
    ce[..., 2], ce[..., 3] = (e0 + nxt * n)[:, None] + j, along + j
    mesh.face_offsets[f0:f0 + n_seg * n] = np.arange(c0, c0 + 4 * n_seg * n, 4, dtype=np.int64)
    if mesh.face_material is not None:
        mesh.face_material[f0:f0 + n_seg * n] = np.repeat(lines.material_index[curves][run.curve_of_point[seg]], n)
    if u_ends is not None:
        u0, u1 = u_ends
        v_lo, v_hi = (j / n).astype(np.float32), ((j + 1) / n).astype(np.float32)
        uv = mesh.corner_uvs[c0:c0 + 4 * n_seg * n].reshape(n_seg, n, 4, 2)
        uv[:, :, 0, 0] = uv[:, :, 1, 0] = u0[:, None]
        uv[:, :, 2, 0] = uv[:, :, 3, 0] = u1[:, None]
        uv[:, :, 0, 1] = uv[:, :, 3, 1] = v_lo
        uv[:, :, 1, 1] = uv[:, :, 2, 1] = v_hi


def _collect_caps(lines, frames, n, curves, run, cursor, settings, caps):
    """Append the caps of the open curves of ``run`` (body rings numbered from ``cursor.v``, ``cursor.e``) to
    ``caps``, numbering their new vertices and edges from ``cursor.cap_v``, ``cursor.cap_e``."""
    open_ = ~run.cyclic
    if not np.any(open_):
        return
    mat = lines.material_index[curves][open_]
    for side, ends in ((-1.0, run.local[:-1][open_]), (1.0, run.local[1:][open_] - 1)):
        p = run.pick.start + ends if isinstance(run.pick, slice) else run.pick[ends]
        ring = CapEnds(centre=lines.points[p], t=frames.t[p].astype(np.float64), n=frames.n[p].astype(np.float64),
                       b=frames.b[p].astype(np.float64), radius=frames.radius[p].astype(np.float64),
                       ring_v=cursor.v + ends * n, ring_e=cursor.e + ends * n, material=mat)
        piece = cap_pieces(settings.caps, n, side, ring, cursor.cap_v, cursor.cap_e, settings.uvs)
        cursor.cap_v += len(piece.positions)
        cursor.cap_e += len(piece.edges)
        caps.append(piece)


def _write_caps(mesh, caps, layout, settings):
    if not caps:
        return
    v, e = layout.body_v, layout.body_e
    f, c = layout.body_f, layout.body_c
    for piece in caps:
        nv, ne = len(piece.positions), len(piece.edges)
        mesh.positions[v:v + nv] = piece.positions
        if mesh.point_normals is not None:
            mesh.point_normals[v:v + nv] = piece.normals
        mesh.edges[e:e + ne] = piece.edges
        v, e = v + nv, e + ne
        for k, faces in enumerate(piece.faces):
            nf, width = faces.shape
            mesh.face_offsets[f:f + nf] = np.arange(c, c + nf * width, width, dtype=np.int64)
            if mesh.face_material is not None:
                mesh.face_material[f:f + nf] = piece.materials[k]
            mesh.corner_verts[c:c + nf * width] = faces.ravel()
            mesh.corner_edges[c:c + nf * width] = piece.corner_edges[k].ravel()
            if settings.uvs:
                mesh.corner_uvs[c:c + nf * width] = piece.uvs[k]
            if settings.caps == "FLAT":
                mesh.corner_normals[c:c + nf * width] = piece.corner_normals[k]
            f, c = f + nf, c + nf * width


def _ring(n):
    theta = 2.0 * np.pi * np.arange(n) / n
    return np.cos(theta), np.sin(theta)
