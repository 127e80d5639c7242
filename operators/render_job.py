"""The one skeleton of the operators that render in a background worker (`addon.render_jobs`): *Bake Impostor* and
*Bake Lighting*.

In the UI, `invoke` starts the worker and returns at once; a timer follows it (the progress bar and the status bar
show how far it is and on which device, Esc stops it and leaves nothing). When the render is in, `_read` and
`_prepare` run on a worker thread, then `_make_steps` makes the data one step per timer tick, all in one
`Transaction`. Scripts, ``blender -b`` and the redo panel call `execute`, which runs to the end with progress lines and
renders again only when something the render depends on changed (`_render_key`): otherwise the last render is reused.

Both act on every selected object the bake takes (`_wanted`), as Blender's own object operators do (`each_selected`):
the active one first, then the others, one render after another, each seeing its object as the active one; all in one
`Transaction`, so Esc or a failure on any of them leaves nothing of the others.
"""

import time

import bpy

from ..addon.guarded import (
    Transaction,
    check_numbers,
    each_selected,
    guarded,
    guarded_step,
    run_to_end,
    select_results,
    targets,
)
from ..kernels.common import workers

#: Renders at most this large are kept for the redo panel.
KEEP_BYTES = 256 * 2**20


class RenderJobOperator:
    """A mix-in for a `bpy.types.Operator` that renders in a worker. A subclass sets `job_label` (the status bar's
    words while it renders), `cancelled` (the report when Esc stops it), a class-level ``_last`` dict (the last
    render, for the redo panel) and defines:

    - ``_start(context)``: check the settings and start the worker: ``(handle with .job, what)``, ``what`` being what
      the later steps need of the scene as it was (refusals raise);
    - ``_render_key(context)``: what the render depends on;
    - ``_read(handle, what)`` (static): the render as read from the worker (a worker thread: numpy and files only);
    - ``_settings()``: the operator's settings `_prepare` needs, a tuple (read on the main thread);
    - ``_prepare(rendered, what, *settings)`` (static): what `_make_steps` makes the data from (a worker thread too);
    - ``_make_steps(context, tx, prepared, what, device)``: a generator making the data, one short step per yield;
      returns the operator's result (``self._t0``: when the bake started).
    ``_check(context)`` (optional) runs before a kept render is reused; ``_wanted(ob)`` (static) says which selected
    objects the bake takes.
    """

    job_label = "Rendering"
    cancelled = "Cancelled: nothing was changed"

    @staticmethod
    def _wanted(ob):
        return ob.type == "MESH"

    def _check(self, context):
        check_numbers(self)

    def _status_text(self, job):
        """The status bar's words while the worker renders."""
        device = job.device()
        on = f" on {device}" if device else ""
        label = self.job_label
        if len(self._targets) > 1:
            label += f" ({self._target + 1} of {len(self._targets)} objects, {self._targets[self._target].name})"
        if job.total > 1:
            view = min(int(job.fraction()) + 1, job.total)
            return f"{label}: {view} of {job.total} ({100.0 * job.fraction() / job.total:.0f}%){on} — Esc to cancel"
        return f"{label}{on} — Esc to cancel"

    @staticmethod
    def _render_bytes(rendered):
        """What keeping ``rendered`` for the redo panel costs, in bytes."""
        return rendered.nbytes

    def _keep(self, key, rendered, what, device):
        """Keep the last render for the redo panel (when small enough)."""
        small = self._render_bytes(rendered) <= KEEP_BYTES
        self._last.update(key=key if small else None, rendered=rendered if small else None,
                          what=what if small else None, device=device)

    def invoke(self, context, event):
        """In the UI: start the worker and follow it from a timer (the UI never waits); elsewhere: `execute`."""
        if bpy.app.background or context.window is None:
            return self.execute(context)
        result = self._begin_all(context)
        if self._job is None:
            return result
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, self._job.job.total)
        context.workspace.status_text_set(self._status_text(self._job.job))
        return {"RUNNING_MODAL"}

    @guarded
    def _begin(self, context, tx):
        """Start the worker (``self._job``; None when refused, and the refusal reported)."""
        self._t0 = time.perf_counter()
        self._job, self._reading, self._making, self._device = None, None, None, ""
        self._key = self._render_key(context)
        self._job, self._what = self._start(context)
        return {"FINISHED"}

    def _begin_all(self, context):
        """The objects to bake (`addon.guarded.targets`), one transaction for all of them, and the first one's worker
        started (``self._job``; None when refused, and the refusal reported)."""
        self._targets, self._target, self._made = targets(context, self._wanted), 0, []
        self._tx = Transaction()  # every object's data: Esc or a failure removes all of it
        return self._begin_target(context)

    def _begin_target(self, context):
        """`_begin` on the current target, seen as the active and only selected object."""
        ob = self._targets[self._target]
        with context.temp_override(active_object=ob, object=ob, selected_objects=[ob], selected_editable_objects=[ob]):
            return self._begin(bpy.context)

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def modal(self, context, event):
        if event.type == "ESC":
            self._job.job.cancel()
            self._tx.rollback()  # what was made so far, of every object
            self._end(context)
            self.report({"WARNING"}, self.cancelled)
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        job = self._job.job
        if job.running():
            context.window_manager.progress_update(job.fraction())
            context.workspace.status_text_set(self._status_text(job))
            return {"RUNNING_MODAL"}
        if self._reading is None:  # rendered: read and prepare on a worker thread, the UI keeps going
            self._device = job.device()
            # bound here: the worker thread touches no operator property (Blender's data is the main thread's)
            handle, what, settings, read, prepare = self._job, self._what, self._settings(), self._read, self._prepare

            def read_and_prepare():
                rendered = read(handle, what)
                return rendered, prepare(rendered, what, *settings)

            self._reading = workers.submit(read_and_prepare)
            context.workspace.status_text_set(f"{self.job_label}: reading the result — Esc to cancel")
            return {"RUNNING_MODAL"}
        if not self._reading.done():
            return {"RUNNING_MODAL"}
        if self._making is None:  # then the data, one step per tick
            self._making = self._finish_steps(context)
        result = guarded_step(self, self._tx, self._making)
        if result is None:
            return {"RUNNING_MODAL"}
        if "FINISHED" in result and self._target + 1 < len(self._targets):  # the next object's render
            self._made.append(context.view_layer.objects.active)
            self._target += 1
            self._reading = self._making = None
            if "FINISHED" in self._begin_target(context):
                context.workspace.status_text_set(self._status_text(self._job.job))
                return {"RUNNING_MODAL"}
            self._tx.rollback()  # refused (and reported): nothing of the others either
            result = {"CANCELLED"}
        self._end(context)
        if "FINISHED" in result:
            select_results(context, self._made)
        return result

    def _finish_steps(self, context):
        rendered, prepared = self._reading.result()  # a failure on the worker thread is reported by the guard
        self._keep(self._key, rendered, self._what, self._device)
        return (yield from self._make_steps(context, self._tx, prepared, self._what, self._device))

    @guarded
    def execute(self, context, tx):
        """Scripts, ``blender -b`` and the redo panel: every selected object the bake takes, each to the end, with
        progress lines; the last render is reused when nothing it depends on changed."""
        return each_selected(self._wanted)(type(self)._execute_one)(self, context, tx)

    def _execute_one(self, context, tx):
        self._t0 = time.perf_counter()
        key = self._render_key(context)
        last = self._last
        if last.get("key") == key and last.get("rendered") is not None:
            self._check(context)
            rendered, what, device = last["rendered"], last["what"], last["device"]
        else:
            handle, what = self._start(context)
            try:
                handle.job.wait(None, self.job_label)
            except BaseException:
                handle.job.cancel()
                raise
            device = handle.job.device()
            rendered = self._read(handle, what)
            self._keep(key, rendered, what, device)
        return run_to_end(self._make_steps(context, tx, self._prepare(rendered, what, *self._settings()), what, device))
