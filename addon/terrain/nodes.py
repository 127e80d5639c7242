"""The geometry-nodes group "Tessera Terrain": a height-map image as a terrain mesh in the modifier stack, with a
distance-based level per tile for the scene's active camera, crack-free; no add-on needed to evaluate it. Numpy
reference: `kernels.terrain.lod.select` in its ``DISTANCE`` and ``UNIFORM`` modes with power-of-two levels, and
`kernels.terrain.heightmap_io.HeightMap.sample` for the heights.

The map (W x H samples, channel 0 = R, row 0 at the bottom) is cut into tiles of ``Tile Size`` texels, as
`kernels.terrain.analysis.tile_bounds` cuts it. Per tile, as the kernel does:

- the inner level from the distance of the tile centre (on the surface) to the camera, each side's level from the
  distance of the side's midpoint (so both tiles of a side compute the same level from the same data): the
  distance law ``clamp(T_max d_max^2 / d^2, 1, T_max)`` (T_max below d_max), ``T_max`` = Max Level capped by the
  tile size; Uniform: T_max everywhere. Levels are rounded up to a power of two and capped by the side's length
  in texels.
- the tile is a grid of ``R = max(inner, sides)`` quads a side (one grid per R, built once in a Repeat zone and
  instanced per tile); the points of each side are then moved onto that side's own level (point m of L at
  ``x0 + m (x1 - x0) / L``, computed by both tiles with the same operations, so bit for bit the same), and Merge by
  Distance (within 1e-4 texel; distinct points are at least 1/64 texel apart) welds what now coincides:
  neighbouring tiles share every side point, no T-junction, no crack; strips along a coarser side become
  triangles.

Heights are sampled (Linear, Extend) at texel coordinates (X + 0.5) / W, so at integer X the texel itself;
positions are the kernel's terrain-local ``((X - (W-1)/2) texel, (Y - (H-1)/2) texel, h scale)``; UVs
``(X / (W-1), Y / (H-1))``.

What only ``terrain_bake`` does (the README lists it): T_max from the height acceleration map and T_min from the
screen-space error (the group has no whole-map analysis), frustum culling, integer and fractional levels, an inner
level below its sides' (the kernel zips strips; the group refines a tile to its finest side), raw and out-of-core
maps, and heights at the file's own precision (the group reads what Blender's image holds).
"""

from ...kernels.common.partition import MAX_LEVEL  # the largest level: quads a tile side
from ..node_groups import Graph, GroupSpec, register_group, socket

GROUP_NAME = "Tessera Terrain"
VERSION = 3
_TILE = ("tessera_x0", "tessera_y0", "tessera_wx", "tessera_wy", "tessera_r", "tessera_bottom", "tessera_right",
         "tessera_top", "tessera_left")
_BORDER = "tessera_border"


def _interface(tree):
    socket(tree, "Geometry", "NodeSocketGeometry", description="Not used: the terrain replaces it")
    socket(tree, "Image", "NodeSocketImage", description="The height map (first channel; set its colour space "
                                                         "to Non-Color)")
    socket(tree, "Texel Size", "NodeSocketFloat", default=1.0, min_value=1e-6, subtype="DISTANCE",
           description="Distance between neighbouring samples")
    socket(tree, "Height Scale", "NodeSocketFloat", default=100.0, subtype="DISTANCE",
           description="Height of a full-scale sample (1.0 in the image)")
    socket(tree, "Tile Size", "NodeSocketInt", default=64, min_value=2, max_value=1024, subtype="PIXEL",
           description="Texels per tile side")
    socket(tree, "Level Mode", "NodeSocketMenu",
           description="Distance: finer near the scene's active camera (without the roughness analysis of "
                       "Bake Terrain); Uniform: Max Level everywhere")
    socket(tree, "Max Level", "NodeSocketInt", default=MAX_LEVEL, min_value=1, max_value=MAX_LEVEL,
           description="Quads per tile side at most (capped by the tile size)")
    socket(tree, "Detail Distance", "NodeSocketFloat", default=100.0, min_value=1e-6, subtype="DISTANCE",
           description="Distance from the camera within which tiles get Max Level; beyond, the level falls with "
                       "the square of the distance")
    socket(tree, "UV Map", "NodeSocketString", default="UVMap", description="Name of the UVs (X/(W-1), Y/(H-1))")
    socket(tree, "Material", "NodeSocketMaterial", description="The terrain's material (a new mesh has none)")
    socket(tree, "Geometry", "NodeSocketGeometry", in_out="OUTPUT", description="The terrain mesh")


