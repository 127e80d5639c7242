"""View-dependent terrain levels ([Nunes 2011, §5.5, corrections 6 and 7]): per-tile edge and inner levels.

Per tile, from the `terrain_analysis.TileTable`:

- ``T_max = clamp(g(HAM_max), 1, L)``, ``g = k·sqrt(HAM)`` (SQRT) or ``1 + k·log2(1 + HAM)`` (LOG): a flat tile
  (HAM_max = 0) gets 1 and is never subdivided.
- ``T_min`` from the allowed screen-space error ε (pixels) and ĥ, the projected distance between the tile's
  highest sample and the coarse tile below it: SEARCH (default) is [Nunes 2011]'s process of Fig. 5.4, the
  smallest power of two whose grid brings the peak within ε pixels; LOG2 is the corrected closed form
  ``log2(ĥ/ε)``; PRINTED is (5-4) as printed, ``log2(ε/ĥ)``. Clamped to ``[1, T_max]``.
- the distance law (5-5..5-7): ``T = T_max`` below ``d_max``, ``T_max·d_max²/d²`` up to
  ``d_min = d_max·sqrt(T_max/T_min)``, ``T_min`` beyond; i.e. ``clamp(T_max·d_max²/d², T_min, T_max)``.

Levels never exceed the tile size in texels (a quad always covers at least a texel, [Nunes 2011] §5.4.2), nor, per
side, that side's length in texels (the last, partial tiles; a map smaller than one tile).
Edge levels use the edge's midpoint (on the terrain surface) and ``max`` of the two tiles' T_max and T_min;
every input is the same for both tiles, and only +, -, ×, / and sqrt touch it, so both tiles compute the
same level bit for bit. The inner level uses the tile centre and the tile's own bounds. Tiles whose bounding
box is outside the view frustum are culled (no triangles).

Coordinates: sample (x, y) is at world ``((x - (W-1)/2)·texel, (y - (H-1)/2)·texel, height)``; the camera is
given in that (terrain-local) space.
"""

from dataclasses import dataclass, replace

import numpy as np

from ..common.camera import product
from ..common.errors import InvalidInputError
from ..common.partition import MAX_LEVEL, segment_counts
from .analysis import HAM_REACH, tile_bounds

MODES = ("OURS", "DISTANCE", "UNIFORM")
G_FUNCTIONS = ("SQRT", "LOG")
T_MIN_RULES = ("SEARCH", "LOG2", "PRINTED")
LEVELS = ("FRACTIONAL", "INTEGER", "POW2")
SIDES = ("BOTTOM", "RIGHT", "TOP", "LEFT")


@dataclass(frozen=True)
class TerrainLod:
    """Level-selection settings.

    mode: OURS (T_max and T_min), DISTANCE (distance law without T_max: [Nunes 2011]'s "straight view-dependent
    LOD"), UNIFORM (max_level everywhere). epsilon: allowed error in pixels. d_max: near distance in world
    units, 0 = automatic (a texel spans ``quad_pixels`` pixels there). levels: FRACTIONAL (continuous,
    fractional-even spacing), INTEGER (ceil) or POW2 (ceil to a power of two: vertices land on texels).
    """

    mode: str = "OURS"
    g: str = "SQRT"
    ham_scale: float = 4.0
    epsilon: float = 3.0
    t_min_rule: str = "SEARCH"
    d_max: float = 0.0
    quad_pixels: float = 4.0
    max_level: int = MAX_LEVEL
    culling: bool = True
    levels: str = "POW2"

    def __post_init__(self):
        for name, allowed in (("mode", MODES), ("g", G_FUNCTIONS), ("t_min_rule", T_MIN_RULES), ("levels", LEVELS)):
            if getattr(self, name) not in allowed:
                raise InvalidInputError(f"{name} must be one of {', '.join(allowed)}; got {getattr(self, name)!r}")
        if not 1 <= self.max_level <= MAX_LEVEL:
            raise InvalidInputError(f"max_level must be in [1, {MAX_LEVEL}]; got {self.max_level!r}")
        for name in ("ham_scale", "epsilon", "quad_pixels"):
            if not (np.isfinite(getattr(self, name)) and getattr(self, name) > 0):
                raise InvalidInputError(f"{name} must be a positive number; got {getattr(self, name)!r}")
        if not (np.isfinite(self.d_max) and self.d_max >= 0):
            raise InvalidInputError(f"d_max must be >= 0 (0 = automatic); got {self.d_max!r}")

    @property
    def spacing(self):
        return "FRACTIONAL_EVEN" if self.levels == "FRACTIONAL" else "EQUAL"


