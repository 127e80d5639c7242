"""The general refinement assembled from shared pieces: faces whose levels all differ, at stamping speed.

A face's triangulation (see `kernels.tessellation.refine`) splits into its *outer strip*, the zipper between the
boundary loop (three segment counts) and ring 1, and its *interior*, rings 1 and inward, whose topology depends on
the inner segment count ``m`` alone. The strip is built for every face at once in closed form: the zipper gives
each segment the vertex the merge walk reaches at its midpoint, and comparing two midpoints ``(j + 1/2) / n`` and
``(q + 1/2) / s`` is an integer comparison. The interior is built once per ``m`` by `refine_general` on a lone
triangle (`interior_template`) and stamped onto the faces with that ``m``; with fractional spacing only its
barycentrics are recomputed per face. Vertex numbering, triangle order and barycentrics are `refine_general`'s,
bit for bit (tests compare both), and the construction names the output edges (the strip's spokes and the
template's edges), so the mesh writer computes none.

Per face, in output order: the strip's boundary triangles (one per boundary segment), the template's triangles
of annulus 1 -> 2, the strip's ring-1 triangles (one per ring-1 segment), then the rest of the template.
"""

import functools
from dataclasses import dataclass

import numpy as np

from ..common.partition import MAX_LEVEL, point_params
from ..common.rows import put_blocks, put_rows
from ..common.topology import group_by_class, ragged
from .refine_general import boundary_vertices, edge_points, interior_counts, local_edge, refine_general, side_weights
from .refine_templates import edge_segments
from .refinement import Lazy, LazyArrays, Refinement


@dataclass(frozen=True)
class InteriorTemplate:
    """Rings 1 and inward of a face with ``m`` inner segments, in interior-local vertex numbers (ring 1 first,
    loop order).

    ring_k, ring_pos: (P,) int64 ring and loop position of each interior vertex; bary: (P, 3) float64 its
    barycentrics with EQUAL spacing; before, after: (Mb, 3), (Ma, 3) int64 the triangles output before and after
    the strip's ring-1 triangles; edges: (K, 2) int64 the edges of those triangles; before_edges, after_edges:
    (Mb, 3), (Ma, 3) int64 the edge leaving each corner; ring1_edges: (L,) int64 the edge from ring-1 vertex
    ``j`` to ``j + 1`` (L ring-1 segments, 0 when ring 1 is a point); side_k, side_j, side_len: (Q,) int64 ring,
    index and side length of the points of one side of every ring (the centre point: side length 0), whose
    `side_weights` give every point's barycentrics by rotation: column_source (P, 3) int64 indexes
    ``[own (Q), b_next (Q), off (Q)]`` for each point's three columns.
    """

    m: int
    ring_k: np.ndarray
    ring_pos: np.ndarray
    bary: np.ndarray
    before: np.ndarray
    after: np.ndarray
    edges: np.ndarray
    before_edges: np.ndarray
    after_edges: np.ndarray
    ring1_edges: np.ndarray
    side_k: np.ndarray
    side_j: np.ndarray
    side_len: np.ndarray
    column_source: np.ndarray