class _Terrain:
    """The builder's state: the graph, the group's inputs, and the map's size."""

    def __init__(self, tree):
        self.g = Graph(tree)
        _interface(tree)
        self.gi, self.go = self.g.node("NodeGroupInput"), self.g.node("NodeGroupOutput")
        info = self.g.node("GeometryNodeImageInfo", [(0, self.inp("Image"))])
        self.width, self.height = info.outputs["Width"], info.outputs["Height"]

    def inp(self, name):
        return self.gi.outputs[name]

    def sample(self, x, y):
        """World height at texel coordinates (x, y) (fields): bilinear, clamped at the edges."""
        g = self.g
        uv = g.xyz(g.math("DIVIDE", g.math("ADD", x, 0.5), self.width),
                   g.math("DIVIDE", g.math("ADD", y, 0.5), self.height), 0.0)
        color = g.node("GeometryNodeImageTexture", [("Image", self.inp("Image")), ("Vector", uv)],
                       interpolation="Linear", extension="EXTEND").outputs[0]
        return g.math("MULTIPLY", g.split(color)[0], self.inp("Height Scale"))

    def world(self, x, y, z):
        """`kernels.terrain.lod.to_world`: terrain-local position of texel coordinates (fields)."""
        g = self.g
        texel = self.inp("Texel Size")
        cx = g.math("MULTIPLY", g.math("SUBTRACT", self.width, 1.0), 0.5)
        cy = g.math("MULTIPLY", g.math("SUBTRACT", self.height, 1.0), 0.5)
        return g.xyz(g.math("MULTIPLY", g.math("SUBTRACT", x, cx), texel),
                     g.math("MULTIPLY", g.math("SUBTRACT", y, cy), texel), z)

    def top_level(self):
        """T_max: Max Level, at most the tile size."""
        return self.g.math("MINIMUM", self.inp("Max Level"), self.inp("Tile Size"))

    def level(self, x, y, cap, uniform, eye):
        """The rounded level at the surface point over texel (x, y), at most ``cap`` (a side's texels)."""
        g = self.g
        top = self.top_level()
        d = g.vec("DISTANCE", self.world(x, y, self.sample(x, y)), eye, out=1)
        d_max = self.inp("Detail Distance")
        law = g.math("DIVIDE", g.math("MULTIPLY", top, g.math("MULTIPLY", d_max, d_max)), g.math("MULTIPLY", d, d))
        far = g.math("MINIMUM", g.math("MAXIMUM", law, 1.0), top)
        t = g.switch("FLOAT", g.math("LESS_THAN", d_max, d), top, far)  # d <= d_max: T_max
        t = g.switch("FLOAT", uniform, t, top)
        return g.math("MINIMUM", g.math("MINIMUM", _pow2_ceiling(g, g.math("MAXIMUM", t, 1.0)), top),
                      g.math("MAXIMUM", cap, 1.0))

    def tiles(self):
        """One point per tile with its bounds (texels), side levels and grid size R stored on it."""
        g = self.g
        ts = self.inp("Tile Size")
        ntx = g.math("CEIL", g.math("DIVIDE", g.math("SUBTRACT", self.width, 1.0), ts))
        nty = g.math("CEIL", g.math("DIVIDE", g.math("SUBTRACT", self.height, 1.0), ts))
        points = g.node("GeometryNodePoints", [("Count", g.math("MULTIPLY", ntx, nty))]).outputs[0]
        index = g.input("GeometryNodeInputIndex")
        x0 = g.math("MULTIPLY", g.math("FLOORED_MODULO", index, ntx), ts)
        y0 = g.math("MULTIPLY", g.math("FLOOR", g.math("DIVIDE", index, ntx)), ts)
        x1 = g.math("MINIMUM", g.math("ADD", x0, ts), g.math("SUBTRACT", self.width, 1.0))
        y1 = g.math("MINIMUM", g.math("ADD", y0, ts), g.math("SUBTRACT", self.height, 1.0))
        wx, wy = g.math("SUBTRACT", x1, x0), g.math("SUBTRACT", y1, y0)
        mx, my = g.math("MULTIPLY", g.math("ADD", x0, x1), 0.5), g.math("MULTIPLY", g.math("ADD", y0, y1), 0.5)
        uniform = g.menu("BOOLEAN", self.inp("Level Mode"), [("Distance", False), ("Uniform", True)])
        camera = g.node("GeometryNodeObjectInfo", [(0, g.input("GeometryNodeInputActiveCamera"))],
                        transform_space="RELATIVE")
        eye = camera.outputs["Location"]
        sides = [self.level(mx, y0, wx, uniform, eye), self.level(x1, my, wy, uniform, eye),
                 self.level(mx, y1, wx, uniform, eye), self.level(x0, my, wy, uniform, eye)]
        r = self.level(mx, my, g.math("MINIMUM", wx, wy), uniform, eye)
        for s in sides:
            r = g.math("MAXIMUM", r, s)
        for name, value in zip(_TILE, (x0, y0, wx, wy, r, *sides), strict=True):
            points = g.store(points, name, value)
        return points, r

    def grids(self):
        """Instances of unit grids with R = 1 .. top level quads a side, instance R - 1 the grid of R."""
        g = self.g
        repeat_in = g.node("GeometryNodeRepeatInput")
        repeat_out = g.node("GeometryNodeRepeatOutput")
        repeat_in.pair_with_output(repeat_out)
        repeat_out.repeat_items.new("INT", "R")
        g.feed(repeat_in.inputs["Iterations"], self.top_level())
        g.feed(repeat_in.inputs["R"], 1)
        r = repeat_in.outputs["R"]
        n = g.math("ADD", r, 1.0)
        grid = g.node("GeometryNodeMeshGrid", [("Size X", 1.0), ("Size Y", 1.0), ("Vertices X", n),
                                               ("Vertices Y", n)]).outputs[0]
        one = g.store(g.node("GeometryNodeGeometryToInstance", [(0, grid)]).outputs[0], "tessera_r", r,
                      domain="INSTANCE")
        joined = g.node("GeometryNodeJoinGeometry")
        self.g.tree.links.new(repeat_in.outputs["Geometry"], joined.inputs[0])
        self.g.tree.links.new(one, joined.inputs[0])
        self.g.tree.links.new(joined.outputs[0], repeat_out.inputs["Geometry"])
        g.feed(repeat_out.inputs["R"], g.math("ADD", r, 1.0))
        # the order Join Geometry lists its inputs in is not the order they were linked in: sort by R
        ordered = g.node("GeometryNodeSortElements", [(0, repeat_out.outputs["Geometry"]),
                                                      ("Sort Weight", g.named("tessera_r"))], domain="INSTANCE")
        return g.remove(ordered.outputs[0], ("tessera_r",))

    def placed(self, mesh):
        """The realised tile grids with their points at texel coordinates (side points on the side's level),
        sampled, in terrain-local space; the side points flagged for welding."""
        g = self.g
        pos = g.split(g.input("GeometryNodeInputPosition"))
        x0, y0, wx, wy, r, bottom, right, top, left = (g.named(name) for name in _TILE)
        i = g.math("ROUND", g.math("MULTIPLY", g.math("ADD", pos[0], 0.5), r))
        j = g.math("ROUND", g.math("MULTIPLY", g.math("ADD", pos[1], 0.5), r))

        def along(start, k, length, level):  # point round(k level / R) of ``level`` on a side
            m = g.math("ROUND", g.math("DIVIDE", g.math("MULTIPLY", k, level), r))
            return g.math("ADD", start, g.math("DIVIDE", g.math("MULTIPLY", m, length), level))

        def equal(a, b):
            return g.node("FunctionNodeCompare", [("A", a), ("B", b)], data_type="FLOAT",
                          operation="EQUAL").outputs[0]

        at_bottom, at_top = equal(j, 0.0), equal(j, r)
        at_left, at_right = equal(i, 0.0), equal(i, r)
        x = g.math("ADD", x0, g.math("DIVIDE", g.math("MULTIPLY", i, wx), r))
        y = g.math("ADD", y0, g.math("DIVIDE", g.math("MULTIPLY", j, wy), r))
        x = g.switch("FLOAT", at_bottom, x, along(x0, i, wx, bottom))
        x = g.switch("FLOAT", at_top, x, along(x0, i, wx, top))
        y = g.switch("FLOAT", at_left, y, along(y0, j, wy, left))
        y = g.switch("FLOAT", at_right, y, along(y0, j, wy, right))
        border = g.math("MAXIMUM", g.math("MAXIMUM", at_bottom, at_top), g.math("MAXIMUM", at_left, at_right))
        mesh = g.store(mesh, _BORDER, g.math("GREATER_THAN", border, 0.5), "BOOLEAN")
        mesh = g.store(mesh, "tessera_texel", g.xyz(x, y, 0.0), "FLOAT_VECTOR")
        texel = g.split(g.named("tessera_texel", "FLOAT_VECTOR"))
        position = self.world(texel[0], texel[1], self.sample(texel[0], texel[1]))
        return g.node("GeometryNodeSetPosition", [(0, mesh), ("Position", position)]).outputs[0]