@dataclass
class Selection:
    """Levels for one camera. Per tile (nty, ntx): t_max, t_min, inner (float64: along x), culled (bool); ``edge``
    (nty, ntx, 4) as each tile computed its own sides (BOTTOM, RIGHT, TOP, LEFT). Shared per edge:
    h_edges (nty + 1, ntx) and v_edges (nty, ntx + 1) (rounded levels, what the mesh uses). ``inner_y``: the inner
    level along y where it differs (a partial tile longer one way than the other; None: ``inner``)."""

    t_max: np.ndarray
    t_min: np.ndarray
    edge: np.ndarray
    inner: np.ndarray
    culled: np.ndarray
    h_edges: np.ndarray
    v_edges: np.ndarray
    spacing: str
    inner_y: np.ndarray | None = None

    @property
    def inner_levels(self):
        """Inner levels along x and along y: two (nty, ntx) float64."""
        return self.inner, self.inner if self.inner_y is None else self.inner_y

    @property
    def inner_counts(self):
        """Inner segment counts along x and along y: two (nty, ntx) int."""
        return tuple(segment_counts(level, self.spacing) for level in self.inner_levels)


def to_world(hm, x, y, z):
    """Terrain-local world coordinates of sample coordinates: (..., 3) float64."""
    tx, ty = hm.texel
    return np.stack([(np.asarray(x, np.float64) - (hm.width - 1) * 0.5) * tx,
                     (np.asarray(y, np.float64) - (hm.height - 1) * 0.5) * ty,
                     np.asarray(z, np.float64)], axis=-1)


def g_of_ham(ham_max, settings):
    """T_max from the tile's HAM maximum: (...) -> (...) float64 in [1, max_level]."""
    a = np.maximum(np.asarray(ham_max, np.float64), 0.0)
    g = settings.ham_scale * (np.sqrt(a) if settings.g == "SQRT" else np.log2(1.0 + a))
    if settings.g == "LOG":
        g = 1.0 + g
    return np.clip(g, 1.0, settings.max_level)


def inverse_square_level(d, t_max, t_min, d_max):
    """Seed (5-5..5-7): T_max below d_max, T_max·d_max²/d² between, T_min beyond d_min. (...) float64."""
    d = np.asarray(d, np.float64)
    with np.errstate(divide="ignore"):
        t = t_max * (d_max * d_max) / (d * d)
    return np.where(d <= d_max, t_max, np.minimum(np.maximum(t, t_min), t_max))


def auto_d_max(hm, camera, settings):
    """Distance at which one texel spans ``quad_pixels`` pixels (vertically, through the image centre)."""
    if settings.d_max > 0:
        return float(settings.d_max)
    focal = 0.5 * camera.height * float(np.asarray(camera.projection)[1, 1])
    return hm.mean_texel * focal / settings.quad_pixels


def _clip_matrix(camera):
    return product(camera.projection, camera.view)  # no BLAS: the same bits on every machine


def _project(camera, points):
    """Pixel coordinates (..., 2) and clip w (...) of world points (..., 3)."""
    cx, cy, w = _clip(_clip_matrix(camera), points)
    with np.errstate(divide="ignore", invalid="ignore"):
        px = np.stack([(cx / w + 1) * 0.5 * camera.width, (cy / w + 1) * 0.5 * camera.height], -1)
    return px, w


def _clip(m, points):
    """Clip x, y and w of world points (..., 3) under the 4x4 matrix ``m``: three (...) arrays."""
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    return [m[r, 0] * x + m[r, 1] * y + m[r, 2] * z + m[r, 3] for r in (0, 1, 3)]


def _vertical_error_px(camera, m, top, dz):
    """Pixels between clip points ``top`` (cx, cy, w, each (n,)) and the same world points moved by ``dz`` (n,)
    along z; 0 where either point is behind the camera: (n,) float64."""
    cx, cy, w = top
    bx, by, bw = cx + m[0, 2] * dz, cy + m[1, 2] * dz, w + m[3, 2] * dz
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.hypot((cx / w - bx / bw) * (0.5 * camera.width), (cy / w - by / bw) * (0.5 * camera.height))
    return np.where((w > 0) & (bw > 0) & np.isfinite(err), err, 0.0)


