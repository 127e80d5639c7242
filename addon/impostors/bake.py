"""Baked impostors (issue "Nailboards", item 4): an object rendered by Cycles from N x N directions of an octahedral
(or hemi-octahedral) atlas (`kernels.impostors.octahedral`) into colour, normal and depth atlases, and a card that
faces the camera whose material picks the view of the camera's direction: the impostor works in EEVEE and Cycles
renders without the object. All views are rendered by one worker process, one after the other, as a job of
`addon.render_jobs` (`start_atlas` returns at once; `read_atlas` assembles the views once it is done); the size is
checked against the memory first (`check_atlas_size`)."""

import os
from dataclasses import dataclass

import bpy
import numpy as np

from ...kernels.common.budget import check_bytes
from ...kernels.common.errors import TesseraError
from ...kernels.common.image_io import read_channels
from ...kernels.common.tolerances import ALPHA_FLOOR
from ...kernels.impostors.dilation import dilate_views
from ...kernels.impostors.octahedral import view_directions
from .. import bridge
from ..guarded import run_to_end
from ..node_groups import Graph
from ..render_jobs import RenderJob, job_folder, remove_folder
from .export import PROPERTY
from .worker import check_renderable, start_worker, world_box, write_job

#: Memory per atlas texel: the colour, normal and depth atlases as assembled (float32 RGBA, RGB, float64), their three
#: RGBA float images in Blender and the packed copies of those images.
ATLAS_BYTES_PER_TEXEL = 140


@dataclass
class Atlas:
    """colour (S, S, 4) straight alpha, normal (S, S, 3), depth (S, S) in [0, 1] (0 at the front of the bounding
    sphere, 1 at its back, 1 where empty), S = grid * tile; row 0 at v = 0; centre (3,), size (the bounding sphere's
    diameter), grid, hemi."""

    colour: np.ndarray
    normal: np.ndarray
    depth: np.ndarray
    centre: np.ndarray
    size: float
    grid: int
    hemi: bool


def view_camera(direction, centre, size):
    """Location, forward and up of the orthographic camera of a view (``direction`` from the object to it)."""
    f = np.asarray(direction, np.float64)
    helper = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    right = np.cross(helper, f)
    right /= np.linalg.norm(right)
    return centre + f * size, -f, np.cross(f, right)


def check_atlas_size(grid, tile, budget_bytes):
    """Refuse (`BudgetError`, with the sizes) an atlas of ``grid`` x ``grid`` views of ``tile`` pixels that the memory
    budget or the free memory cannot hold, before anything is rendered."""
    s = int(grid) * int(tile)
    check_bytes(s * s * ATLAS_BYTES_PER_TEXEL, budget_bytes,
                f"The impostor's atlases would be {s:,} x {s:,} texels ({int(grid) ** 2:,} views of {int(tile)} x "
                f"{int(tile)} pixels)", "fewer Views or a smaller View Size")


@dataclass
class AtlasJob:
    """An atlas being rendered: the `render_jobs.RenderJob`, its views (dicts with ``out``, the EXR of view (j, i)
    named ``view_j_i.exr``), and what the atlas needs to be assembled."""

    job: RenderJob
    views: list
    centre: np.ndarray
    size: float
    grid: int
    tile: int
    hemi: bool


def start_atlas(ob, grid=8, tile=128, samples=16, hemi=False, device=None):
    """Start rendering ``ob`` (world space) from every view of the atlas in a worker process: an `AtlasJob`, at once.
    device: the Cycles device (`render_jobs.render_device`; default: the user's)."""
    check_renderable(ob)
    lo, hi = world_box(ob)
    centre, size = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
    if not size > 0:
        raise TesseraError(f"{ob.name!r} has no extent to bake")
    folder = job_folder("impostor")
    try:
        dirs = view_directions(grid, hemi)
        views = []
        for j in range(grid):
            for i in range(grid):
                loc, fwd, up = view_camera(dirs[j, i], centre, size)
                views.append({"location": loc.tolist(), "forward": fwd.tolist(), "up": up.tolist(),
                              "out": os.path.join(folder, f"view_{j}_{i}.exr")})
        log = os.path.join(folder, "worker.log")
        process = start_worker(write_job(ob, folder, tile, samples, size, 2.0 * size, views, device), log)
    except BaseException:
        remove_folder(folder)
        raise
    return AtlasJob(RenderJob(process, folder, len(views), log), views, centre, size, int(grid), int(tile), bool(hemi))


