"""SIGTERM on the command line (farm managers send it to stop a task): the run unwinds at once and its partial files
are removed. A stop that lands inside an exporter fails the exporter; its traceback is held back with the rest of
what it printed (`files._captured_output`), so the task still ends with one sentence."""


class Stopped(Exception):
    """The process was asked to stop: unwind, removing partial files."""


#: The signals received since the run began (an operator that a signal interrupted reports a failure; this tells them
#: apart).
requested = set()


def message():
    return f"stopped by signal {min(requested)}; nothing was written"


def handler(signum, frame):
    """The SIGTERM handler of a run."""
    requested.add(signum)
    raise Stopped(message())