def _distance(eye, xyz):
    """Distances from ``eye`` (3,) of points given as three planes ``xyz`` (3, ...): (...) float64."""
    dx, dy, dz = xyz[0] - eye[0], xyz[1] - eye[1], xyz[2] - eye[2]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def _planes(points):
    """(..., 3) points as contiguous (3, ...) coordinate planes (fast to stream through)."""
    return np.ascontiguousarray(np.moveaxis(points, -1, 0))


def _cached(table, key, make):
    """A camera-independent array derived from the table, computed once (edits clear `TileTable.derived`)."""
    if key not in table.derived:
        table.derived[key] = make()
    return table.derived[key]


def _peak_grid_points(table, xs, ys, levels):
    """The corners of the grid cell around each tile's peak for each of ``levels``: x and y lists of 4 (nty, ntx) arrays
    per level, and per level the peak's place (u, v) in its cell."""
    (x0, x1), (y0, y1) = xs, ys
    px, py = table.peak_x.astype(np.float64), table.peak_y.astype(np.float64)
    cells, gx, gy = [], [], []
    for level in levels:
        sx, sy = (x1 - x0) / level, (y1 - y0) / level
        fx, fy = (px - x0) / sx, (py - y0) / sy
        i, j = np.minimum(np.floor(fx), level - 1), np.minimum(np.floor(fy), level - 1)
        cells.append((fx - i, fy - j))
        gx0, gy0 = x0 + i * sx, y0 + j * sy
        gx1, gy1 = x0 + (i + 1) * sx, y0 + (j + 1) * sy
        gx += [gx0, gx1, gx0, gx1]
        gy += [gy0, gy0, gy1, gy1]
    return gx, gy, cells


def _heights_at_peak(z, cells):
    """The heights at the peaks from the corner heights ``z`` (4 per level, float64) of `_peak_grid_points`. The grid
    cell around the peak is split along its (i, j)-(i+1, j+1) diagonal, as the mesh splits it."""
    out = []
    for k, (u, v) in enumerate(cells):
        z00, z10, z01, z11 = z[4 * k:4 * k + 4]
        lower = u >= v
        out.append(np.where(lower, z00 + u * (z10 - z00) + v * (z11 - z10), z00 + u * (z11 - z01) + v * (z01 - z00)))
    return out


#: The levels the peak search tries (every power of two up to `MAX_LEVEL`): their grids are read together, once.
_SEARCHED = [1 << k for k in range(MAX_LEVEL.bit_length())]


def _heights(hm, table, xs, ys):
    """Every height the selection reads, in one pass over the map (a file's blocks decoded once for all of them), kept
    in ``table.derived``: each tile's edge midpoints ``("edge", side)`` and centre ``"centre"`` as world coordinate
    planes (3, nty, ntx), and for every searched level the grid under its peak minus the peak ``("peak_dz", level)``
    (`_peak_base`). Returns ``table.derived``."""
    if "centre" in table.derived:
        return table.derived
    (x0, x1), (y0, y1) = xs, ys
    mx, my = (x0 + x1) * 0.5, (y0 + y1) * 0.5
    points = [(mx, y0), (x1, my), (mx, y1), (x0, my), (mx, my)]
    gx, gy, cells = _peak_grid_points(table, xs, ys, _SEARCHED)
    z = hm.sample(np.stack([p[0] for p in points] + gx), np.stack([p[1] for p in points] + gy))
    for side, (px, py) in enumerate(points[:4]):
        table.derived[("edge", side)] = _planes(to_world(hm, px, py, z[side]))
    for lv, height in zip(_SEARCHED, _heights_at_peak(z[5:].astype(np.float64), cells), strict=True):
        table.derived[("peak_dz", lv)] = (height - table.h_max).ravel()
    table.derived["centre"] = _planes(to_world(hm, mx, my, z[4]))  # last: it marks them all read
    return table.derived


def _peak_base(hm, table, xs, ys, level):
    """Flat (nty * ntx,) heights of each tile's level-``level`` grid below its peak, minus the peak height: ``level`` a
    power of two up to `MAX_LEVEL` (what the search tries; read with the others by `_heights`)."""
    return _heights(hm, table, xs, ys)[("peak_dz", level)]


def _peak_clip(hm, table, m):
    """Clip x, y, w of every tile's peak, flat (nty * ntx,) each."""
    top = _cached(table, "peak", lambda: to_world(hm, table.peak_x, table.peak_y, table.h_max).reshape(-1, 3))
    return _clip(m, top)


