"""Make Blender's `gpu` module usable in background mode.

In a UI session a GPU context always exists. Under ``blender --background`` or the ``bpy`` module every
`gpu` call raises until one is created; Blender creates it for a render engine that asks for one
(``bl_use_gpu_context``), so a 4x4 render of a throw-away scene with such an engine makes it. That
works with Mesa's llvmpipe through EGL on a machine without a GPU.
"""

import bpy

from ..kernels.common.errors import GPUContextError

_ENGINE_ID = "TESSERA_GPU_CONTEXT"


class _ContextEngine(bpy.types.RenderEngine):
    bl_idname = _ENGINE_ID
    bl_label = "Tessera GPU context"
    bl_use_gpu_context = True

    def render(self, depsgraph):
        pass


def has_gpu_context():
    """True when `gpu` calls work now."""
    import gpu

    try:
        gpu.platform.renderer_get()
    except SystemError:
        return False
    return True


def ensure_gpu_context():
    """Return the renderer string, creating a GPU context first when in background mode.

    Leaves no scene, object or camera behind. Raises `GPUContextError` when no context can be made.
    """
    import gpu

    if not has_gpu_context():
        _create_context()
    if not has_gpu_context():
        raise GPUContextError(
            "No GPU context could be created. In background mode Tessera needs EGL with Mesa (llvmpipe) "
            "or a GPU driver: on Debian, apt install libegl1 libegl-mesa0 libgl1-mesa-dri"
        )
    return gpu.platform.renderer_get()


def _create_context():
    registered = not hasattr(bpy.types, _ENGINE_ID)
    if registered:
        bpy.utils.register_class(_ContextEngine)
    results = {im.name for im in bpy.data.images if im.type == "RENDER_RESULT"}
    scene = bpy.data.scenes.new("__tessera_gpu_context")
    cam_data = bpy.data.cameras.new("__tessera_gpu_context")
    cam = bpy.data.objects.new("__tessera_gpu_context", cam_data)
    try:
        scene.collection.objects.link(cam)
        scene.camera = cam
        scene.render.engine = _ENGINE_ID
        scene.render.resolution_x = scene.render.resolution_y = 4
        bpy.ops.render.render(scene=scene.name)
    except RuntimeError as err:
        raise GPUContextError(f"Creating a GPU context failed: {err}") from err
    finally:
        bpy.data.objects.remove(cam)
        bpy.data.cameras.remove(cam_data)
        bpy.data.scenes.remove(scene)
        for im in [im for im in bpy.data.images if im.type == "RENDER_RESULT" and im.name not in results]:
            bpy.data.images.remove(im)  # the render made one: the context leaves nothing behind
        if registered:
            bpy.utils.unregister_class(_ContextEngine)
