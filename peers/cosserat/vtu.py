"""A tiny reader for the 2D triangle .vtu files porofrac writes (`porofrac_grid::io::write_vtu`):
inline DataArrays, `format="binary"` (base64 of a UInt64 byte count + the raw little-endian
values, no compression) or `format="ascii"`. Returns the points (n, 2) and the triangles
(m, 3) in file order, so cell ids are porofrac's."""
import base64
import xml.etree.ElementTree as ET

import numpy as np

_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4",
          "UInt64": "<u8", "UInt32": "<u4", "UInt8": "<u1", "Int8": "<i1"}


def _array(node, header="UInt64"):
    dtype = np.dtype(_TYPES[node.get("type")])
    fmt = node.get("format", "ascii")
    text = (node.text or "").strip()
    if fmt == "ascii":
        return np.array(text.split(), dtype=dtype)
    if fmt != "binary":
        raise ValueError(f"DataArray {node.get('Name')}: format {fmt!r} not supported")
    raw = base64.b64decode("".join(text.split()))
    h = np.dtype(_TYPES[header]).itemsize
    nbytes = int(np.frombuffer(raw[:h], dtype=_TYPES[header])[0])
    return np.frombuffer(raw[h:h + nbytes], dtype=dtype)


def read_triangles(path):
    root = ET.parse(path).getroot()
    if root.get("compressor"):
        raise ValueError(f"{path}: compressed .vtu not supported")
    header = root.get("header_type", "UInt32")
    piece = root.find("UnstructuredGrid/Piece")
    pts = _array(piece.find("Points/DataArray"), header).reshape(-1, 3)
    arrays = {a.get("Name"): _array(a, header) for a in piece.find("Cells")}
    offsets = arrays["offsets"]
    if not np.all(np.diff(np.concatenate([[0], offsets])) == 3):
        raise ValueError(f"{path}: not a triangle mesh")
    tri = arrays["connectivity"].reshape(-1, 3).astype(np.int64)
    return np.ascontiguousarray(pts[:, :2]), tri
