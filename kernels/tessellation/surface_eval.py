"""Evaluate a patch surface (any polynomial basis) at every vertex of a `Refinement`.

Output vertices come in three groups (see `kernels.tessellation.refine`): input corners (copied), edge points
(evaluated once per mesh edge from that edge's own control, in the canonical direction, so shared
edges are bit-identical from both sides) and interior points (evaluated from their face's control).

Points of the same *class* (edges with the same segment count and level, faces with the same inner
level) sit at the same parameters, so a class is evaluated as one matrix product
``basis (P, K) @ control (K, owners * C)``. When there are too many classes for that to pay (random
adaptive levels), points are evaluated one by one in chunks. Both give the same values up to the
summation order of float64 products (checked in the tests).
"""

import numpy as np

from ..common.rows import put_blocks
from ..common.topology import group_by_class
from .interpolate import normalize_channels, weighted_sum
from .refine_templates import slot_bary, stamp, triangle_starts

#: Use per-class matrix products when there are at most this many classes, or few per owner.
MAX_CLASSES = 256
#: Points per chunk on the point-by-point path (its float64 terms and sums stay in cache).
CHUNK = 1 << 14
#: Points per chunk on the class path (keeps the float64 temporaries in cache before they are rounded).
CHUNK_POINTS = 1 << 15


def _class_path(n_classes, n_owners):
    return n_classes <= MAX_CLASSES or n_classes * 16 <= n_owners


