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
    stamped per inner segment count. Returns a `Refinement`."""
    edge_f, edge_n, inner_f, inner_n = levels
    outer_n = edge_n[face_edges].astype(np.int64)  # (T, 3)
    n_faces = len(tris)
    point_edge, point_start, edge_point_t = edge_points(edge_f, edge_n, spacing)
    edge_first = n_vertices + point_start
    interior_first = n_vertices + len(point_edge)

    m = np.asarray(inner_n, np.int64)
    n_int = interior_counts(m)
    int_start = np.cumsum(n_int) - n_int
    boundary = outer_n.sum(axis=1)
    side = np.maximum(m - 2, 0)  # segments per side of ring 1
    ring1_loop = np.where(m >= 3, 3 * side, 1)  # ring-1 vertices (a point for m == 2)
    n_strip_inner = np.where(m >= 3, 3 * side, 0)  # the strip's ring-1 triangles
    n_strip_outer = np.where(m >= 2, boundary, 1)  # its boundary triangles (m == 1: the face itself)
    values, inverse = np.unique(m, return_inverse=True)
    templates = [interior_template(int(v)) for v in values]
    groups = group_by_class(inverse.reshape(-1), len(values))
    n_before = np.array([len(t.before) for t in templates], np.int64)[inverse]
    n_after = np.array([len(t.after) for t in templates], np.int64)[inverse]
    tri_counts = n_strip_outer + n_before + n_strip_inner + n_after
    tri_start = np.cumsum(tri_counts) - tri_counts
    n_out = int(tri_counts.sum())

    # Slots: every face's boundary loop, then the interior points in output order.
    b_face, b_pos, b_start = ragged(boundary)
    n_b = len(b_face)
    boundary_slots = Lazy(lambda: boundary_vertices(tris, face_edges, flipped, outer_n, edge_first, edge_point_t,
                                                    n_vertices, b_face, b_pos))  # (ids, barycentrics)
    n_interior = int(n_int.sum())
    index_type = np.int32 if n_b + n_interior + interior_first < 2**31 else np.int64
    interior_base = n_b + int_start  # slot of each face's first interior point
    # Built on first use, so the threads that evaluate the surface build them side by side (see `tessellate`).

    def ids_of(block, boundary_columns):  # output vertex of the slots (k, 3) whose listed columns are boundary slots
        out = block + (interior_first - n_b)  # interior slots are numbered in vertex order
        for col in boundary_columns:
            out[:, col] = boundary_slots.get()[0][block[:, col]]
        return out.astype(index_type, copy=False)

    def slot_faces():
        out = np.empty(n_b + n_interior, index_type)
        out[:n_b] = b_face
        out[n_b:] = np.repeat(np.arange(n_faces, dtype=index_type), n_int)
        return out

    def slot_barys():
        slot_bary = np.empty((n_b + n_interior, 3))
        slot_bary[:n_b] = boundary_slots.get()[1]
        in_bary = slot_bary[n_b:]  # the interior points' rows, written in place
        if spacing == "EQUAL":
            for tpl, faces in zip(templates, groups, strict=True):
                put_blocks(in_bary, int_start[faces], tpl.bary)
        else:
            # The inner partition's parameters once per face and point index; the weights once per point of one side
            # of each ring, rotated onto the other two (the same bits per element as `interior_bary`).
            index = np.arange(int(m.max()) + 1)
            table = point_params(inner_f[:, None], m[:, None], np.minimum(index, m[:, None]), spacing)
            for tpl, faces in zip(templates, groups, strict=True):
                if not len(tpl.ring_k):
                    continue
                params = table[faces]
                weights = np.concatenate(side_weights(params[:, tpl.side_k], params[:, tpl.side_k + tpl.side_j],
                                                      tpl.side_j, tpl.side_len), axis=1)  # (F, 3Q)
                put_blocks(in_bary, int_start[faces],
                           np.take(weights, tpl.column_source.ravel(), axis=1).reshape(len(faces), -1, 3))
        return slot_bary

    def strip():  # slot of every output triangle corner; the strip rows (boundary, ring 1) and unrefined faces
        tri_slots = np.empty((n_out, 3), index_type)
        # Strip, boundary triangles: segment i (local edge e, index j of n) reaches ring-1 vertex `inner_pos`, the
        # number of ring-1 segments whose midpoint comes before its midpoint: e * s, plus those q of side e with
        # (2q + 1) n < (2j + 1) s.
        sf = np.flatnonzero(m[b_face] >= 2)
        f, i = b_face[sf], b_pos[sf]
        e, j = local_edge(i, outer_n[f])
        n = outer_n[f, e]
        s = side[f]
        inner_pos = e * s + ((2 * j + 1) * s + n - 1) // (2 * n)
        a_rows = tri_start[f] + i
        a_block = np.stack([b_start[f] + i, b_start[f] + (i + 1) % boundary[f],
                            interior_base[f] + inner_pos % ring1_loop[f]], axis=1)
        put_rows(tri_slots, a_rows, a_block.astype(index_type))
        a_walk = i + inner_pos
        # Strip, ring-1 triangles: segment q of side c reaches boundary vertex `outer_pos`, the number of boundary
        # segments whose midpoint comes at or before its midpoint.
        c_face, jj, _ = ragged(n_strip_inner)
        s = side[c_face]
        c, q = jj // np.maximum(s, 1), jj % np.maximum(s, 1)
        n_c = outer_n[c_face, c]
        before_c = np.where(c >= 1, outer_n[c_face, 0], 0) + np.where(c >= 2, outer_n[c_face, 1], 0)
        outer_pos = before_c + ((2 * q + 1) * n_c + s) // (2 * s)
        c_rows = tri_start[c_face] + n_strip_outer[c_face] + n_before[c_face] + jj
        c_block = np.stack([interior_base[c_face] + (jj + 1) % ring1_loop[c_face], interior_base[c_face] + jj,
                            b_start[c_face] + outer_pos % boundary[c_face]], axis=1)
        put_rows(tri_slots, c_rows, c_block.astype(index_type))
        c_walk = jj + outer_pos
        # Unrefined faces (m == 1): the boundary loop's three corners.
        lone = np.flatnonzero(m == 1)
        lone_block = b_start[lone][:, None] + np.arange(3)
        tri_slots[tri_start[lone]] = lone_block
        # Interiors, stamped per inner segment count.
        for tpl, faces in zip(templates, groups, strict=True):
            for part, offset in ((tpl.before, n_strip_outer[faces]),
                                 (tpl.after, n_strip_outer[faces] + n_before[faces] + n_strip_inner[faces])):
                put_blocks(tri_slots, tri_start[faces] + offset, part, interior_base[faces])
        # The strip rows' vertex ids (their boundary slots looked up), for the triangles and the output edges.
        return (tri_slots, (f, e, j, n, a_rows, a_walk, ids_of(a_block, (0, 1))),
                (c_face, jj, c_rows, c_walk, ids_of(c_block, (2,))), (lone, ids_of(lone_block, (0, 1, 2))))

    slot_bary, slots = Lazy(slot_barys), Lazy(strip)

    def triangle_ids():  # the slots' vertex ids; only strip rows and unrefined faces hold boundary slots
        tri_slots, (*_, a_rows, _, a_ids), (_, _, c_rows, _, c_ids), (lone, lone_ids) = slots.get()
        out = np.add(tri_slots, interior_first - n_b, dtype=index_type)
        for rows, ids in ((a_rows, a_ids), (c_rows, c_ids), (tri_start[lone], lone_ids)):
            put_rows(out, rows, ids)
        return out

    def output_edges():
        seg_start, seg_ends = edge_segments(edges, edge_n, point_start, n_vertices)
        n_seg = len(seg_ends)
        spokes = n_strip_outer * (m >= 2) + n_strip_inner  # one spoke per strip triangle
        n_tpl = np.array([len(t.edges) for t in templates], np.int64)[inverse]
        counts = spokes + n_tpl
        face_start = n_seg + np.cumsum(counts) - counts
        out = np.empty((n_seg + int(counts.sum()), 2), np.int32)
        out[:n_seg] = seg_ends
        corner = np.empty((n_out, 3), np.int32)
        _, a, (c_face, jj, c_rows, c_walk, c_ids), (lone, _) = slots.get()
        # The strip's spokes, numbered by walk position: a triangle's spoke is the one it starts from (its first
        # boundary and ring-1 vertex); the one it ends on is the next triangle's.
        f, e, j, n, rows, walk, a_ids = a
        base, count = face_start[f], spokes[f]
        canonical = np.where(flipped[f, e], n - 1 - j, j)
        put_rows(corner, rows, np.stack([seg_start[face_edges[f, e]] + canonical, base + (walk + 1) % count,
                                              base + walk], axis=1).astype(np.int32))
        put_rows(out, base + walk, a_ids[:, [0, 2]].astype(np.int32))
        base, count = face_start[c_face], spokes[c_face]
        put_rows(corner, c_rows, np.stack([base + spokes[c_face] + _ring1_edges(templates, inverse[c_face], jj),
                                                base + c_walk, base + (c_walk + 1) % count], axis=1).astype(np.int32))
        put_rows(out, base + c_walk, c_ids[:, [2, 1]].astype(np.int32))
        corner[tri_start[lone]] = seg_start[face_edges[lone]]  # one segment a side
        for tpl, faces in zip(templates, groups, strict=True):
            if not len(tpl.edges):
                continue
            first = face_start[faces] + spokes[faces]
            put_blocks(out, first, tpl.edges, interior_first + int_start[faces])
            for part_edges, offset in (
                    (tpl.before_edges, n_strip_outer[faces]),
                    (tpl.after_edges, n_strip_outer[faces] + n_before[faces] + n_strip_inner[faces])):
                put_blocks(corner, tri_start[faces] + offset, part_edges, first)
        return out, corner

    ref = Refinement(
        n_corners=int(n_vertices), faces=tris, edges=edges,
        edge_point_edge=point_edge.astype(np.int32), edge_point_t=edge_point_t, spacing=spacing,
        edge_level=edge_f, edge_segments=edge_n, inner_level=inner_f, inner_segments=inner_n,
        interior_counts=n_int, n_triangles=n_out, face_edges=face_edges, flipped=flipped,
        arrays=LazyArrays(
            triangles=Lazy(triangle_ids),
            triangle_face=Lazy(lambda: np.repeat(np.arange(n_faces, dtype=np.int32), tri_counts)),
            interior_face=Lazy(lambda: np.repeat(np.arange(n_faces, dtype=np.int32), n_int)),
            interior_bary=Lazy(lambda: slot_bary.get()[n_b:]),
            corner_bary=Lazy(lambda: slot_bary.get()[slots.get()[0]]), output_edges=Lazy(output_edges),
            corner_slots=Lazy(lambda: (slot_faces(), slot_bary.get(), slots.get()[0]))),
    )
    return ref


def _ring1_edges(templates, classes, jj):
    """Template edge id of ring-1 segment ``jj`` (k,) of faces of template classes ``classes`` (k,)."""
    out = np.empty(len(jj), np.int64)
    for index, tpl in enumerate(templates):
        rows = np.flatnonzero(classes == index)
        if len(rows):
            out[rows] = tpl.ring1_edges[jj[rows]]
    return out