def _peak_error_px(hm, table, camera, xs, ys, level):
    """Projected vertical error at each tile's peak of a level-``level`` grid over the tile: (nty, ntx) float64."""
    m = _clip_matrix(camera)
    err = _vertical_error_px(camera, m, _peak_clip(hm, table, m), _peak_base(hm, table, xs, ys, level))
    return err.reshape(table.h_max.shape)


def t_min_levels(hm, table, camera, settings, t_max, xs, ys):
    """T_min per tile, clamped to [1, T_max]: (nty, ntx) float64.

    SEARCH tests each power of two only on the tiles no coarser level has brought within ε.
    """
    eps = settings.epsilon
    if settings.t_min_rule == "SEARCH":
        m = _clip_matrix(camera)
        top = _peak_clip(hm, table, m)
        t = np.full(t_max.size, float(settings.max_level))
        todo = np.arange(t_max.size)
        level = 1
        while level <= settings.max_level and len(todo):
            dz = _peak_base(hm, table, xs, ys, level)[todo]
            ok = _vertical_error_px(camera, m, [c[todo] for c in top], dz) <= eps
            t[todo[ok]] = level
            todo = todo[~ok]
            level *= 2
        t = t.reshape(t_max.shape)
    else:
        h_hat = _peak_error_px(hm, table, camera, xs, ys, 1)
        with np.errstate(divide="ignore"):
            ratio = h_hat / eps if settings.t_min_rule == "LOG2" else eps / h_hat
            t = np.log2(np.where(h_hat > 0, ratio, 1.0))
    return np.clip(t, 1.0, t_max)


def box_distance(hm, table, camera):
    """Distance from ``camera``'s eye to the terrain's bounding box (terrain-local units): float, 0 inside."""
    half = np.array([(hm.width - 1) * 0.5, (hm.height - 1) * 0.5]) * hm.texel
    lo = np.array([-half[0], -half[1], float(table.h_min.min())])
    hi = np.array([half[0], half[1], float(table.h_max.max())])
    eye = camera.eye
    return float(np.linalg.norm(eye - np.clip(eye, lo, hi)))


def _culled(hm, table, camera, xs, ys):
    """Tiles whose bounding box lies outside one frustum plane: (nty, ntx) bool.

    Per plane ``p`` (clip ±x, ±y, ±z against w) a box is outside when its corner that maximises ``p`` is: the
    maximum of a linear function over a box is the sum of its per-axis maxima (x per tile column, y per row).
    """
    m = _clip_matrix(camera)
    (x0, x1), (y0, y1) = xs, ys
    tx, ty = hm.texel
    wx = [(x[0] - (hm.width - 1) * 0.5) * tx for x in (x0, x1)]  # (ntx,) each, as in to_world
    wy = [(y[:, 0] - (hm.height - 1) * 0.5) * ty for y in (y0, y1)]  # (nty,) each
    out = np.zeros(x0.shape, bool)
    for axis in range(3):
        for sign in (1.0, -1.0):
            p = m[3] + sign * m[axis]
            top_x = np.maximum(p[0] * wx[0], p[0] * wx[1])
            top_y = np.maximum(p[1] * wy[0], p[1] * wy[1])
            top_z = p[2] * (table.h_max if p[2] > 0 else table.h_min)
            out |= (top_z + top_y[:, None]) + (top_x[None, :] + p[3]) < 0
    return out


def _round(levels, settings):
    f = np.clip(levels, 1.0, settings.max_level)
    if settings.levels == "INTEGER":
        return np.ceil(f)
    if settings.levels == "POW2":
        m, e = np.frexp(f)  # f = m·2^e, m in [0.5, 1): the next power of two is 2^e, or f itself when m = 0.5
        return np.minimum(np.ldexp(1.0, e - (m == 0.5)), settings.max_level)
    return f


def _cap(texels, spacing):
    """The highest level whose segment count fits ``texels`` (...) float64: the length itself, or its even
    floor for FRACTIONAL_EVEN (at least 2, that spacing's fewest segments)."""
    if spacing == "FRACTIONAL_EVEN":
        return np.maximum(2.0 * np.floor(texels / 2.0), 2.0)
    return np.maximum(texels, 1.0)


