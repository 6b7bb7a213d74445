"""Reads the VTU files pneufem writes (viz/vtk_output.h): XML with appended raw data, zlib
compressed, UInt64 headers. numpy and zlib only, so the package needs no VTK Python module."""
import re
import zlib

import numpy as np

_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int32": "<i4", "Int64": "<i8", "UInt8": "u1", "Int8": "i1",
          "UInt32": "<u4", "UInt64": "<u8"}
_TAG = re.compile(rb"<(DataArray|Array)\b([^>]*?)/?>", re.S)
_ATTR = re.compile(rb'(\w+)="([^"]*)"')
_SECTION = re.compile(rb"<(FieldData|PointData|CellData|Points|Cells)\b")


def _block(raw, start, header):
    """The decoded bytes of one appended array at `start` (vtkZLibDataCompressor block layout)."""
    h = np.dtype(header)
    nblocks = int(np.frombuffer(raw, h, 1, start)[0])
    sizes = np.frombuffer(raw, h, 3 + nblocks, start)[3:]
    pos = start + (3 + nblocks) * h.itemsize
    out = []
    for s in sizes:
        out.append(zlib.decompress(raw[pos:pos + int(s)]))
        pos += int(s)
    return b"".join(out)


def read_vtu(path):
    """{"field": {...}, "point": {...}, "cell": {...}, "points": (n, 3), "connectivity", "offsets",
    "types"} of a pneufem VTU; tensors of 9 components as (n, 3, 3)."""
    with open(path, "rb") as f:
        raw = f.read()
    head_end = raw.index(b"<AppendedData")
    base = raw.index(b"_", raw.index(b">", head_end)) + 1
    head = raw[:head_end]
    if b'compressor="vtkZLibDataCompressor"' not in head or b'header_type="UInt64"' not in head:
        raise ValueError(f"{path}: not a VTU file as pneufem writes it (zlib-compressed, UInt64 headers)")
    sections = [(m.start(), m.group(1).decode()) for m in _SECTION.finditer(head)]
    out = {"field": {}, "point": {}, "cell": {}}
    for m in _TAG.finditer(head):
        attrs = {k.decode(): v.decode() for k, v in _ATTR.findall(m.group(2))}
        if "offset" not in attrs:
            continue
        section = [name for pos, name in sections if pos < m.start()][-1]
        data = _block(raw, base + int(attrs["offset"]), "<u8")
        name = attrs.get("Name", "")
        if attrs["type"] == "String":
            value = [s.decode() for s in data.split(b"\0") if s]
        else:
            value = np.frombuffer(data, _TYPES[attrs["type"]]).copy()
            ncomp = int(attrs.get("NumberOfComponents", "1"))
            if ncomp == 9:
                value = value.reshape(-1, 3, 3)
            elif ncomp > 1:
                value = value.reshape(-1, ncomp)
        if section == "FieldData":
            out["field"][name] = value[0] if not isinstance(value, list) and value.size == 1 else value
        elif section == "PointData":
            out["point"][name] = value
        elif section == "CellData":
            out["cell"][name] = value
        elif section == "Points":
            out["points"] = value
        else:
            out[name] = value
    return out
