"""The one guarded path every operator's ``execute`` runs through.

`guarded` wraps ``execute(self, context, tx)``: the operator makes its new data blocks through the
`Transaction` ``tx`` (or registers them with `Transaction.track`) and registers an undo for any change it makes
to existing data (`Transaction.on_rollback`). When everything succeeded the result stands. On any failure every
registered undo runs (last first, while the new blocks still exist, so an undo may read them), then every new
block is removed, and the failure becomes a report:

- a `TesseraError` (including `EmptyResultError`): its text, which says what to change;
- anything else: "Tessera failed: <what> — nothing was changed", with the traceback printed to the console.

Either way the operator returns ``{'CANCELLED'}``: no traceback escapes to the user and nothing is half-done.

Before ``execute`` runs, `check_numbers` refuses any numeric property of the operator outside its hard range:
Blender clamps what it is given to that range but lets NaN through (and every Tessera property has a finite
range, `kernels.common.limits`). Settings an operator reads from a property group are checked the same way
where it reads them.
"""

import functools
import math
import re
import traceback

import bpy

from ..kernels.common import opencl_runtime
from ..kernels.common.errors import InvalidInputError, TesseraError

#: ID type -> its collection in bpy.data, for removal on rollback.
_COLLECTIONS = (
    (bpy.types.Object, "objects"), (bpy.types.Mesh, "meshes"), (bpy.types.Image, "images"),
    (bpy.types.Material, "materials"), (bpy.types.NodeTree, "node_groups"), (bpy.types.Curve, "curves"),
)


class Transaction:
    """New data blocks and undo steps of one operator run (see the module docstring)."""

    def __init__(self):
        self._blocks = []
        self._undo = []

    def track(self, block):
        """Remove ``block`` (a new ID) if the run fails; returns it."""
        self._blocks.append(block)
        return block

    def new_mesh(self, name):
        return self.track(bpy.data.meshes.new(name))

    def new_object(self, name, data):
        return self.track(bpy.data.objects.new(name, data))

    def on_rollback(self, undo):
        """Call ``undo()`` if the run fails (before the new blocks are removed, last registered first)."""
        self._undo.append(undo)

    def rollback(self):
        """Run the undo steps, then remove every tracked block that still exists. Errors here are printed, not
        raised: the operator is already reporting the failure that caused the rollback."""
        for undo in reversed(self._undo):
            try:
                undo()
            except Exception:  # noqa: BLE001 - every undo must get its chance
                traceback.print_exc()
        for block in reversed(self._blocks):
            try:
                remove_block(block)
            except ReferenceError:  # removed already (a writer replaced it): nothing left to do
                pass
            except RuntimeError as err:
                print(f"Tessera: could not remove {block!r} after a failure: {err}")
        self._blocks.clear()
        self._undo.clear()


def remove_block(block):
    """Remove a new ID from its bpy.data collection (a ReferenceError when something removed it already)."""
    for id_type, name in _COLLECTIONS:
        if isinstance(block, id_type):
            getattr(bpy.data, name).remove(block)
            return
    raise RuntimeError(f"no collection for {type(block).__name__}")


def check_numbers(struct):
    """Raise `InvalidInputError` naming the first FLOAT or INT property of ``struct`` (an operator or a property
    group) that is NaN or outside its hard range, with that range."""
    if isinstance(struct, bpy.types.Operator):
        struct = struct.properties  # an operator's own settings live there, not on the Operator type
    for prop in struct.bl_rna.properties:
        if prop.type not in ("FLOAT", "INT") or prop.identifier == "rna_type":
            continue
        value = getattr(struct, prop.identifier)
        for v in (value if prop.array_length else (value,)):
            if not (math.isfinite(v) and prop.hard_min <= v <= prop.hard_max):
                raise InvalidInputError(f"{prop.name} must be a finite number between {prop.hard_min:g} and "
                                        f"{prop.hard_max:g}; got {v!r}")


def check_editable(block, change, instead):
    """Refuse to change a data-block that comes from a library (linked, or not editable here): `InvalidInputError`
    naming it, its library, ``change`` (what would be changed) and ``instead`` (what the user can do)."""
    if getattr(block, "is_editable", True) and getattr(block, "library", None) is None:
        return
    library = getattr(block, "library", None)
    where = f"linked from {library.filepath}" if library is not None else "not editable in this file"
    raise InvalidInputError(f"{block.name!r} is {where}, so {change} cannot be saved. {instead}")


def failure_message(err):
    """What the user reads for an unexpected exception."""
    what = str(err) or type(err).__name__
    return f"Tessera failed: {what} — nothing was changed (details in the system console)"


#: OpenCL status names that mean a device (or the host, for PoCL) ran out of memory.
_CL_OUT_OF_MEMORY = ("MEM_OBJECT_ALLOCATION_FAILURE", "OUT_OF_RESOURCES", "OUT_OF_HOST_MEMORY")


