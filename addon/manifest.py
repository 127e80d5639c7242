"""The extension's own ``blender_manifest.toml``, read once: its website (the manual), maintainer, license and
copyright, for the sidebar's start panel and the node-group assets' metadata."""

import functools
import tomllib
from pathlib import Path

MANIFEST = Path(__file__).resolve().parents[1] / "blender_manifest.toml"


@functools.cache
def manifest():
    """The manifest as a dict (empty when it cannot be read: the add-on then shows no link and no author)."""
    try:
        return tomllib.loads(MANIFEST.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError):
        return {}


def website():
    return manifest().get("website", "")


def license_id():
    """The first license without its ``SPDX:`` prefix (``GPL-3.0-or-later``), or ""."""
    licenses = manifest().get("license", [])
    return licenses[0].removeprefix("SPDX:") if licenses else ""
