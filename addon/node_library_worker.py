"""Run by a separate Blender process (never imported by the add-on): write Tessera's node-group library
(`node_library.write_library`), so that building its groups (a second or two of Python) never holds the artist's
window. Argument after ``--``: a job file (JSON) with ``package`` (the folder of the Tessera package) and
``directory`` (where the library goes). Prints ``TESSERA_PROGRESS 1/1`` when the library is written."""

import importlib
import json
import sys
from pathlib import Path

job = json.loads(Path(sys.argv[sys.argv.index("--") + 1]).read_text(encoding="utf-8"))
package = Path(job["package"])
sys.path.insert(0, str(package.parent))
library = importlib.import_module(package.name + ".addon.node_library")
print(library.write_library(job["directory"]))
print("TESSERA_PROGRESS 1/1", flush=True)
