"""Is a file an exporter just wrote whole? Blender's exporters report nothing on a short write (a full disk, a quota),
so every file is checked, as its format allows, before it gets its final name.

- binary STL: exactly 84 + 50 bytes per triangle of its header's count; ASCII STL ends with ``endsolid``;
- PLY: the header's elements walked to the byte (binary) or counted in lines (ASCII);
- GLB: the header's length is the file's size and its chunks add up to it; ``.gltf``: its JSON parses and every
  ``.bin`` buffer it names has the byte length it gives;
- OBJ: the number of ``v`` and ``f`` lines is the number of vertices and faces written (when known), and the file ends
  with a whole line;
- .blend: an uncompressed one ends with its ``ENDB`` block's header, exactly; a compressed one (zstd, seekable) ends
  with a seek table whose frames add up to its size;
- every format: a file system left with no free block means the write was cut short.

No Blender imports: the checks read bytes only. `check_written` raises `ShortWrite` with the reason; `os_cause` says
what an operating-system error means for a file being written.
"""

import errno
import json
import os
import re
import struct

import numpy as np


class ShortWrite(Exception):
    """The file is not whole: the message says what is missing."""


#: What an operating-system error means for a file being written, in the user's words.
CAUSES = {errno.ENOSPC: "no space left on the device", errno.EDQUOT: "the disk quota is used up",
          errno.EROFS: "the file system is read-only", errno.EACCES: "permission denied",
          errno.EPERM: "permission denied", errno.EISDIR: "it is a folder; give a file name",
          errno.ENOTDIR: "a folder in its path is a file", errno.ENAMETOOLONG: "the name is too long",
          errno.EIO: "the device reported an input/output error"}


def os_cause(err):
    """The cause of an `OSError` in the user's words."""
    return CAUSES.get(err.errno) or (err.strerror or str(err)).lower()


_ERRNO_TEXT = re.compile(r"\[Errno (\d+)\]")
#: Operating-system errors an exporter may print (or put in its exception) while a write fails.
_PRINTED = (errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO)


def cause_in_text(text):
    """The cause of a failed write named in ``text`` (what an exporter printed or raised: Python's ``[Errno 28]``,
    or the C library's "No space left on device"), in the user's words; None when it names none."""
    found = _ERRNO_TEXT.findall(text)
    if found:
        number = int(found[-1])
        return CAUSES.get(number) or os.strerror(number).lower()
    for number in _PRINTED:
        if os.strerror(number) in text:
            return CAUSES[number]
    return None


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}
_CHUNK = 1 << 22


def check_written(path, expected=None):
    """Raise `ShortWrite` unless ``path`` holds a whole file of its format (by extension). ``expected``: optional
    {"vertices": int, "faces": int}, what an OBJ must hold."""
    ext = os.path.splitext(path)[1].lower()
    size = os.path.getsize(path)
    if size == 0:
        raise ShortWrite("the file is empty")
    check = _CHECKS.get(ext)
    if check is not None:
        with open(path, "rb") as f:
            check(f, size, path, expected)
    if disk_full(os.path.dirname(path) or "."):
        raise ShortWrite("no space was left on the device after it was written")


def free_bytes(folder):
    """The bytes this process may still write on the file system of ``folder`` (root may use the blocks kept for it);
    None where that cannot be asked."""
    try:
        st = os.statvfs(folder)
    except (OSError, AttributeError):  # no statvfs (Windows)
        return None
    blocks = st.f_bfree if hasattr(os, "geteuid") and os.geteuid() == 0 else st.f_bavail
    return blocks * st.f_frsize


def disk_full(folder):
    """Whether the file system of ``folder`` has no free block left for this process (a write there was cut short)."""
    return free_bytes(folder) == 0


def least_size(ext, vertices, corners, faces):
    """The fewest bytes a mesh of ``vertices``, ``corners`` (face corners) and ``faces`` takes in format ``ext``: its
    positions and its faces' indices, at least (binary STL: exactly). 0 for a format not known here."""
    triangles = corners - 2 * faces
    if ext == ".stl":
        return 84 + 50 * triangles
    if ext == ".obj":  # "v x y z" with 6 decimals, "f a b c"
        return 26 * vertices + 2 * corners + 3 * faces
    if ext == ".ply":  # uncompressed binary (USD's crate, FBX and .blend compress: no least size)
        return 12 * vertices + 4 * corners
    if ext == ".abc":  # Alembic writes corner normals and UVs too: sized whole, its exporter aborts on a full disk
        return 16384 + 12 * vertices + 4 * faces + 24 * corners
    if ext in (".glb", ".gltf"):  # vertices split per face corner where normals or UVs differ: positions at least
        return 12 * vertices + 4 * 3 * triangles
    return 0


