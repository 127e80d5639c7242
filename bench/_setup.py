"""Make the source tree importable as the package ``tessera`` (a symlink in a temporary folder)."""

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def import_path():
    folder = Path(tempfile.mkdtemp(prefix="tessera-bench-"))
    (folder / "tessera").symlink_to(ROOT, target_is_directory=True)
    sys.path.insert(0, str(folder))
