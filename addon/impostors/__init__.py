"""Nailboards in Blender: the background worker that renders an object's board with Cycles (`worker`, running
`worker_script.py` in a separate, niced process)."""
