"""Custom OpenCL kernels stored in a .blend: run only on an explicit user action, and only when trusted.

A kernel body lives in a Text datablock (``Object.tessera.displacement.kernel_text``). Nothing compiles or runs
it on file load or on any handler. ``tessera.displacement_custom`` runs it, and only when either Blender's
"Auto Run Python Scripts" allows this file's scripts (the same trust that gates drivers and registered
scripts), or the user confirmed this exact source in this session (``tessera.displacement_trust_kernel``; the
confirmation is held in memory, never saved). Compiler errors are reported with the compiler log and the map
is left unchanged.
"""

import hashlib

import bpy

from ..addon.displacement.maps import channels_for, commit, map_state
from ..addon.guarded import check_numbers, guarded
from ..kernels.common.errors import TesseraError
from ..kernels.common.opencl_runtime import get_runtime
from ..kernels.displacement.map_edit import apply_custom, compile_custom
from ..kernels.displacement.map_strokes import TileUndo

_trusted_sources = set()  # sha256 of sources the user confirmed in this session


def _digest(source):
    return hashlib.sha256(source.encode("utf-8")).hexdigest()


def blender_trusts_scripts(context):
    """True when Blender lets this file's scripts run (Auto Run Python Scripts, no blocked auto-exec)."""
    return bool(context.preferences.filepaths.use_scripts_auto_execute) and not bpy.app.autoexec_fail


def is_trusted(context, source):
    return blender_trusts_scripts(context) or _digest(source) in _trusted_sources


def _source(context):
    ob = context.active_object
    text = ob.tessera.displacement.kernel_text if ob is not None and ob.type == "MESH" else None
    return None if text is None else text.as_string()


class TESSERA_OT_displacement_trust_kernel(bpy.types.Operator):
    """Allow the active object's custom kernel (this exact source) to run in this session"""

    bl_idname = "tessera.displacement_trust_kernel"
    bl_label = "Trust Custom Kernel"

    @classmethod
    def poll(cls, context):
        return _source(context) is not None

    def invoke(self, context, event):
        return context.window_manager.invoke_confirm(self, event, message="Run OpenCL code from this file? "
                                                     "Only trust code you have read.")

    @guarded
    def execute(self, context, tx):
        _trusted_sources.add(_digest(_source(context)))
        self.report({"INFO"}, "Custom kernel trusted for this session")
        return {"FINISHED"}


class TESSERA_OT_displacement_custom(bpy.types.Operator):
    """Run the custom kernel over the whole displacement map (an explicit, trusted action)"""

    bl_idname = "tessera.displacement_custom"
    bl_label = "Run Custom Kernel"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        if _source(context) is None or context.active_object.tessera.displacement.image is None:
            cls.poll_message_set("The active object needs a displacement map and a custom kernel text")
            return False
        return True

    @guarded
    def execute(self, context, tx):
        ob = context.active_object
        settings = ob.tessera.displacement
        check_numbers(settings)
        source = _source(context)
        if not is_trusted(context, source):
            raise TesseraError("This file's scripts are not trusted: enable Auto Run Python Scripts (or reload "
                               "the file as trusted), or use Trust Custom Kernel after reading the code")
        runtime = get_runtime()
        if runtime is None:
            raise TesseraError("Custom kernels need OpenCL, and no OpenCL device is available")
        kernel = compile_custom(runtime, source)
        state = map_state(settings.image, channels_for(settings))
        args = [tuple(settings.kernel_args[4 * i:4 * i + 4]) for i in range(4)]
        h, w = state.host.shape[:2]
        undo = TileUndo(state.host)
        undo.record(state.host, (0, 0, w, h))
        apply_custom(state.host, kernel, runtime, args=args, device=state.device)  # refuses non-finite output
        commit(state, settings.image, undo)
        return {"FINISHED"}


classes = (TESSERA_OT_displacement_trust_kernel, TESSERA_OT_displacement_custom)
register, unregister = bpy.utils.register_classes_factory(classes)