def _neighbour(a, side, fill):
    """The neighbouring tile's value across ``side`` (fill outside the map): (nty, ntx)."""
    out = np.full_like(a, fill)
    if side == 0:
        out[1:] = a[:-1]
    elif side == 2:
        out[:-1] = a[1:]
    elif side == 3:
        out[:, 1:] = a[:, :-1]
    else:
        out[:, :-1] = a[:, 1:]
    return out


def block_tiles(block, counts):
    """Tile columns and rows of ``block`` = (column, row, columns, rows), one block of an even split of a ``counts`` =
    (ntx, nty) tile grid: two ``range``s (empty where the split has more blocks than tiles). Raises
    `InvalidInputError` for a block outside its split."""
    col, row, cols, rows = (int(v) for v in block)
    if cols < 1 or rows < 1 or not (0 <= col < cols and 0 <= row < rows):
        raise InvalidInputError(f"Block {col}, {row} of a {cols} x {rows} split does not exist: the column must be "
                                "below the columns and the row below the rows, both at least 1")
    ntx, nty = counts
    return range(ntx * col // cols, ntx * (col + 1) // cols), range(nty * row // rows, nty * (row + 1) // rows)


def block_region(block, counts):
    """The tiles a block's levels depend on: the block's own and the ring of tiles around it (each edge level takes the
    larger T_max and T_min of its two tiles), as (tx0, ty0, tx1, ty1), end exclusive, clipped to the ``counts`` =
    (ntx, nty) tile grid. `block_tiles` gives the block."""
    xs, ys = block_tiles(block, counts)
    ntx, nty = counts
    return max(0, xs.start - 1), max(0, ys.start - 1), min(ntx, xs.stop + 1), min(nty, ys.stop + 1)


def block_window(block, counts, tile_size, shape):
    """The samples a block's task reads, as (y0, y1, x0, x1) (rows and columns from the bottom, end exclusive,
    clipped to the map of ``shape`` = (H, W)): its region's tiles (`block_region`) and `analysis.HAM_REACH` samples
    around them."""
    tx0, ty0, tx1, ty1 = block_region(block, counts)
    h, w = shape
    reach = HAM_REACH
    return (max(0, ty0 * tile_size - reach), min(h, ty1 * tile_size + 1 + reach),
            max(0, tx0 * tile_size - reach), min(w, tx1 * tile_size + 1 + reach))


def _region_table(table, region):
    """The tile table of ``region`` (tx0, ty0, tx1, ty1) as a `TileTable` of its own (sample coordinates and the map's
    shape kept), made once per table and region."""
    def make():
        tx0, ty0, tx1, ty1 = region
        sl = (slice(ty0, ty1), slice(tx0, tx1))
        return replace(table, ham_max=table.ham_max[sl], h_min=table.h_min[sl], h_max=table.h_max[sl],
                       peak_x=table.peak_x[sl], peak_y=table.peak_y[sl], derived={})
    return _cached(table, ("region", tuple(region)), make)


def _only_block(sel, region, counts, block):
    """The selection ``sel`` of the tiles of ``region`` laid on the whole ``counts`` = (ntx, nty) tile grid, every tile
    outside ``block`` culled (level 1 outside the region: nothing there is meshed)."""
    tx0, ty0, tx1, ty1 = region
    ntx, nty = counts
    sl = (slice(ty0, ty1), slice(tx0, tx1))

    def laid(values, shape, at):
        out = np.ones(shape, values.dtype)
        out[at] = values
        return out

    xs, ys = block_tiles(block, counts)
    culled = np.ones((nty, ntx), bool)
    culled[ys.start:ys.stop, xs.start:xs.stop] = sel.culled[ys.start - ty0:ys.stop - ty0, xs.start - tx0:xs.stop - tx0]
    return Selection(laid(sel.t_max, (nty, ntx), sl), laid(sel.t_min, (nty, ntx), sl),
                     laid(sel.edge, (nty, ntx, 4), sl), laid(sel.inner, (nty, ntx), sl), culled,
                     laid(sel.h_edges, (nty + 1, ntx), (slice(ty0, ty1 + 1), slice(tx0, tx1))),
                     laid(sel.v_edges, (nty, ntx + 1), (slice(ty0, ty1), slice(tx0, tx1 + 1))), sel.spacing,
                     None if sel.inner_y is None else laid(sel.inner_y, (nty, ntx), sl))


def select(hm, table, camera, settings=TerrainLod(), block=None):
    """Edge and inner levels of every tile for ``camera`` (a `camera.Camera` in terrain-local space).

    With ``camera=None`` the result is view-independent: every level is its T_max (the terrain as close up
    as it ever needs to be), nothing is culled.

    ``block`` = (column, row, columns, rows), one block of an even split (`block_tiles`): every tile outside it is
    culled, and only the block and the ring around it (`block_region`) are looked at, so ``table`` needs only those
    tiles analysed and only their samples are read. Every level is computed per tile from the same inputs as for the
    whole terrain, so the blocks of a split, meshed apart, weld into exactly the whole terrain's mesh.
    """
    if table.shape != (hm.height, hm.width):
        raise InvalidInputError("The tile table was made for a different height map; analyse the map again")
    if block is not None:
        counts = table.counts
        region = block_region(block, counts)
        sel = _select(hm, _region_table(table, region), camera, settings, region[:2])
        return _only_block(sel, region, counts, block)
    return _select(hm, table, camera, settings, (0, 0))


def _select(hm, table, camera, settings, first):
    """`select` over the tiles of ``table``, whose first tile is tile ``first`` = (tx0, ty0) of the map."""
    ntx, nty = table.counts
    tx0, ty0 = first
    ts = table.tile_size
    # "a quad always covers a texel" ([Nunes 2011] §5.4.2): no level above the tile's size in texels
    settings = replace(settings, max_level=min(settings.max_level, ts))
    if settings.mode == "UNIFORM":  # the top level everywhere, whole: one quad per texel, partial tiles included
        settings = replace(settings, levels="INTEGER")
    xb = tile_bounds(np.arange(tx0, tx0 + ntx), ts, hm.width)
    yb = tile_bounds(np.arange(ty0, ty0 + nty), ts, hm.height)
    xs = tuple(np.broadcast_to(b[None, :].astype(np.float64), (nty, ntx)) for b in xb)
    ys = tuple(np.broadcast_to(b[:, None].astype(np.float64), (nty, ntx)) for b in yb)
    top = float(settings.max_level)
    heights = _heights(hm, table, xs, ys)
    if settings.mode == "UNIFORM":
        t_max = np.full((nty, ntx), top)
        t_min = t_max.copy()
    elif settings.mode == "DISTANCE":
        t_max, t_min = np.full((nty, ntx), top), np.ones((nty, ntx))
    elif camera is None:
        t_max = g_of_ham(table.ham_max, settings)
        t_min = t_max
    else:
        t_max = g_of_ham(table.ham_max, settings)
        t_min = t_min_levels(hm, table, camera, settings, t_max, xs, ys)
    if camera is None:  # the distance law at d = 0 everywhere: T_max
        eye, d_max = np.zeros(3), np.inf
    else:
        eye, d_max = camera.eye, auto_d_max(hm, camera, settings)
    (x0, x1), (y0, y1) = xs, ys
    edge = np.empty((nty, ntx, 4))
    for side in range(4):
        p = heights[("edge", side)]
        e_max = np.maximum(t_max, _neighbour(t_max, side, 0.0))
        e_min = np.maximum(t_min, _neighbour(t_min, side, 0.0))
        edge[..., side] = inverse_square_level(_distance(eye, p), e_max, e_min, d_max)
    inner = inverse_square_level(_distance(eye, heights["centre"]), t_max, t_min, d_max)
    if settings.culling and camera is not None:
        culled = _culled(hm, table, camera, xs, ys)
    else:
        culled = np.zeros((nty, ntx), bool)
    # a level at most its length in texels, per side and per axis inside: the tiles of a map smaller than one tile
    # (or the last, partial row and column) never outgrow their full grid, and reach it at the top level
    wx, wy = x1 - x0, y1 - y0
    rounded = np.minimum(_round(edge, settings), _cap(np.stack([wx, wy, wx, wy], -1), settings.spacing))
    inner = _round(inner, settings)
    inner_x = np.minimum(inner, _cap(wx, settings.spacing))
    inner_y = np.minimum(inner, _cap(wy, settings.spacing))
    h_edges = np.concatenate([rounded[:, :, 0], rounded[-1:, :, 2]], axis=0)
    v_edges = np.concatenate([rounded[:, :, 3], rounded[:, -1:, 1]], axis=1)
    return Selection(t_max, t_min, edge, inner_x, culled, h_edges, v_edges, settings.spacing,
                     None if np.array_equal(inner_x, inner_y) else inner_y)