def _stl(f, size, path, expected):
    head = f.read(84)
    if len(head) == 84:
        (count,) = struct.unpack_from("<I", head, 80)
        if size == 84 + 50 * count:
            return
    f.seek(0)
    first = f.readline(1024).rstrip(b"\r\n")
    if first.lower().startswith(b"solid"):  # ASCII (a binary STL may begin with "solid" too: its size decided above)
        f.seek(max(0, size - 1024))
        tail = f.read()
        if tail.endswith(b"\n") and tail.rstrip(b"\r\n").rsplit(b"\n", 1)[-1] == b"end" + first:
            return
        raise ShortWrite("the ASCII STL stops before its endsolid line")
    count = struct.unpack_from("<I", head, 80)[0] if len(head) == 84 else 0
    raise ShortWrite(f"the STL holds {size:,} bytes where its {count:,} triangles need {84 + 50 * count:,}")


def _ply_header(f):
    lines = []
    while True:
        line = f.readline()
        if not line:
            raise ShortWrite("the PLY stops inside its header")
        text = line.decode("ascii", "replace").strip()
        lines.append(text)
        if text == "end_header":
            return lines


def _ply(f, size, path, expected):
    lines = _ply_header(f)
    fmt = next((ln.split()[1] for ln in lines if ln.startswith("format ")), "")
    elements = []  # [name, count, [(kind, dtype or (count dtype, item dtype))]]
    for ln in lines:
        words = ln.split()
        if words[:1] == ["element"] and len(words) == 3:
            elements.append([words[1], int(words[2]), []])
        elif words[:1] == ["property"] and elements:
            if words[1] == "list" and len(words) == 5:
                elements[-1][2].append(("list", (_PLY_TYPES[words[2]], _PLY_TYPES[words[3]])))
            elif len(words) == 3:
                elements[-1][2].append(("scalar", _PLY_TYPES[words[1]]))
    if fmt == "ascii":
        rows = sum(count for _, count, _ in elements)
        body = f.read()
        got = body.count(b"\n") + (0 if body.endswith(b"\n") or not body else 1)
        if got < rows or (body and not body.endswith(b"\n")):
            raise ShortWrite(f"the PLY holds {got:,} of its {rows:,} data lines")
        return
    order = "<" if fmt == "binary_little_endian" else ">"
    offset = f.tell()
    for name, count, props in elements:
        offset = _ply_element(f, offset, size, name, count, props, order)
        if offset > size:
            break
    if offset != size:
        raise ShortWrite(f"the PLY holds {size:,} bytes where its header's elements need {offset:,}")


def _ply_element(f, offset, size, name, count, props, order):
    """The offset after ``count`` rows of element ``name`` that start at ``offset`` (beyond ``size`` when cut)."""
    if count == 0:
        return offset
    if all(kind == "scalar" for kind, _ in props):
        return offset + count * sum(np.dtype(t).itemsize for _, t in props)
    if len(props) != 1:  # lists beside other properties: walk row by row
        return _ply_walk(f, offset, size, count, props, order)
    count_type, item_type = props[0][1]
    cw, iw = np.dtype(count_type).itemsize, np.dtype(item_type).itemsize
    f.seek(offset)
    first = f.read(cw)
    if len(first) < cw:
        return size + 1
    k = int(np.frombuffer(first, order + count_type)[0])
    stride = cw + k * iw
    end = offset + count * stride
    if end <= size:  # every row the same length (all triangles, all quads): check the counts in one strided read
        f.seek(offset)
        block = np.frombuffer(f.read(count * stride), np.uint8).reshape(count, stride)[:, :cw]
        if np.all(np.ascontiguousarray(block).view(order + count_type).ravel() == k):
            return end
    return _ply_walk(f, offset, size, count, props, order)