def read_atlas(aj):
    """The `Atlas` of a finished `AtlasJob` (undilated); the job's folder is removed, read or failed."""
    try:
        aj.job.check("Baking the impostor")
        grid, tile, size = aj.grid, aj.tile, aj.size
        s = grid * tile
        colour, normal, depth = np.zeros((s, s, 4), np.float32), np.zeros((s, s, 3), np.float32), np.ones((s, s))
        for view in aj.views:
            j, i = (int(x) for x in os.path.basename(view["out"])[5:-4].split("_"))
            r, g, b, a, z, nx, ny, nz = read_channels(view["out"], "impostor view", (
                "Combined.R", "Combined.G", "Combined.B", "Combined.A", "Depth.Z", "Normal.X", "Normal.Y", "Normal.Z"))
            rows, cols = slice(j * tile, (j + 1) * tile), slice(i * tile, (i + 1) * tile)
            alpha = np.maximum(a, ALPHA_FLOOR)[..., None]
            colour[rows, cols] = np.concatenate([np.stack([r, g, b], -1) / alpha, a[..., None]], -1)
            normal[rows, cols] = np.stack([nx, ny, nz], -1)
            depth[rows, cols] = np.where(a > 0.5, np.clip(z / size - 0.5, 0, 1), 1.0)
    finally:
        aj.job.close()
    return Atlas(colour, normal, depth, aj.centre, size, grid, aj.hemi)


def dilated(atlas, dilation):
    """``atlas`` with each view's colours and normals spread ``dilation`` texels into the empty texels around it
    (`dilate_views`; alpha and depth unchanged): a new `Atlas` (the given one is not changed)."""
    if not dilation:
        return atlas
    covered = atlas.colour[..., 3] > 0
    colour = atlas.colour.copy()
    colour[..., :3] = dilate_views(atlas.colour[..., :3], covered, atlas.grid, dilation)
    normal = dilate_views(atlas.normal, covered, atlas.grid, dilation)
    return Atlas(colour, normal, atlas.depth, atlas.centre, atlas.size, atlas.grid, atlas.hemi)


def bake_atlas(ob, grid=8, tile=128, samples=16, hemi=False, timeout=None, dilation=0, report=None):
    """Render ``ob`` from every view of the atlas and assemble the atlases, waiting for the worker (scripts,
    background mode; ``report(line)`` gets a progress line per view): an `Atlas`. dilation: see `dilated`."""
    aj = start_atlas(ob, grid, tile, samples, hemi)
    try:
        aj.job.wait(report, "Baking impostor views", timeout)
    except BaseException:
        aj.job.cancel()
        raise
    return dilated(read_atlas(aj), dilation)


def packed_float_image(name, pixels):
    """A float image of ``pixels`` (H, W, C <= 4; the channels padded to RGBA), packed into the .blend
    (`bridge.pack_float_image`: bit for bit after save and reload)."""
    return run_to_end(packed_float_image_steps(name, pixels))


def packed_float_image_steps(name, pixels):
    """`packed_float_image` as steps (a generator returning the image): the pixels, then the packing."""
    h, w, c = pixels.shape
    rgba = np.ones((h, w, 4), np.float32)
    rgba[..., :c] = pixels
    image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    try:
        bridge.write_image_pixels(image, rgba)
        yield
        bridge.pack_float_image(image)
    except BaseException:
        bpy.data.images.remove(image)
        raise
    return image