@functools.lru_cache(maxsize=MAX_LEVEL + 1)
def interior_template(m):
    """The `InteriorTemplate` of inner segment count ``m`` (>= 1), from the general construction; built once per
    ``m`` and kept (its arrays are shared: never write to them)."""
    m = int(m)
    empty = np.zeros((0, 3), np.int64)
    if m == 1:  # the face itself, no interior
        z = np.zeros(0, np.int64)
        return InteriorTemplate(m, z, z, np.zeros((0, 3)), empty, empty, np.zeros((0, 2), np.int64), empty, empty,
                                z, z, z, z, empty)
    tris = np.array([[0, 1, 2]], np.int32)
    edges = np.array([[0, 1], [0, 2], [1, 2]], np.int32)
    levels = (np.full(3, float(m)), np.full(3, m, np.int64), np.array([float(m)]), np.array([m], np.int64))
    lone = refine_general(tris, 3, edges, np.array([[0, 2, 1]], np.int32), np.array([[False, False, True]]),
                          levels, "EQUAL")
    first = 3 * m  # 3 corners and 3 (m - 1) edge points come before the interior
    t = lone.triangles.astype(np.int64)
    strip = np.flatnonzero((t < first).any(axis=1))
    n_ring1 = 3 * (m - 2)  # ring-1 segments (0 for m == 2: ring 1 is a point)
    c0 = first if m == 2 else int(strip[first])  # first triangle of the strip's ring-1 part
    if not (np.array_equal(strip[:first], np.arange(first))
            and np.array_equal(strip[first:], np.arange(c0, c0 + n_ring1))):
        raise AssertionError(f"unexpected triangle order in the pattern of inner level {m}")
    before, after = t[first:c0] - first, t[c0 + n_ring1:] - first
    ring_sizes = np.array([3 * (m - 2 * k) if m > 2 * k else 1 for k in range(1, m // 2 + 1)], np.int64)
    ring, ring_pos, _ = ragged(ring_sizes)
    n_points = len(ring)
    local = np.concatenate([before, after])
    a, b = local, np.roll(local, -1, axis=1)
    keys = (np.minimum(a, b) * n_points + np.maximum(a, b)).ravel()
    uniq, inverse = np.unique(keys, return_inverse=True)
    corner_edges = inverse.reshape(local.shape).astype(np.int64)
    ring1 = np.arange(n_ring1)
    ring1_next = (ring1 + 1) % max(n_ring1, 1)
    ring1_keys = np.minimum(ring1, ring1_next) * n_points + np.maximum(ring1, ring1_next)
    ring1_edges = np.searchsorted(uniq, ring1_keys)
    if n_ring1 and not np.array_equal(uniq[ring1_edges], ring1_keys):
        raise AssertionError(f"a ring-1 segment of inner level {m} is no edge of the interior")
    k = ring + 1
    side = m - 2 * k
    # one side of each ring: (k, j) for j < side, or the centre point (k, 0) with side 0
    side_k = np.concatenate([np.full(max(m - 2 * r, 1), r) for r in range(1, m // 2 + 1)])
    side_j = np.concatenate([np.arange(max(m - 2 * r, 1)) for r in range(1, m // 2 + 1)])
    side_len = m - 2 * side_k
    first_of_ring = np.cumsum([max(m - 2 * r, 1) for r in range(1, m // 2 + 1)])
    q = (first_of_ring - np.maximum(m - 2 * np.arange(1, m // 2 + 1), 1))[k - 1] + ring_pos % np.maximum(side, 1)
    c = ring_pos // np.maximum(side, 1)
    n_side = len(side_k)
    column_source = np.empty((n_points, 3), np.int64)
    for col in range(3):  # column c takes own, c + 1 b_next, c + 2 off
        column_source[:, col] = q + n_side * ((col - c) % 3)
    column_source[side == 0] = q[side == 0][:, None]  # the centre: own, 1/3, in every column
    arrays = [np.array(a) for a in (k, ring_pos, lone.interior_bary, before, after,
                                    np.stack([uniq // n_points, uniq % n_points], axis=1), corner_edges[:len(before)],
                                    corner_edges[len(before):], ring1_edges, side_k, side_j, side_len, column_source)]
    for a in arrays:
        a.flags.writeable = False  # cached and shared by every call
    return InteriorTemplate(m, *arrays)


def refine_split(tris, n_vertices, edges, face_edges, flipped, levels, spacing):
    """Same contract and output as `refine_general` (and output edges): outer strips in closed form, interiors
    stamped per inner segment count. Returns a `Refinement` whose arrays are built on first use, so the threads that
    evaluate the surface build them side by side (see `tessellate`)."""
    split = _SplitFaces(tris, n_vertices, edges, face_edges, flipped, levels, spacing)
    edge_f, edge_n, inner_f, inner_n = levels
    slot_bary, slots = Lazy(split.slot_barys), Lazy(split.strip)
    split.slots = slots
    n_faces, n_b = len(tris), split.n_b
    return Refinement(
        n_corners=int(n_vertices), faces=tris, edges=edges,
        edge_point_edge=split.point_edge.astype(np.int32), edge_point_t=split.edge_point_t, spacing=spacing,
        edge_level=edge_f, edge_segments=edge_n, inner_level=inner_f, inner_segments=inner_n,
        interior_counts=split.n_int, n_triangles=split.n_out, face_edges=face_edges, flipped=flipped,
        arrays=LazyArrays(
            triangles=Lazy(split.triangle_ids),
            triangle_face=Lazy(lambda: np.repeat(np.arange(n_faces, dtype=np.int32), split.tri_counts)),
            interior_face=Lazy(lambda: np.repeat(np.arange(n_faces, dtype=np.int32), split.n_int)),
            interior_bary=Lazy(lambda: slot_bary.get()[n_b:]),
            corner_bary=Lazy(lambda: slot_bary.get()[slots.get()[0]]), output_edges=Lazy(split.output_edges),
            corner_slots=Lazy(lambda: (split.slot_faces(), slot_bary.get(), slots.get()[0]))),
    )


class _SplitFaces:
    """What every part of one `refine_split` shares: the faces' counts and where each face's triangles, boundary
    slots and interior points start. Slots number every face's boundary loop (``n_b`` of them), then the interior
    points in output order; a triangle corner is first a slot, its vertex id looked up when asked for."""

    def __init__(self, tris, n_vertices, edges, face_edges, flipped, levels, spacing):
        edge_f, edge_n, inner_f, inner_n = levels
        self.tris, self.n_vertices, self.edges = tris, n_vertices, edges
        self.face_edges, self.flipped = face_edges, flipped
        self.edge_n, self.inner_f, self.spacing = edge_n, inner_f, spacing
        self.outer_n = edge_n[face_edges].astype(np.int64)  # (T, 3)
        self.point_edge, self.point_start, self.edge_point_t = edge_points(edge_f, edge_n, spacing)
        self.edge_first = n_vertices + self.point_start
        self.interior_first = n_vertices + len(self.point_edge)
        m = self.m = np.asarray(inner_n, np.int64)
        self.n_int = interior_counts(m)
        self.int_start = np.cumsum(self.n_int) - self.n_int
        self.boundary = self.outer_n.sum(axis=1)
        self.side = np.maximum(m - 2, 0)  # segments per side of ring 1
        self.ring1_loop = np.where(m >= 3, 3 * self.side, 1)  # ring-1 vertices (a point for m == 2)
        self.n_strip_inner = np.where(m >= 3, 3 * self.side, 0)  # the strip's ring-1 triangles
        self.n_strip_outer = np.where(m >= 2, self.boundary, 1)  # its boundary triangles (m == 1: the face itself)
        values, self.inverse = np.unique(m, return_inverse=True)
        self.templates = [interior_template(int(v)) for v in values]
        self.groups = group_by_class(self.inverse.reshape(-1), len(values))
        self.n_before = np.array([len(t.before) for t in self.templates], np.int64)[self.inverse]
        self.n_after = np.array([len(t.after) for t in self.templates], np.int64)[self.inverse]
        self.tri_counts = self.n_strip_outer + self.n_before + self.n_strip_inner + self.n_after
        self.tri_start = np.cumsum(self.tri_counts) - self.tri_counts
        self.n_out = int(self.tri_counts.sum())
        self.b_face, self.b_pos, self.b_start = ragged(self.boundary)
        self.n_b = len(self.b_face)
        self.boundary_slots = Lazy(lambda: boundary_vertices(
            tris, face_edges, flipped, self.outer_n, self.edge_first, self.edge_point_t, n_vertices, self.b_face,
            self.b_pos))  # (ids, barycentrics)
        self.n_interior = int(self.n_int.sum())
        total = self.n_b + self.n_interior + self.interior_first
        self.index_type = np.int32 if total < 2**31 else np.int64
        self.interior_base = self.n_b + self.int_start  # slot of each face's first interior point
        self.slots = None  # the Lazy of `strip`, set by `refine_split`

    def ids_of(self, block, boundary_columns):
        """Output vertex of the slots (k, 3) whose listed columns are boundary slots."""
        out = block + (self.interior_first - self.n_b)  # interior slots are numbered in vertex order
        for col in boundary_columns:
            out[:, col] = self.boundary_slots.get()[0][block[:, col]]
        return out.astype(self.index_type, copy=False)

    def slot_faces(self):
        out = np.empty(self.n_b + self.n_interior, self.index_type)
        out[:self.n_b] = self.b_face
        out[self.n_b:] = np.repeat(np.arange(len(self.tris), dtype=self.index_type), self.n_int)
        return out

    def slot_barys(self):
        """Barycentrics (n_b + n_interior, 3) of every slot."""
        slot_bary = np.empty((self.n_b + self.n_interior, 3))
        slot_bary[:self.n_b] = self.boundary_slots.get()[1]
        in_bary = slot_bary[self.n_b:]  # the interior points' rows, written in place
        if self.spacing == "EQUAL":
            for tpl, faces in zip(self.templates, self.groups, strict=True):
                put_blocks(in_bary, self.int_start[faces], tpl.bary)
            return slot_bary
        # The inner partition's parameters once per face and point index; the weights once per point of one side of
        # each ring, rotated onto the other two (the same bits per element as `interior_bary`).
        m = self.m
        index = np.arange(int(m.max()) + 1)
        table = point_params(self.inner_f[:, None], m[:, None], np.minimum(index, m[:, None]), self.spacing)
        for tpl, faces in zip(self.templates, self.groups, strict=True):
            if not len(tpl.ring_k):
                continue
            params = table[faces]
            weights = np.concatenate(side_weights(params[:, tpl.side_k], params[:, tpl.side_k + tpl.side_j],
                                                  tpl.side_j, tpl.side_len), axis=1)  # (F, 3Q)
            put_blocks(in_bary, self.int_start[faces],
                       np.take(weights, tpl.column_source.ravel(), axis=1).reshape(len(faces), -1, 3))
        return slot_bary

    def _boundary_rows(self, tri_slots):
        """The strip's boundary triangles into ``tri_slots``: segment i (local edge e, index j of n) reaches ring-1
        vertex `inner_pos`, the number of ring-1 segments whose midpoint comes before its midpoint: e * s, plus those
        q of side e with (2q + 1) n < (2j + 1) s. Returns (f, e, j, n, rows, walk, vertex ids)."""
        sf = np.flatnonzero(self.m[self.b_face] >= 2)
        f, i = self.b_face[sf], self.b_pos[sf]
        e, j = local_edge(i, self.outer_n[f])
        n = self.outer_n[f, e]
        s = self.side[f]
        inner_pos = e * s + ((2 * j + 1) * s + n - 1) // (2 * n)
        rows = self.tri_start[f] + i
        block = np.stack([self.b_start[f] + i, self.b_start[f] + (i + 1) % self.boundary[f],
                          self.interior_base[f] + inner_pos % self.ring1_loop[f]], axis=1)
        put_rows(tri_slots, rows, block.astype(self.index_type))
        return f, e, j, n, rows, i + inner_pos, self.ids_of(block, (0, 1))

    def _ring1_rows(self, tri_slots):
        """The strip's ring-1 triangles into ``tri_slots``: segment q of side c reaches boundary vertex `outer_pos`,
        the number of boundary segments whose midpoint comes at or before its midpoint. Returns (faces, jj, rows,
        walk, vertex ids)."""
        c_face, jj, _ = ragged(self.n_strip_inner)
        s = self.side[c_face]
        c, q = jj // np.maximum(s, 1), jj % np.maximum(s, 1)
        n_c = self.outer_n[c_face, c]
        before_c = np.where(c >= 1, self.outer_n[c_face, 0], 0) + np.where(c >= 2, self.outer_n[c_face, 1], 0)
        outer_pos = before_c + ((2 * q + 1) * n_c + s) // (2 * s)
        rows = self.tri_start[c_face] + self.n_strip_outer[c_face] + self.n_before[c_face] + jj
        block = np.stack([self.interior_base[c_face] + (jj + 1) % self.ring1_loop[c_face],
                          self.interior_base[c_face] + jj, self.b_start[c_face] + outer_pos % self.boundary[c_face]],
                         axis=1)
        put_rows(tri_slots, rows, block.astype(self.index_type))
        return c_face, jj, rows, jj + outer_pos, self.ids_of(block, (2,))

    def strip(self):
        """The slot of every output triangle corner (n_out, 3), and the strip rows (boundary, ring 1) and unrefined
        faces with their vertex ids, for the triangles and the output edges."""
        tri_slots = np.empty((self.n_out, 3), self.index_type)
        a = self._boundary_rows(tri_slots)
        c = self._ring1_rows(tri_slots)
        lone = np.flatnonzero(self.m == 1)  # unrefined faces: the boundary loop's three corners
        lone_block = self.b_start[lone][:, None] + np.arange(3)
        tri_slots[self.tri_start[lone]] = lone_block
        for tpl, faces in zip(self.templates, self.groups, strict=True):  # interiors, stamped per inner count
            for part, offset in ((tpl.before, self.n_strip_outer[faces]),
                                 (tpl.after, self.n_strip_outer[faces] + self.n_before[faces]
                                  + self.n_strip_inner[faces])):
                put_blocks(tri_slots, self.tri_start[faces] + offset, part, self.interior_base[faces])
        return tri_slots, a, c, (lone, self.ids_of(lone_block, (0, 1, 2)))

    def triangle_ids(self):
        """The slots' vertex ids; only strip rows and unrefined faces hold boundary slots."""
        tri_slots, (*_, a_rows, _, a_ids), (_, _, c_rows, _, c_ids), (lone, lone_ids) = self.slots.get()
        out = np.add(tri_slots, self.interior_first - self.n_b, dtype=self.index_type)
        for rows, ids in ((a_rows, a_ids), (c_rows, c_ids), (self.tri_start[lone], lone_ids)):
            put_rows(out, rows, ids)
        return out

    def output_edges(self):
        """The output edges (E', 2) int32 and the edge leaving each triangle corner (n_out, 3) int32."""
        seg_start, seg_ends = edge_segments(self.edges, self.edge_n, self.point_start, self.n_vertices)
        n_seg = len(seg_ends)
        m, tri_start, templates = self.m, self.tri_start, self.templates
        spokes = self.n_strip_outer * (m >= 2) + self.n_strip_inner  # one spoke per strip triangle
        n_tpl = np.array([len(t.edges) for t in templates], np.int64)[self.inverse]
        counts = spokes + n_tpl
        face_start = n_seg + np.cumsum(counts) - counts
        out = np.empty((n_seg + int(counts.sum()), 2), np.int32)
        out[:n_seg] = seg_ends
        corner = np.empty((self.n_out, 3), np.int32)
        _, a, (c_face, jj, c_rows, c_walk, c_ids), (lone, _) = self.slots.get()
        # The strip's spokes, numbered by walk position: a triangle's spoke is the one it starts from (its first
        # boundary and ring-1 vertex); the one it ends on is the next triangle's.
        f, e, j, n, rows, walk, a_ids = a
        base, count = face_start[f], spokes[f]
        canonical = np.where(self.flipped[f, e], n - 1 - j, j)
        put_rows(corner, rows, np.stack([seg_start[self.face_edges[f, e]] + canonical, base + (walk + 1) % count,
                                         base + walk], axis=1).astype(np.int32))
        put_rows(out, base + walk, a_ids[:, [0, 2]].astype(np.int32))
        base, count = face_start[c_face], spokes[c_face]
        put_rows(corner, c_rows, np.stack([base + spokes[c_face] + _ring1_edges(templates, self.inverse[c_face], jj),
                                           base + c_walk, base + (c_walk + 1) % count], axis=1).astype(np.int32))
        put_rows(out, base + c_walk, c_ids[:, [2, 1]].astype(np.int32))
        corner[tri_start[lone]] = seg_start[self.face_edges[lone]]  # one segment a side
        for tpl, faces in zip(templates, self.groups, strict=True):
            if not len(tpl.edges):
                continue
            first = face_start[faces] + spokes[faces]
            put_blocks(out, first, tpl.edges, self.interior_first + self.int_start[faces])
            for part_edges, offset in (
                    (tpl.before_edges, self.n_strip_outer[faces]),
                    (tpl.after_edges, self.n_strip_outer[faces] + self.n_before[faces] + self.n_strip_inner[faces])):
                put_blocks(corner, tri_start[faces] + offset, part_edges, first)
        return out, corner


def _ring1_edges(templates, classes, jj):
    """Template edge id of ring-1 segment ``jj`` (k,) of faces of template classes ``classes`` (k,)."""
    out = np.empty(len(jj), np.int64)
    for index, tpl in enumerate(templates):
        rows = np.flatnonzero(classes == index)
        if len(rows):
            out[rows] = tpl.ring1_edges[jj[rows]]
    return out