def _ply_walk(f, offset, size, count, props, order):
    f.seek(offset)
    for _ in range(count):
        for kind, t in props:
            if kind == "scalar":
                offset += np.dtype(t).itemsize
            else:
                cw = np.dtype(t[0]).itemsize
                f.seek(offset)
                raw = f.read(cw)
                if len(raw) < cw:
                    return size + 1
                offset += cw + int(np.frombuffer(raw, order + t[0])[0]) * np.dtype(t[1]).itemsize
        if offset > size:
            return offset
    return offset


def _glb(f, size, path, expected):
    head = f.read(12)
    if len(head) < 12 or head[:4] != b"glTF":
        raise ShortWrite("the GLB has no whole header")
    length = struct.unpack_from("<I", head, 8)[0]
    if length != size:
        raise ShortWrite(f"the GLB holds {size:,} bytes where its header says {length:,}")
    at = 12
    while at < size:
        f.seek(at)
        chunk = f.read(8)
        if len(chunk) < 8:
            raise ShortWrite("the GLB stops inside a chunk header")
        at += 8 + struct.unpack_from("<I", chunk, 0)[0]
    if at != size:
        raise ShortWrite(f"the GLB's chunks need {at:,} bytes; it holds {size:,}")


def _gltf(f, size, path, expected):
    try:
        document = json.loads(f.read().decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as err:
        raise ShortWrite(f"the glTF's JSON does not parse ({err})") from None
    folder = os.path.dirname(path)
    for buffer in document.get("buffers", []):
        uri = buffer.get("uri", "")
        if not uri or uri.startswith("data:"):
            continue
        part = os.path.join(folder, uri)
        got = os.path.getsize(part) if os.path.isfile(part) else -1
        if got != buffer.get("byteLength"):
            raise ShortWrite(f"its buffer {uri} holds {max(got, 0):,} bytes where the glTF says "
                             f"{buffer.get('byteLength'):,}")


def _obj(f, size, path, expected):
    vertices = faces = 0
    tail = b"\n"
    while True:
        block = f.read(_CHUNK)
        if not block:
            break
        joined = tail[-2:] + block  # a line start split across blocks
        vertices += joined.count(b"\nv ")
        faces += joined.count(b"\nf ")
        tail = block
    if not tail.endswith(b"\n"):
        raise ShortWrite("the OBJ stops in the middle of a line")
    if expected is not None:
        if (vertices, faces) != (expected["vertices"], expected["faces"]):
            raise ShortWrite(f"the OBJ holds {vertices:,} vertices and {faces:,} faces of the "
                             f"{expected['vertices']:,} and {expected['faces']:,} written")


_ZSTD = b"\x28\xb5\x2f\xfd"
_SEEK_TABLE = 0x8F92EAB1  # the zstd seekable format's footer (Blender writes compressed .blend files so)


def _blend(f, size, path, expected):
    head = f.read(12)
    if head.startswith(b"BLENDER"):
        # the file ends with the ENDB block's header and nothing after it: 32 bytes in the format of Blender 5.0+
        # ("BLENDER17-…"), else 24 (8-byte pointers, "BLENDER-") or 20 (4-byte pointers, "BLENDER_")
        last = 32 if head[7:9] == b"17" else 24 if head[7:8] == b"-" else 20
        f.seek(max(0, size - last))
        if size < last or f.read(4) != b"ENDB":
            raise ShortWrite("the .blend stops before its last block")
        return
    if not head.startswith(_ZSTD):
        raise ShortWrite("the .blend does not begin as Blender's files do")
    # compressed: frames, then a skippable frame holding the seek table, whose footer ends the file
    if size < 17:
        raise ShortWrite("the compressed .blend has no seek table")
    f.seek(size - 9)
    frames, descriptor, magic = struct.unpack("<IBI", f.read(9))
    if magic != _SEEK_TABLE:
        raise ShortWrite("the compressed .blend stops before its seek table")
    entry = 12 if descriptor & 0x80 else 8
    table = 8 + frames * entry + 9
    f.seek(size - table + 8)
    entries = f.read(frames * entry)
    compressed = sum(struct.unpack_from("<I", entries, i * entry)[0] for i in range(frames))
    if compressed + table != size:
        raise ShortWrite(f"the compressed .blend holds {size:,} bytes where its seek table counts "
                         f"{compressed + table:,}")


_CHECKS = {".stl": _stl, ".ply": _ply, ".glb": _glb, ".gltf": _gltf, ".obj": _obj, ".blend": _blend}
