"""Temporary folders of the tests, benches, tools and the demo, removed when their process has ended.

Blender writes into its user and cache folders while the process ends (its GL shader cache among them), after
Python's own exit handlers, so a folder that holds them cannot be removed from inside the process: `remove_at_exit`
starts a small detached process as this one exits, which waits for it to be gone and then removes the folder. Links
inside the folder (the source tree linked as the package ``tessera``) are removed as links; what they point at stays.
"""

import atexit
import os
import subprocess
import sys

_REAPER = """
import os, shutil, sys, time
pid, folder = int(sys.argv[1]), sys.argv[2]
for _ in range(3000):  # at most ten minutes
    try:
        os.kill(pid, 0)
    except OSError:
        break
    time.sleep(0.2)
shutil.rmtree(folder, ignore_errors=True)
"""


def _reap(folder):
    try:
        subprocess.Popen([sys.executable, "-c", _REAPER, str(os.getpid()), str(folder)], start_new_session=True,
                         stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:  # no process can be started any more: remove what can be removed now
        import shutil

        shutil.rmtree(folder, ignore_errors=True)


def remove_at_exit(folder):
    """Remove ``folder`` (a temporary folder this process made) once this process has ended. Returns ``folder``."""
    atexit.register(_reap, folder)
    return folder
