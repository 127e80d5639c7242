"""The worker side of background renders (`render_jobs`): imported by the worker scripts, which run in a Blender
process of their own with this folder on ``sys.path`` (not as part of the add-on), so this module imports nothing of
Tessera's."""

import bpy


def use_device(scene, device):
    """Render on the Cycles device the user chose (``device``: `addon.render_jobs.render_device`), else the CPU; says
    which in a ``TESSERA_DEVICE`` line (and, when a GPU was asked for, why it is the CPU)."""
    scene.cycles.device = "CPU"
    why = ""
    if device and device.get("gpu"):
        why = f", because no GPU was found (Cycles sees no {device.get('type')} device)"
        try:
            prefs = bpy.context.preferences.addons["cycles"].preferences
            prefs.compute_device_type = device["type"]
            (getattr(prefs, "refresh_devices", None) or prefs.get_devices)()
            wanted = set(device.get("devices") or ())
            used = []
            for d in prefs.devices:
                d.use = d.type != "CPU" and (not wanted or d.id in wanted)
                if d.use:
                    used.append(d.name)
            if used:
                scene.cycles.device = "GPU"
                print(f"TESSERA_DEVICE GPU ({device['type']}): {', '.join(used)}", flush=True)
                return
        except (KeyError, TypeError, AttributeError, RuntimeError) as err:
            why = f", because the GPU could not be set up ({err})"
    print(f"TESSERA_DEVICE CPU{why}", flush=True)


def report_samples():
    """Print a ``TESSERA_SAMPLES k/n`` line each time the render under way reaches a new sample (from Blender's
    render statistics), so progress moves within a view (`render_jobs.RenderJob.fraction`)."""
    import re

    last = [None]
    pattern = re.compile(r"Sample (\d+)/(\d+)")

    def stats(text):
        found = pattern.search(text)
        if found and found.groups() != last[0]:
            last[0] = found.groups()
            print(f"TESSERA_SAMPLES {found.group(1)}/{found.group(2)}", flush=True)

    bpy.app.handlers.render_stats.append(stats)