def octahedral_uv(g, direction, hemi):
    """Shader-node arithmetic of `kernels.impostors.octahedral.encode`: direction (a vector socket) -> (u, v)."""
    x, y, z = g.split(direction)
    total = g.math("ADD", g.math("ADD", g.math("ABSOLUTE", x), g.math("ABSOLUTE", y)), g.math("ABSOLUTE", z))
    px, py = g.math("DIVIDE", x, total), g.math("DIVIDE", y, total)
    if hemi:
        u, v = g.math("ADD", px, py), g.math("SUBTRACT", px, py)
    else:
        fold = g.math("LESS_THAN", z, 0.0)
        sx = g.math("SUBTRACT", g.math("MULTIPLY", g.math("GREATER_THAN", px, -1e-30), 2.0), 1.0)
        sy = g.math("SUBTRACT", g.math("MULTIPLY", g.math("GREATER_THAN", py, -1e-30), 2.0), 1.0)
        uf = g.math("MULTIPLY", g.math("SUBTRACT", 1.0, g.math("ABSOLUTE", py)), sx)
        vf = g.math("MULTIPLY", g.math("SUBTRACT", 1.0, g.math("ABSOLUTE", px)), sy)
        u = g.math("ADD", px, g.math("MULTIPLY", fold, g.math("SUBTRACT", uf, px)))
        v = g.math("ADD", py, g.math("MULTIPLY", fold, g.math("SUBTRACT", vf, py)))
    return g.math("ADD", g.math("MULTIPLY", u, 0.5), 0.5), g.math("ADD", g.math("MULTIPLY", v, 0.5), 0.5)


#: Custom property of a card material: what it was built for (`_material_key`); a later card of the same kind copies
#: it (Blender copies a node tree at once, far faster than building its ~120 nodes) and points it at its own atlas.
MATERIAL_KIND = "tessera_card_material"
_MATERIAL_VERSION = 1
_VIEW_LABEL = "Atlas view"


def _material_key(grid, hemi, blend):
    return f"{_MATERIAL_VERSION}/{int(grid)}/{int(bool(hemi))}/{int(bool(blend))}"


def card_material(name, colour_image, grid, hemi, blend=True):
    """The card's material: the view direction (Incoming, world space) picks its atlas cell, the card's UVs the
    texel inside it; the atlas's colour is emitted as it was rendered, its alpha mixes in transparency. blend: the four
    views around the direction are mixed with bilinear weights over the octahedral grid (premultiplied by their
    alpha; a direction at a view's own centre shows that view alone), so the card changes smoothly as it turns; off:
    the nearest view is shown (it switches at cell borders). A local card material of the same kind in the file is
    copied rather than built again."""
    return run_to_end(card_material_steps(name, colour_image, grid, hemi, blend))


def card_material_steps(name, colour_image, grid, hemi, blend=True):
    """`card_material` as steps (a generator returning the material; it yields between parts of the build, each a
    few tens of nodes, so a timer tick never holds the UI long)."""
    key = _material_key(grid, hemi, blend)
    like = next((m for m in bpy.data.materials if m.get(MATERIAL_KIND) == key and m.library is None
                 and m.node_tree is not None), None)
    if like is not None:
        mat = like.copy()
        mat.name = name
        for node in mat.node_tree.nodes:
            if node.type == "TEX_IMAGE" and node.label == _VIEW_LABEL:
                node.image = colour_image
        return mat
    mat = yield from _build_card_material(name, colour_image, grid, hemi, blend)
    mat[MATERIAL_KIND] = key
    return mat


def _build_card_material(name, colour_image, grid, hemi, blend):
    mat = bpy.data.materials.new(name)
    if mat.node_tree is None:
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.clear()
    g = Graph(tree)
    try:
        incoming = g.node("ShaderNodeNewGeometry").outputs["Incoming"]
        u, v = octahedral_uv(g, incoming, hemi)
        yield
        return (yield from _card_views(mat, g, u, v, colour_image, grid, blend))
    except BaseException:
        bpy.data.materials.remove(mat)  # nothing half-built is left
        raise


