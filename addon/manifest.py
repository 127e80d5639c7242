"""The extension's own ``blender_manifest.toml``, read once: its website, maintainer, license and copyright, for the
sidebar's start panel and the node-group assets' metadata; and where the manual is (`manual_url`)."""

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


#: The manual as it ships in the extension (HTML made by tools/manual.py at the build); absent in a source tree.
MANUAL = MANIFEST.parent / "manual" / "index.html"


def manual_url():
    """Where the Manual button goes: the copy inside the extension (offline, and true to this version), else the
    website; "" when there is neither."""
    return MANUAL.as_uri() if MANUAL.is_file() else website()


def license_id():
    """The first license without its ``SPDX:`` prefix (``GPL-3.0-or-later``), or ""."""
    licenses = manifest().get("license", [])
    return licenses[0].removeprefix("SPDX:") if licenses else ""
