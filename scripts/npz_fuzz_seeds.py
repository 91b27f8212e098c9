#!/usr/bin/env python3
"""Writes seed inputs for the npy and npz fuzz targets (scripts/fuzz.sh) into OUT/npy and
OUT/npz: small IDR-style camera arrays, so that no binary seed needs to be checked in. Standard
library only (struct, zipfile): the .npy format is a magic, a header dict and raw values."""
import os
import struct
import sys
import zipfile


def npy(shape, values, descr="<f8"):
    dims = ", ".join(str(n) for n in shape) + ("," if len(shape) == 1 else "")
    header = "{'descr': '%s', 'fortran_order': False, 'shape': (%s), }" % (descr, dims)
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    code = "<f" if descr == "<f4" else "<d"
    data = b"".join(struct.pack(code, v) for v in values)
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + data


def main(out):
    world_mat = [1000, 0, 400, 40, 0, 1000, 300, 30, 0, 0, 1, 3, 0, 0, 0, 1]
    scale_mat = [2, 0, 0, 1, 0, 2, 0, -1, 0, 0, 2, 5, 0, 0, 0, 1]
    os.makedirs(os.path.join(out, "npy"), exist_ok=True)
    os.makedirs(os.path.join(out, "npz"), exist_ok=True)
    with open(os.path.join(out, "npy", "world_mat.npy"), "wb") as f:
        f.write(npy((4, 4), world_mat))
    with open(os.path.join(out, "npy", "f4.npy"), "wb") as f:
        f.write(npy((3, 4), world_mat[:12], "<f4"))
    for name, compression in (("stored.npz", zipfile.ZIP_STORED),
                              ("deflated.npz", zipfile.ZIP_DEFLATED)):
        with zipfile.ZipFile(os.path.join(out, "npz", name), "w", compression) as z:
            z.writestr("world_mat_0.npy", npy((4, 4), world_mat))
            z.writestr("world_mat_1.npy", npy((3, 4), world_mat[:12], "<f4"))
            z.writestr("scale_mat_0.npy", npy((4, 4), scale_mat))


if __name__ == "__main__":
    main(sys.argv[1])
