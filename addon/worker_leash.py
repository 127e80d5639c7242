"""A render worker's leash (run by plain Python, never imported by the add-on): `render_jobs.start_worker` starts
``python -I worker_leash.py FOLDER -- WORKER COMMAND...`` with a pipe as its standard input, of which only the Blender
that started it holds the other end. The leash starts the worker below normal priority and waits for it; when the
pipe closes (that Blender cancelled the job, exited, crashed or was killed, even with SIGKILL, which no handler can
catch), it kills the worker and removes the job's FOLDER (a ``tessera-*`` folder; none when empty), so a worker never
outlives its task. It ends as the worker ended: the same exit code, or the same signal.
"""

import os
import shutil
import signal
import subprocess
import sys
import threading


def _lower_priority():
    """Nice 10 (the worker inherits it: the viewport and the farm's own work come first); no lower when the parent
    has set it already."""
    if hasattr(os, "setpriority"):
        try:
            os.setpriority(os.PRIO_PROCESS, 0, max(os.getpriority(os.PRIO_PROCESS, 0), 10))
        except OSError:
            pass


def main(argv):
    folder, command = argv[0], argv[argv.index("--") + 1:]
    _lower_priority()
    kwargs = {"creationflags": subprocess.BELOW_NORMAL_PRIORITY_CLASS} if os.name == "nt" else {}
    worker = subprocess.Popen(command, stdin=subprocess.DEVNULL, **kwargs)
    released = threading.Event()

    def watch():
        try:
            while os.read(0, 1):  # nothing is ever written: this returns at the pipe's end
                pass
        except OSError:
            pass
        released.set()
        if worker.poll() is None:
            worker.kill()
            worker.wait()
        if folder and os.path.basename(folder).startswith("tessera-"):
            shutil.rmtree(folder, ignore_errors=True)
        os._exit(1)

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    code = worker.wait()
    if released.is_set():
        watcher.join()  # removing the folder: exits from there
    if code < 0 and hasattr(signal, "SIGKILL"):  # ended by a signal: end by the same one, so the parent can say which
        signal.signal(-code, signal.SIG_DFL)
        os.kill(os.getpid(), -code)
    os._exit(code)  # not sys.exit: the watcher still blocks on the pipe, which interpreter shutdown would wait for


if __name__ == "__main__":
    main(sys.argv[1:])