def out_of_memory_message(err):
    """The reason to give when an allocation failed after the estimates let a run start (numpy's MemoryError, an
    OpenCL device's allocation failure), or None for any other exception."""
    text = str(err)
    if isinstance(err, MemoryError):
        size = re.search(r"allocate ([\d.,]+ ?[KMGT]i?B)", text)
        where = f"could not allocate {size.group(1).replace('. ', ' ')}" if size else "an allocation failed"
        return (f"Out of memory: {where}, and nothing was changed. Use smaller settings (fewer levels, a lower Max "
                "Level, fewer copies), lower the memory budget in the Tessera preferences so that such runs are "
                "refused before they start, or close other programs")
    if type(err).__module__.startswith("pyopencl") and any(name in text for name in _CL_OUT_OF_MEMORY):
        return ("The OpenCL device ran out of memory, and nothing was changed. Use smaller settings, or set OpenCL "
                "to Off in the Tessera preferences to compute on the CPU with numpy")
    return None


def _failed(op, tx, err):
    """Roll ``tx`` back and report ``err`` on operator ``op`` (see the module): ``{'CANCELLED'}``."""
    if not isinstance(err, TesseraError):
        traceback.print_exc()
    tx.rollback()
    op.report({"ERROR"}, str(err) if isinstance(err, TesseraError) else out_of_memory_message(err) or
              failure_message(err))
    return {"CANCELLED"}


def guarded(execute):
    """Decorate ``execute(self, context, tx)`` into Blender's ``execute(self, context)`` (see the module)."""

    @functools.wraps(execute)
    def wrapper(self, context):
        tx = Transaction()
        try:
            check_numbers(self)
            result = execute(self, context, tx)
        except Exception as err:  # noqa: BLE001 - the guard: no traceback may escape to the user
            return _failed(self, tx, err)
        if "CANCELLED" in result:
            tx.rollback()
        notice = opencl_runtime.fallback_notice()  # once: where a window shows it (the status bar)
        if notice:
            self.report({"WARNING"}, notice)
        return result

    return wrapper


def targets(context, wanted):
    """The objects an operator on the active object acts on (see `each_selected`): the active one, then the other
    selected objects ``wanted(ob)`` accepts, in selection order; the active one alone when it is not selected (a script
    that only set it active) or when it is not wanted but nothing else is."""
    active = context.active_object
    if active is not None and not active.select_get():
        return [active]
    out = [active] if active is not None and wanted(active) else []
    out += [ob for ob in context.selected_objects if ob is not active and wanted(ob)]
    return out or ([active] if active is not None else [])


def each_selected(wanted):
    """Make ``execute(self, context, tx)`` of an operator on the active object act on every selected object that
    ``wanted(ob)`` accepts, as Blender's own object operators do: once per object (the active one first, then the
    others in selection order), each run seeing that object as the active and only selected one, all in the one
    `Transaction` of `guarded` (one object failing leaves nothing of the others). Use below ``@guarded``. An active
    object that is not selected (a script that only set it active) is acted on alone, as is one with nothing else
    selected: the plain call."""

    def decorate(execute):
        @functools.wraps(execute)
        def wrapper(self, context, tx):
            acted_on = targets(context, wanted)
            if len(acted_on) <= 1:
                return execute(self, context, tx)
            results = []
            for ob in acted_on:
                with context.temp_override(active_object=ob, object=ob, selected_objects=[ob],
                                           selected_editable_objects=[ob]):
                    result = execute(self, bpy.context, tx)
                if "CANCELLED" in result:
                    return result
                results.append(context.view_layer.objects.active)
            select_results(context, results)
            return {"FINISHED"}

        return wrapper

    return decorate


def select_results(context, results):
    """After an operator ran once per object: every run's result (the object each run left active) selected, as
    Blender's own multi-object operators leave them; a result removed meanwhile, or None, is passed over."""
    for ob in results:
        if ob is not None and ob.name in context.view_layer.objects:
            ob.select_set(True)


def run_to_end(steps):
    """Run a generator of steps (see `guarded_step`) at once: its return value."""
    while True:
        try:
            next(steps)
        except StopIteration as done:
            return done.value


def guarded_step(op, tx, steps):
    """One step of work spread over several calls (a modal operator's timer ticks, each short): ``next(steps)`` with
    the new blocks tracked by ``tx``, a `Transaction` kept across the steps. Returns None while steps remain, the
    result when ``steps`` (a generator returning the operator's result) ends, or ``{'CANCELLED'}`` on failure (rolled
    back and reported as the guard does)."""
    try:
        next(steps)
    except StopIteration as done:
        return done.value
    except Exception as err:  # noqa: BLE001 - the guard
        return _failed(op, tx, err)
    return None
