"""Rational Bézier patches split into smaller ones, so that each part of a large patch gets its own levels (a sphere's
patches near their poles need fewer steps around than at the equator), welded as the whole patches were.

A patch is split into ``a x b`` equal parts of its parameters, along u then along v, by blossoming (each part's
control points are the polar forms ``f(s0^(p-r), s1^r)`` of its interval, de Casteljau's triangle with a different
argument on each level; [Piegl 1997, ch. 1]). Parts that meet share their side bitwise (the second one's copy of it is
the first's). Two patches that share a side must split it into as many parts: the counts are made equal over every
chain of shared sides (`consistent_counts`), and each shared side is split once, in its canonical direction, and
written into the parts of every patch that has it (`split_patches`), so the parts' sides are keyed exactly as the
whole patches' were (`kernels.surfaces.bezier_patches.patch_edges`).
"""

import numpy as np

#: Sides of a patch (BOTTOM, RIGHT, TOP, LEFT): the axis their points run along (0: u, 1: v).
SIDE_AXIS = (0, 1, 0, 1)


def split_curves(control, count):
    """Rational Bézier curves split into ``count`` equal parts: control (N, k, d) -> (N, count, k, d). Parts meet
    bitwise (part s + 1 starts with part s's last point). Elementwise arithmetic only, so equal curves give equal
    parts whatever else is in the batch."""
    c = np.asarray(control, np.float64)
    n, k, d = c.shape
    p = k - 1
    t = np.arange(count + 1) / count
    a, b = t[:-1], t[1:]
    out = np.empty((n, count, k, d))
    for r in range(k):
        args = [a] * (p - r) + [b] * r  # the polar form's arguments, one per level
        pts = np.broadcast_to(c[:, None], (n, count, k, d)).copy()
        for level in range(p):
            u = args[level][None, :, None, None]
            pts = (1.0 - u) * pts[:, :, :-1] + u * pts[:, :, 1:]
        out[:, :, r] = pts[:, :, 0]
    out[:, 0, 0] = c[:, 0]  # the ends exactly
    out[:, -1, -1] = c[:, -1]
    out[:, 1:, 0] = out[:, :-1, -1]
    return out


def consistent_counts(want, edge, reversed_):
    """Split counts (P, 2) at least ``want`` (P, 2) and equal along every chain of shared sides. edge (P, 4) the
    edge of each patch side (`PatchEdges.edge`); a side along u of one patch may be a side along v of another."""
    n_p = len(want)
    parent = np.arange(2 * n_p)

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    first = {}
    for q in range(n_p):
        for side in range(4):
            node = 2 * q + SIDE_AXIS[side]
            e = int(edge[q, side])
            if e in first:
                ra, rb = find(first[e]), find(node)
                if ra != rb:
                    parent[ra] = rb
            else:
                first[e] = node
    roots = np.array([find(x) for x in range(2 * n_p)])
    best = np.zeros(2 * n_p, np.int64)
    np.maximum.at(best, roots, np.asarray(want, np.int64).ravel())
    return best[roots].reshape(n_p, 2)


def split_patches(h, counts, edges):
    """Patches h (P, k, k, 4) split into counts (P, 2) parts along u and v (equal along shared sides:
    `consistent_counts`). Returns (parts (P', k, k, 4), parent (P',) int64, box (P', 2, 2) float64: each part's
    ((u0, u1), (v0, v1)) in its parent's parameters). A patch of counts (1, 1) is kept as it is."""
    h = np.asarray(h, np.float64)
    n_p, k = len(h), h.shape[1]
    counts = np.asarray(counts, np.int64)
    parts, parent, box = [], [], []
    # each shared side split once, in its canonical direction
    side_parts = {}
    for q in range(n_p):
        for side in range(4):
            e = int(edges.edge[q, side])
            c = int(counts[q, SIDE_AXIS[side]])
            if (e, c) not in side_parts:
                side_parts[(e, c)] = split_curves(edges.control[e][None], c)[0]  # (c, k, 4)
    for (cu, cv) in np.unique(counts, axis=0):
        ps = np.flatnonzero((counts[:, 0] == cu) & (counts[:, 1] == cv))
        g = h[ps]
        if cu > 1:  # along u: the curves h[:, :, j] for every j
            g = split_curves(g.transpose(0, 2, 1, 3).reshape(-1, k, 4), cu)  # (p * k_v, cu, k_u, 4)
            g = g.reshape(len(ps), k, cu, k, 4).transpose(0, 2, 3, 1, 4)  # (p, cu, k_u, k_v, 4)
        else:
            g = g[:, None]
        if cv > 1:  # along v: the curves g[..., i, :] for every i
            s = split_curves(g.reshape(-1, k, 4), cv)  # (p * cu * k_u, cv, k_v, 4)
            g = s.reshape(len(ps), cu, k, cv, k, 4).transpose(0, 1, 3, 2, 4, 5)  # (p, cu, cv, k_u, k_v, 4)
        else:
            g = g[:, :, None]
        # the parts on the patch's sides take the shared sides' canonical parts
        for local, q in enumerate(ps):
            for side in range(4):
                e = int(edges.edge[q, side])
                axis = SIDE_AXIS[side]
                c = int(counts[q, axis])
                pieces = side_parts[(e, c)]
                if edges.reversed[q, side]:
                    pieces = pieces[::-1, ::-1]
                if side == 0:
                    g[local, :, 0, :, 0] = pieces
                elif side == 2:
                    g[local, :, -1, :, -1] = pieces
                elif side == 1:
                    g[local, -1, :, -1, :] = pieces
                else:
                    g[local, 0, :, 0, :] = pieces
        parts.append(g.reshape(-1, k, k, 4))
        parent.append(np.repeat(ps, cu * cv))
        iu, iv = np.meshgrid(np.arange(cu), np.arange(cv), indexing="ij")
        b = np.stack([np.stack([iu / cu, (iu + 1) / cu], -1), np.stack([iv / cv, (iv + 1) / cv], -1)], -2)
        box.append(np.broadcast_to(b.reshape(-1, 2, 2), (len(ps), cu * cv, 2, 2)).reshape(-1, 2, 2))
    order = np.argsort(np.concatenate(parent), kind="stable")
    return np.concatenate(parts)[order], np.concatenate(parent)[order], np.concatenate(box)[order]
