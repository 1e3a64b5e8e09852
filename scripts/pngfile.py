"""An 8-bit RGB PNG from rows of filtered scanlines, with Python's standard library only: for the
scripts that write the demo scenes' images (planet-map.py, rocket.py)."""

import struct
import zlib


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def write_png(path, width, height, rows):
    """Write `rows` (each a filter byte then width RGB triples) as an 8-bit RGB PNG."""
    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(b"".join(rows), 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)
