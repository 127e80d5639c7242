"""SIGTERM on the command line (farm managers send it to stop a task): the run unwinds at once, its partial files
removed, except while an exporter writes: then the stop waits until the exporter returns (`deferred`), so the task
ends with one sentence instead of the exporter's traceback, and nothing is written."""

from contextlib import contextmanager


class Stopped(Exception):
    """The process was asked to stop: unwind, removing partial files."""


#: The signals received since the run began (an operator that a signal interrupted reports a failure; this tells them
#: apart).
requested = set()
_deferring = []


def message():
    return f"stopped by signal {min(requested)}; nothing was written"


def handler(signum, frame):
    """The SIGTERM handler of a run: raise `Stopped` now, or when the write under way returns."""
    requested.add(signum)
    if not _deferring:
        raise Stopped(message())


@contextmanager
def deferred():
    """Hold a stop until the block ends (an exporter writing), then raise `Stopped`."""
    _deferring.append(True)
    try:
        yield
    finally:
        _deferring.pop()
    if requested and not _deferring:
        raise Stopped(message())
