"""The record in which gmsh's child process (:mod:`gatetherm.geometry.isolate`) sends its result
back: a kind byte, a length, and for a result a JSON header and numeric arrays (:func:`pack`,
:func:`unpack`): checked as it is read, no pickle."""
from __future__ import annotations

import json
import struct

import numpy as np

_DTYPES = {"<f8", "<i8", "<i4", "|i1", "|b1"}
_RESULT, _ERROR, _CRASH = b"R", b"E", b"X"


def _record(kind: bytes, payload: bytes) -> bytes:
    return kind + struct.pack("<Q", len(payload)) + payload


def pack(meta: dict, arrays: dict[str, np.ndarray]) -> bytes:
    """A result record: ``meta`` (JSON) and the arrays (numeric, C order)."""
    arrays = {k: np.ascontiguousarray(v) for k, v in arrays.items()}
    head = json.dumps({"meta": meta, "arrays": [[k, v.dtype.str, list(v.shape)] for k, v in arrays.items()]}).encode()
    return _record(_RESULT, struct.pack("<Q", len(head)) + head + b"".join(v.tobytes() for v in arrays.values()))


def unpack(payload: bytes) -> tuple[dict, dict[str, np.ndarray]]:
    """Read a result record's payload (from a sandboxed child: checked, no pickle)."""
    (n,) = struct.unpack_from("<Q", payload)
    head = json.loads(payload[8:8 + n])
    buf, at, arrays = memoryview(payload), 8 + n, {}
    for name, dtype, shape in head["arrays"]:
        if dtype not in _DTYPES or not all(isinstance(s, int) and s >= 0 for s in shape):
            raise ValueError(f"bad array {name!r} in the result of gmsh's process")
        size = int(np.prod(shape)) * np.dtype(dtype).itemsize
        if at + size > len(payload):
            raise ValueError("truncated result from gmsh's process")
        arrays[name] = np.frombuffer(buf[at:at + size], dtype=dtype).reshape(shape).copy()
        at += size
    if at != len(payload):
        raise ValueError("truncated result from gmsh's process")
    return head["meta"], arrays
