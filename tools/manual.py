"""The manual as it ships inside the extension: every page of ``docs/`` (and the README as ``readme.html``) made into
HTML with Python-Markdown, links between pages kept, pictures scaled down (at most `MAX_WIDTH` pixels wide, JPEG) so
the whole manual is a few MB, the sample files the examples link (``docs/samples/``) copied as they are, and nothing
that points outside it. The sidebar's *Manual* button opens ``manual/index.html`` (`addon.manifest.manual_url`), so
the manual works offline.

Usage: python tools/manual.py OUT_DIR      (tools/build_extension.py calls `build_manual` into the staged copy)
"""

import html
import re
import shutil
import sys
from pathlib import Path

import markdown

ROOT = Path(__file__).resolve().parents[1]
MAX_WIDTH = 800
JPEG_QUALITY = 85
_LINK = re.compile(r'(href|src)="([^"#:]+?)(#[^"]*)?"')
_STYLE = """body{font:15px/1.5 system-ui,sans-serif;max-width:60em;margin:2em auto;padding:0 1em;color:#222}
img{max-width:100%}table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #ccc;padding:2px 6px}
code,pre{background:#f4f4f4}pre{padding:.6em;overflow:auto}nav{margin-bottom:1.5em}"""


def _page_name(md_path):
    return "readme.html" if md_path.name == "README.md" else md_path.with_suffix(".html").name


def _picture(source, out_dir, done):
    """The scaled-down copy of picture ``source`` in ``out_dir`` (made once): its file name."""
    if source in done:
        return done[source]
    import OpenImageIO as oiio

    name = source.with_suffix(".jpg").name
    buf = oiio.ImageBuf(str(source))
    spec = buf.spec()
    if spec.width > MAX_WIDTH:
        height = max(1, round(spec.height * MAX_WIDTH / spec.width))
        buf = oiio.ImageBufAlgo.resize(buf, roi=oiio.ROI(0, MAX_WIDTH, 0, height, 0, 1, 0, spec.nchannels))
    if buf.spec().nchannels == 4:  # JPEG has no alpha: over white, as a page shows it
        white = oiio.ImageBufAlgo.fill((1.0, 1.0, 1.0, 1.0), roi=buf.roi)
        buf = oiio.ImageBufAlgo.over(buf, white)
    buf = oiio.ImageBufAlgo.channels(buf, (0, 1, 2))
    buf.specmod().attribute("compression", f"jpeg:{JPEG_QUALITY}")
    if not buf.write(str(out_dir / name), "uint8"):
        raise RuntimeError(f"could not write {name}: {buf.geterror()}")
    done[source] = name
    return name


def build_manual(out_dir, docs=ROOT / "docs", readme=ROOT / "README.md"):
    """Write the manual's HTML pages and pictures into ``out_dir``: the list of files written."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    pages = sorted(docs.glob("*.md")) + [readme]
    names = {p.resolve(): _page_name(p) for p in pages}
    pictures = {}
    written = []
    samples, samples_out, copied = (docs / "samples").resolve(), out_dir / "samples", set()
    for page in pages:
        body = markdown.markdown(page.read_text(encoding="utf-8"), extensions=["tables", "fenced_code", "toc"])

        def relink(m, page=page):
            kind, target, anchor = m.group(1), m.group(2), m.group(3) or ""
            path = (page.parent / html.unescape(target)).resolve()
            if path in names:
                return f'{kind}="{names[path]}{anchor}"'
            if kind == "src" and path.suffix.lower() in (".png", ".jpg") and path.is_file():
                return f'{kind}="{_picture(path, out_dir, pictures)}"'
            if kind == "href" and path.parent == samples and path.is_file():  # a file an example uses, as it is
                samples_out.mkdir(exist_ok=True)
                shutil.copyfile(path, samples_out / path.name)
                copied.add(samples_out / path.name)
                return f'{kind}="samples/{path.name}"'
            return f'{kind}="https://github.com/tessera-blender/tessera/blob/main/{target}{anchor}"' \
                if not target.startswith("/") else m.group(0)

        body = _LINK.sub(relink, body)
        title = re.search(r"<h1[^>]*>(.*?)</h1>", body)
        title = re.sub(r"<[^>]+>", "", title.group(1)) if title else "Tessera"
        text = (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{title}</title>'
                f'<style>{_STYLE}</style></head><body><nav><a href="index.html">Tessera manual</a> · '
                f'<a href="readme.html">Start</a></nav>\n{body}\n</body></html>\n')
        target = out_dir / names[page.resolve()]
        target.write_text(text, encoding="utf-8")
        written.append(target)
    return written + [out_dir / n for n in pictures.values()] + sorted(copied)


if __name__ == "__main__":
    for path in build_manual(Path(sys.argv[1])):
        print(path)