def _pow2_ceiling(g, f):
    """The smallest power of two >= f >= 1 (as the kernel's frexp rounding): p = 2^round(log2 f) is within a
    factor sqrt(2) of f, so it is the answer, or twice it when below f."""
    p = g.math("POWER", 2.0, g.math("ROUND", g.math("LOGARITHM", f, 2.0)))
    return g.math("MULTIPLY", p, g.math("ADD", 1.0, g.math("LESS_THAN", p, f)))


def _build(tree):
    b = _Terrain(tree)
    g = b.g
    points, r = b.tiles()
    instances = g.node("GeometryNodeInstanceOnPoints", [("Points", points), ("Instance", b.grids()),
                                                        ("Pick Instance", True),
                                                        ("Instance Index", g.math("SUBTRACT", r, 1.0))]).outputs[0]
    mesh = g.node("GeometryNodeRealizeInstances", [(0, instances)]).outputs[0]
    mesh = b.placed(mesh)
    merge = g.node("GeometryNodeMergeByDistance", [("Geometry", mesh), ("Selection", g.named(_BORDER, "BOOLEAN")),
                                                   ("Distance", g.math("MULTIPLY", b.inp("Texel Size"), 1e-4))])
    mesh = merge.outputs[0]
    texel = g.split(g.named("tessera_texel", "FLOAT_VECTOR"))
    uv = g.xyz(g.math("DIVIDE", texel[0], g.math("SUBTRACT", b.width, 1.0)),
               g.math("DIVIDE", texel[1], g.math("SUBTRACT", b.height, 1.0)), 0.0)
    mesh = g.node("GeometryNodeStoreNamedAttribute", [(0, mesh), ("Name", b.inp("UV Map")), ("Value", uv)],
                  data_type="FLOAT2", domain="CORNER").outputs[0]
    mesh = g.node("GeometryNodeSetMaterial", [(0, mesh), ("Material", b.inp("Material"))]).outputs[0]
    tree.links.new(g.remove(mesh, (*_TILE, _BORDER, "tessera_texel")), b.go.inputs[0])


SPEC = register_group(GroupSpec(GROUP_NAME, VERSION, _build, catalog="Tessera/Terrain",
                                description="Build a crack-free terrain mesh from a height-map image, finer near "
                                            "the camera"))
