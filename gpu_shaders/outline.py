"""Blender's selection outline around the previews drawn instead of their objects (the overlay engine outlines an
object from its own evaluated geometry, which a preview hides): `OutlineMask` takes the previewed objects' coverage
and depth in a region-sized framebuffer of its own, `resolve` draws the outline from it over the viewport, faint
where the scene hides it, as Blender's overlay does."""


from . import loader
from .textures import FULLSCREEN_VERT, fullscreen_batch

#: The outline's alpha where another object hides it (Blender's overlay fades occluded outlines to this, outside
#: X-ray), and the depth slack below which a pixel counts as visible (Blender's: 3 units of a 23-bit mantissa).
OCCLUDED_ALPHA = 0.35
DEPTH_BIAS = 3.0 / 8388608.0
#: The alpha channel a previewed object is drawn with into the mask: its outline id.
SELECTED_ID, ACTIVE_ID = 0.5, 1.0

def _describe():
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, "VEC2", "corner")
    info.push_constant("VEC4", "selected_color")
    info.push_constant("VEC4", "active_color")
    info.push_constant("FLOAT", "alpha")
    info.push_constant("FLOAT", "depth_bias")
    info.push_constant("INT", "thick")
    info.sampler(0, "FLOAT_2D", "ids")
    info.sampler(1, "FLOAT_2D", "depths")
    info.fragment_out(0, "VEC4", "frag_color")
    if hasattr(info, "depth_write"):  # 4.5+ declares it; 4.2's OpenGL takes gl_FragDepth as it is
        info.depth_write("ANY")
    info.vertex_source(FULLSCREEN_VERT)
    info.fragment_source(loader.source("outline_frag.glsl"))
    return info


class OutlineMask:
    """A framebuffer of ``size`` (width, height) pixels: RGBA8 colour (the outline id in alpha) and 32-bit float depth,
    both readable by `resolve`. Made once per region size (`mask_for`)."""

    def __init__(self, size):
        import gpu

        self.size = tuple(int(v) for v in size)
        self.ids = gpu.types.GPUTexture(self.size, format="RGBA8")
        self.depths = gpu.types.GPUTexture(self.size, format="DEPTH_COMPONENT32F")
        self.framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.depths, color_slots=(self.ids,))

    def draw(self, draws):
        """Clear, then call each ``draw(color)`` of ``draws`` (``(draw, outline id)``: the object drawn flat, unlit,
        in ``color``, as its preview draws it) with depth test, so the nearest object's id and depth stay."""
        import gpu

        with self.framebuffer.bind():
            self.framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
            gpu.state.blend_set("NONE")
            gpu.state.depth_test_set("LESS_EQUAL")
            gpu.state.depth_mask_set(True)
            for draw, outline_id in draws:
                draw((0.0, 0.0, 0.0, outline_id))


_masks = {}  # size -> OutlineMask, the most recently used last
#: Masks kept: one per viewport size in use (a few viewports of different sizes each keep theirs).
KEEP_MASKS = 4


def mask_for(size):
    """The `OutlineMask` of this ``size``, made once and kept while viewports of this size draw outlines."""
    key = tuple(int(v) for v in size)
    mask = _masks.pop(key, None) or OutlineMask(key)
    _masks[key] = mask
    while len(_masks) > KEEP_MASKS:
        del _masks[next(iter(_masks))]
    return mask


def clear():
    """Forget the masks (their GPU context is going)."""
    _masks.clear()


def shader():
    """The compiled outline shader (`loader.shader`: raises `GPUShaderError` where it does not compile)."""
    return loader.shader("selection_outline", _describe)


def resolve(shader, mask, selected_color, active_color, thick=False, xray=False):
    """Draw with ``shader`` (`shader()`) the outline of ``mask`` over the bound framebuffer (the viewport's, whose
    depth holds the scene): colours linear rgba; thick: two pixels a side instead of one; xray: the occluded part as
    bright as the rest, as X-ray shows it. Leaves depth test and blending off."""
    import gpu

    batch = fullscreen_batch("selection_outline", shader)
    shader.bind()
    shader.uniform_sampler("ids", mask.ids)
    shader.uniform_sampler("depths", mask.depths)
    shader.uniform_float("selected_color", tuple(selected_color))
    shader.uniform_float("active_color", tuple(active_color))
    shader.uniform_float("depth_bias", DEPTH_BIAS)
    shader.uniform_int("thick", 1 if thick else 0)
    gpu.state.blend_set("ALPHA")
    gpu.state.depth_mask_set(False)
    passes = (("ALWAYS", 1.0),) if xray else (("LESS_EQUAL", 1.0), ("GREATER", OCCLUDED_ALPHA))
    try:
        for test, alpha in passes:
            gpu.state.depth_test_set(test)
            shader.uniform_float("alpha", alpha)
            batch.draw(shader)
    finally:
        gpu.state.blend_set("NONE")
        gpu.state.depth_test_set("NONE")
