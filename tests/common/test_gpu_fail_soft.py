"""A shader that does not compile (injected here at the one place shaders are compiled) fails soft, once (tier: gpu):
the loader remembers it per backend and names the backend and the shader; a preview stops with one message instead
of raising every frame; the operators' GPU paths fall back to the numpy reference with a warning and give its
result."""

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


@pytest.fixture
def failing(addon_module, gpu_renderer, monkeypatch):
    """Make the shaders named in the returned set fail to compile; count the compiles tried."""
    loader = addon_module("gpu_shaders.loader")
    names, tried, asked = set(), [], []
    original, real = loader.shader, loader._compile

    def shader(name, describe):  # which shader is being compiled (a create-info does not say)
        asked.append(name)
        return original(name, describe)

    def compile_(info):
        tried.append(asked[-1])
        if asked[-1] in names:
            raise Exception("ERROR: 0:12: 'frob' : no matching overloaded function found (simulated)")  # noqa: TRY002
        return real(info)

    monkeypatch.setattr(loader, "_compile", compile_)
    monkeypatch.setattr(loader, "_shaders", {})
    monkeypatch.setattr(loader, "_failed", {})
    monkeypatch.setattr(loader, "shader", shader)
    yield loader, names, tried
    loader.clear()


def test_a_failed_shader_is_remembered_and_named(failing, addon_module):
    loader, names, tried = failing
    errors = addon_module("kernels.common.errors")
    draw = addon_module("gpu_shaders.tessellation.draw")
    names.add("patch_compute")
    for _ in range(3):
        with pytest.raises(errors.GPUShaderError) as err:
            draw.compute_shader()
    message = str(err.value)
    assert "'patch_compute'" in message and loader.backend().title() in message and "simulated" in message
    assert len(tried) == 1  # compiled once; later calls raise what was remembered
    assert list(loader.failures()) == [(loader.backend(), "patch_compute")]


def test_a_preview_stops_once_instead_of_raising_every_frame(failing, addon_module, capfd):
    loader, names, _ = failing
    viewport = addon_module("addon.viewport")
    names.add("flat_mesh")
    offscreen = addon_module("gpu_shaders.offscreen")
    frames = []

    def draw(context, region, view, projection):
        frames.append(1)
        loader.shader("flat_mesh", offscreen._describe_flat_mesh)

    preview = viewport.Preview(draw, topic="tessera_test")
    preview.register()
    try:
        capfd.readouterr()
        for _ in range(5):
            if not preview.stopped:  # what the draw handler does each frame
                preview.run(None, None, np.eye(4), np.eye(4))
        assert len(frames) == 1 and "'flat_mesh'" in preview.stopped
        assert "'flat_mesh'" in viewport.stopped_previews()["tessera_test"]
        out = capfd.readouterr()
        assert (out.out + out.err).count("preview stopped") == 1
    finally:
        preview.unregister()
    assert "tessera_test" not in viewport.stopped_previews()


def test_a_failed_outline_shader_leaves_previews_drawing_without_outlines(failing, addon_module, capfd):
    """The selection outline's shader failing is told once; the draw handler's outline step returns instead of
    raising, frame after frame (the previews it outlines keep drawing), and keeps nothing of the frame."""
    loader, names, tried = failing
    viewport = addon_module("addon.viewport")
    names.add("selection_outline")
    capfd.readouterr()
    for _ in range(5):
        viewport._outlined.append((lambda color: None, 1.0))
        viewport._draw_outlines(None, None)  # returns before it reads the context: the shader is not there
        viewport._outlined.clear()  # as the draw handler does after every frame
    out = capfd.readouterr()
    assert tried.count("selection_outline") == 1 and (out.out + out.err).count("'selection_outline'") == 1


def test_the_outline_is_as_thick_as_blenders(bpy_module, addon_module):
    """Two pixels a side where Blender's is: a resolution scale above 1, or the theme's Outline Width above 2 (read
    from the preferences of every supported Blender)."""
    bpy = bpy_module
    viewport = addon_module("addon.viewport")
    prefs = bpy.context.preferences
    theme = prefs.themes[0].view_3d
    width = theme.outline_width
    try:
        theme.outline_width = 1
        thin = viewport.thick_outline(prefs)
        theme.outline_width = 3
        wide = viewport.thick_outline(prefs)
    finally:
        theme.outline_width = width
    assert thin == (prefs.system.pixel_size > 1.0) and wide


def _pixels(image):
    px = np.empty(image.size[0] * image.size[1] * 4, np.float32)
    image.pixels.foreach_get(px)
    return px


def test_operators_fall_back_to_numpy_with_a_warning(failing, bpy_module, clean_scene, capfd):
    bpy = bpy_module
    _, names, _ = failing
    names.update({"patch_compute", "vector_field_advect", "vector_field_splat"})
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1)
    source = bpy.context.active_object
    results = []
    for evaluate_on in ("GPU", "CPU"):
        for ob in bpy.context.selected_objects:  # the last result stays selected: Tessellate would take it too
            ob.select_set(False)
        bpy.context.view_layer.objects.active = source
        source.select_set(True)
        capfd.readouterr()
        assert bpy.ops.tessera.tessellate(level=3, evaluate_on=evaluate_on) == {"FINISHED"}
        out = capfd.readouterr()
        made = bpy.context.active_object
        pos = np.empty(len(made.data.vertices) * 3, np.float32)
        made.data.vertices.foreach_get("co", pos)
        results.append((pos, out.out + out.err))
    assert results[0][0].tobytes() == results[1][0].tobytes()  # the numpy reference's mesh
    assert "with numpy" in results[0][1] and "'patch_compute'" in results[0][1]
    images = []
    for backend in ("GPU", "CPU"):
        capfd.readouterr()
        known = set(bpy.data.images.keys())
        assert bpy.ops.tessera.vector_field_texture(width=48, height=48, backend=backend) == {"FINISHED"}
        out = capfd.readouterr()
        images.append((_pixels(bpy.data.images[(set(bpy.data.images.keys()) - known).pop()]), out.out + out.err))
    assert images[0][0].tobytes() == images[1][0].tobytes()
    assert "with numpy" in images[0][1]