def _card_views(mat, g, u, v, colour_image, grid, blend):
    n = float(grid)
    card = g.split(g.node("ShaderNodeTexCoord").outputs["UV"])

    def clamp(cell):
        return g.math("MINIMUM", g.math("MAXIMUM", cell, 0.0), n - 1)

    def view(cu, cv):  # the atlas texel of the card's UV inside view (cu, cv)
        atlas = g.xyz(g.math("DIVIDE", g.math("ADD", cu, card[0]), n), g.math("DIVIDE", g.math("ADD", cv, card[1]), n),
                      0.0)
        return g.node("ShaderNodeTexImage", [("Vector", atlas)], image=colour_image, interpolation="Closest",
                      extension="EXTEND", label=_VIEW_LABEL)

    if not blend:
        tex = view(clamp(g.math("FLOOR", g.math("MULTIPLY", u, n))), clamp(g.math("FLOOR", g.math("MULTIPLY", v, n))))
        colour, alpha = tex.outputs["Color"], tex.outputs["Alpha"]
    else:
        gu, gv = (g.math("SUBTRACT", g.math("MULTIPLY", t, n), 0.5) for t in (u, v))  # in cell-centre units
        iu, iv = g.math("FLOOR", gu), g.math("FLOOR", gv)
        fu, fv = g.math("SUBTRACT", gu, iu), g.math("SUBTRACT", gv, iv)
        premultiplied, alpha = None, None
        for du in (0, 1):
            for dv in (0, 1):
                weight = g.math("MULTIPLY", fu if du else g.math("SUBTRACT", 1.0, fu),
                                fv if dv else g.math("SUBTRACT", 1.0, fv))
                tex = view(clamp(g.math("ADD", iu, du)), clamp(g.math("ADD", iv, dv)))
                wa = g.math("MULTIPLY", weight, tex.outputs["Alpha"])
                term = g.vec("SCALE", tex.outputs["Color"], wa)
                premultiplied = term if premultiplied is None else g.vec("ADD", premultiplied, term)
                alpha = wa if alpha is None else g.math("ADD", alpha, wa)
                yield
        colour = g.vec("SCALE", premultiplied, g.math("DIVIDE", 1.0, g.math("MAXIMUM", alpha, ALPHA_FLOOR)))
    emit = g.node("ShaderNodeEmission", [("Color", colour), ("Strength", 1.0)])
    clear = g.node("ShaderNodeBsdfTransparent")
    mix = g.node("ShaderNodeMixShader", [(0, alpha), (1, clear.outputs[0]), (2, emit.outputs[0])])
    out = g.node("ShaderNodeOutputMaterial")
    g.tree.links.new(mix.outputs[0], out.inputs["Surface"])
    if hasattr(mat, "blend_method"):  # EEVEE (4.2 Legacy): let the alpha through
        try:
            mat.blend_method = "HASHED"
        except (AttributeError, TypeError):
            pass
    return mat


def make_card(name, atlas, images, scene_camera, blend=True):
    """A square card as big as the bounding sphere at its centre, facing ``scene_camera`` (Track To) when there is
    one, with the atlas material (``blend``: see `card_material`): a new object (not linked)."""
    return run_to_end(make_card_steps(name, atlas, images, scene_camera, blend))


def make_card_steps(name, atlas, images, scene_camera, blend=True):
    """`make_card` as steps (a generator returning the card; see `card_material_steps`)."""
    mat = yield from card_material_steps(name, images["colour"], atlas.grid, atlas.hemi, blend)
    half = atlas.size / 2
    me = bpy.data.meshes.new(name)
    me.from_pydata([(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)], [], [(0, 1, 2, 3)])
    uv = me.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", np.array([0, 0, 1, 0, 1, 1, 0, 1], np.float32))
    for k, key in enumerate(("normal", "depth")):  # kept by the material (saved with it) for the exporters
        label = f"{key.title()} atlas (for export)"
        node = mat.node_tree.nodes.get(label) or mat.node_tree.nodes.new("ShaderNodeTexImage")
        node.name = node.label = label
        node.image, node.location = images[key], (-1200, -300 * k)
    me.materials.append(mat)
    card = bpy.data.objects.new(name, me)
    card.location = tuple(atlas.centre)
    card[PROPERTY] = {"grid": int(atlas.grid), "hemi": bool(atlas.hemi), "size": float(atlas.size),
                      "blend": bool(blend)}  # what `export.export_card` writes for an engine
    if scene_camera is not None:
        track = card.constraints.new("TRACK_TO")
        track.target, track.track_axis, track.up_axis = scene_camera, "TRACK_Z", "UP_Y"
    return card


def atlas_pixels(atlas):
    """The pixels of the card's three images: {"colour", "normal" (0..1), "depth"} -> (H, W, C) float32."""
    return {"colour": atlas.colour, "normal": atlas.normal * 0.5 + 0.5, "depth": atlas.depth[..., None]}