def _evaluate_group(out, first, counts, keys, template_of, all_params, control, basis, unit=False):
    """Evaluate points owned by rows of ``control``; writes ``out[first + ...]``.

    counts: (K,) points per owner, stored contiguously in owner order from ``first``; keys: (K,) class
    of each owner (same key -> same parameters); template_of: ``(owner, start) -> (P, ...)`` parameters
    of one owner's points; all_params: ``() -> (N, ...)`` every point's parameters (the point path);
    control: (K, k, C); basis: callable ``params (P, ...) -> (P, k)``; unit: normalise each value (in
    float64, before rounding).
    """
    n = int(counts.sum())
    if n == 0:
        return
    starts = np.cumsum(counts) - counts
    if keys.min() == keys.max():
        uniq, inverse = keys[:1], np.zeros(len(keys), np.int64)
    else:
        uniq, inverse = np.unique(keys, return_inverse=True)
    channels = control.shape[2]
    if _class_path(len(uniq), len(counts)):
        planes = [np.ascontiguousarray(control[:, :, c]) for c in range(channels)]  # (K, k) per channel
        for owners in group_by_class(inverse, len(uniq)):
            p = int(counts[owners[0]])
            if p == 0:
                continue
            basis_t = np.ascontiguousarray(basis(template_of(owners[0], int(starts[owners[0]]))).T)  # (k, p)
            consecutive = owners[-1] - owners[0] + 1 == len(owners)
            step = max(1, CHUNK_POINTS // p)
            for lo in range(0, len(owners), step):
                chunk = owners[lo : lo + step]
                pick = slice(chunk[0], chunk[-1] + 1) if consecutive else chunk
                vals = [plane[pick] @ basis_t for plane in planes]  # C x (n, p) float64
                if unit:
                    normalize_channels(vals)
                if consecutive:
                    at = first + int(starts[chunk[0]])
                    block = out[at : at + len(chunk) * p].reshape(len(chunk), p, channels)
                else:
                    block = np.empty((len(chunk), p, channels), out.dtype)
                for c in range(channels):
                    block[:, :, c] = vals[c]
                if not consecutive:
                    put_blocks(out, first + starts[chunk], block)
        return
    params = all_params()
    # Per point and channel ``sum_k basis[k] * control[owner, k, c]`` in k order (`weighted_sum`): the products and
    # sums of ``einsum("nk,nkc->nc")``, with each owner's control repeated over its run of points instead of
    # gathering (n, k, C) controls.
    k = control.shape[1]
    table = np.ascontiguousarray(control.transpose(2, 1, 0).reshape(channels * k, -1))  # row c k + j: control[:, j, c]
    bounds = np.append(starts, n)
    for lo in range(0, n, CHUNK):
        hi = min(n, lo + CHUNK)
        # owners [f0, f1) hold points [lo, hi) (f0: the last owner starting at or before lo, the one holding it)
        f0, f1 = int(np.searchsorted(bounds, lo, side="right")) - 1, int(np.searchsorted(bounds, hi, side="left"))
        run = np.diff(np.clip(bounds[f0 : f1 + 1], lo, hi))
        b = np.ascontiguousarray(basis(params[lo:hi]).T)  # (k, n): each term's weights one flat run
        repeated = np.repeat(table[:, f0:f1], run, axis=1)  # (C k, n): each owner's control over its run
        vals = [weighted_sum(zip(b, repeated[c * k : (c + 1) * k], strict=True)) for c in range(channels)]
        if unit:
            normalize_channels(vals)
        block = out[first + lo : first + hi]
        for c in range(channels):
            block[:, c] = vals[c]


def _edge_keys(ref):
    return ref.edge_level if ref.spacing != "EQUAL" else ref.edge_segments.astype(np.float64)


def _inner_keys(ref):
    return ref.inner_level if ref.spacing != "EQUAL" else ref.inner_segments.astype(np.float64)


def evaluate_surface(ref, corner_values, edge_control, edge_basis, face_control, face_basis, unit=False):
    """Values of a patch surface at every output vertex.

    corner_values: (V, C) values at the input vertices (the patches interpolate them);
    edge_control: (E, ke, C) per mesh edge, for the direction ``edges[e, 0] -> edges[e, 1]``;
    edge_basis: ``t (P,) -> (P, ke)``; face_control: (T, kf, C); face_basis: ``bary (P, 3) -> (P, kf)``.
    unit: normalise every value (a normal field); the corner values must then be unit already.
    Returns (n_vertices, C) float32 (evaluated in float64, rounded once).
    """
    channels = face_control.shape[2]
    out = np.empty((ref.n_vertices, channels), dtype=np.float32)
    out[: ref.n_corners] = corner_values
    edge_counts = np.maximum(ref.edge_segments - 1, 0)
    _evaluate_group(out, ref.n_corners, edge_counts, _edge_keys(ref),
                    lambda e, start: ref.edge_point_t[start : start + int(edge_counts[e])],
                    lambda: ref.edge_point_t, edge_control, edge_basis, unit)
    _evaluate_group(out, ref.n_corners + len(ref.edge_point_edge), ref.interior_counts, _inner_keys(ref),
                    ref.interior_template, lambda: ref.interior_bary, face_control, face_basis, unit)
    return out


def evaluate_corners(ref, triangles, face_control, face_basis, out, unit=False):
    """A face field at the corners of some output triangles, written into ``out`` (M, 3, C) at rows ``triangles``.

    triangles: (m,) output triangle ids; face_control: (T, k, C); face_basis as in `evaluate_surface`. Evaluated per
    corner from ``ref.corner_bary`` in float64 blocks, normalised when ``unit``, rounded once into ``out``; for
    fields that differ between the faces of a shared vertex (split normals) on any refinement.
    """
    step = max(1, CHUNK // 3)
    for lo in range(0, len(triangles), step):  # blocks: the gathered controls and products stay small
        tris = triangles[lo : lo + step]
        b = face_basis(ref.corner_bary[tris].reshape(-1, 3)).reshape(len(tris), 3, -1)
        vals = np.einsum("mck,mkd->mcd", b, face_control[ref.triangle_face[tris]])
        if unit:
            normalize_channels([vals[..., c] for c in range(vals.shape[2])])
        out[tris] = vals


def evaluate_corners_by_class(ref, faces, face_control, face_basis, out, unit=False):
    """A face field at every output corner of some faces, for a refinement built per pattern class.

    faces: (S,) ascending face ids; face_control: (S, k, C) their fields; face_basis as in `evaluate_surface`;
    out: (M, 3, C) float32, overwritten at those faces' output triangles. The field is evaluated once per
    vertex slot of each face (one matrix product per class and channel, float64, normalised when ``unit``,
    rounded once) and stamped onto the corners by the class pattern, so corners that share a vertex share the
    value. Equal to ``evaluate_corners`` up to the summation order of three to ten float64 products.
    """
    if len(faces) == 0:
        return
    row_of = np.full(len(ref.faces), -1, np.int64)  # row of each chosen face in face_control, -1 elsewhere
    row_of[faces] = np.arange(len(faces))
    starts = triangle_starts(ref.classes, len(ref.faces))
    channels = face_control.shape[2]
    for cls in ref.classes:
        sub = cls.faces[row_of[cls.faces] >= 0]
        if len(sub) == 0:
            continue
        basis_t = np.ascontiguousarray(face_basis(slot_bary(cls)).T)  # (k, slots)
        n_slots, n_tris = basis_t.shape[1], len(cls.triangles)
        step = max(1, CHUNK_POINTS // n_slots)
        for lo in range(0, len(sub), step):
            part = sub[lo : lo + step]
            control = face_control[row_of[part]]
            vals = [np.ascontiguousarray(control[:, :, c]) @ basis_t for c in range(channels)]  # C x (F, slots)
            if unit:
                normalize_channels(vals)
            table = np.empty((len(part), n_slots, channels), np.float32)
            for c in range(channels):
                table[:, :, c] = vals[c]
            block = stamp(table, cls.triangles.ravel())  # (F, Mt * 3, C)
            rows = (starts[part][:, None] + np.arange(n_tris)).ravel()
            out[rows] = block.reshape(len(part) * n_tris, 3, channels)
