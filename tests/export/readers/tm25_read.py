#!/usr/bin/env python3
"""Reads ANSI/IES TM-25-13 ray files as the standard's layout describes them and checks them
against it, sharing nothing with lumislab's reader; prints one JSON line per file (header, flags,
texts, ray count, flux sums, the first rays) and exits 1 naming the file and the section when a
file breaks the layout.

No TM-25 reader could be found in the npm registry or Debian's archive (docs/formats.md §17),
so this one is written from the layout: ANSI/IES TM-25-13 section 4.7, as its public reference
reader reads it (JuliusMuschaweck/TM25RaySetTools, TM25Library/TM25_impl.h, the header read
section by section 4.7.1.1-4.7.6 with the standard's section numbers). Little-endian, int32 and
float32 (the ray count uint64):
  4.7.1  "TM25", version 2013, creation method, luminous flux, radiant flux, number of rays,
         date (28 bytes), start position, spectral data identifier (0-4), single / min / max
         wavelength, number of spectral tables, number of additional ray items, size of the
         additional text block (a multiple of 32), 168 reserved bytes;
  4.7.2  eight flags 0/1: position (must be 1), direction (must be 1), radiant flux,
         wavelength, luminous flux, Stokes, tristimulus, spectrum index (1 only with spectral
         identifier 4); not both flux flags 0;
  4.7.3  nine texts of 1000 UTF-32 characters;
  4.7.4  spectral tables (each: int32 n, then n float32 (wavelength, weight) pairs; the block
         padded to 32 bytes);
  4.7.5  512-byte names of the additional items; 4.7.6 the additional text block;
  rays   float32 each: x y z, kx ky kz, then the flagged items in that order, then additional.

Usage: tm25_read.py file.ray...
"""
import json
import math
import struct
import sys


class LayoutError(Exception):
    pass


TEXTS = ("name", "manufacturer", "model_creator", "rayfile_creator", "equipment", "camera",
         "light_source_operation", "additional_info", "data_reference")
FLAGS = ("position", "direction", "radiant_flux", "wavelength", "luminous_flux", "stokes",
         "tristimulus", "spectrum_index")


def read(path):
    data = open(path, "rb").read()
    at = 0

    def take(fmt, section):
        nonlocal at
        size = struct.calcsize("<" + fmt)
        if at + size > len(data):
            raise LayoutError(f"section {section}: the file ends before it")
        v = struct.unpack_from("<" + fmt, data, at)
        at += size
        return v if len(v) > 1 else v[0]

    if take("4s", "4.7.1.1") != b"TM25":
        raise LayoutError("section 4.7.1.1: file type is not TM25")
    out = {"file": path, "bytes": len(data)}
    out["version"] = take("i", "4.7.1.2")
    if out["version"] != 2013:
        raise LayoutError(f"section 4.7.1.2: version {out['version']}, expected 2013")
    out["creation_method"] = take("i", "4.7.1.3")
    out["luminous_flux"] = take("f", "4.7.1.4")
    out["radiant_flux"] = take("f", "4.7.1.5")
    for key, section in (("luminous_flux", "4.7.1.4"), ("radiant_flux", "4.7.1.5")):
        v = out[key]
        if not (math.isnan(v) or v >= 0):
            raise LayoutError(f"section {section}: expected a flux >= 0 or NaN, got {v}")
        if math.isnan(v):
            out[key] = None  # JSON has no NaN
    out["rays"] = take("Q", "4.7.1.6")
    out["date"] = take("28s", "4.7.1.7").rstrip(b"\0").decode("ascii", "replace")
    out["start_position"] = take("i", "4.7.1.8")
    out["spectral_identifier"] = take("i", "4.7.1.9")
    if not 0 <= out["spectral_identifier"] <= 4:
        raise LayoutError("section 4.7.1.9: spectral data identifier outside 0-4")
    out["wavelengths"] = take("3f", "4.7.1.10-12")
    if out["spectral_identifier"] == 1 and not out["wavelengths"][0] > 0:
        raise LayoutError("section 4.7.1.10: single wavelength must be > 0 with identifier 1")
    out["wavelengths"] = [None if math.isnan(w) else w for w in out["wavelengths"]]
    tables = take("i", "4.7.1.13")
    extra = take("i", "4.7.1.14")
    text_block = take("i", "4.7.1.15")
    if tables < 0 or extra < 0 or text_block < 0 or text_block % 32:
        raise LayoutError("sections 4.7.1.13-15: negative counts or a text block size that "
                          "is not a multiple of 32")
    take("168s", "4.7.1.16 (reserved)")
    flags = dict(zip(FLAGS, take("8i", "4.7.2")))
    for name, v in flags.items():
        if v not in (0, 1):
            raise LayoutError(f"section 4.7.2: {name} flag {v}, expected 0 or 1")
    if flags["position"] != 1 or flags["direction"] != 1:
        raise LayoutError("section 4.7.2.1-2: position and direction flags must be 1")
    if not (flags["radiant_flux"] or flags["luminous_flux"]):
        raise LayoutError("section 4.7.2.3/5: no flux column")
    if flags["spectrum_index"] != (out["spectral_identifier"] == 4):
        raise LayoutError("section 4.7.2.8: spectrum index flag iff spectral identifier 4")
    out["flags"] = flags
    for name in TEXTS:
        chars = take("1000I", "4.7.3 (" + name + ")")
        chars = chars[:chars.index(0)] if 0 in chars else chars
        out[name] = "".join(chr(c) for c in chars)
    start = at
    for t in range(tables):
        n = take("i", "4.7.4 (pairs in a spectral table)")
        if n <= 0:
            raise LayoutError("section 4.7.4: a spectral table of no pairs")
        take(f"{2 * n}f", "4.7.4")
    at += (-(at - start)) % 32
    at += 512 * extra + text_block
    columns = 6 + flags["radiant_flux"] + flags["wavelength"] + flags["luminous_flux"] + \
        3 * flags["stokes"] + 2 * flags["tristimulus"] + flags["spectrum_index"] + extra
    if len(data) - at != out["rays"] * columns * 4:
        raise LayoutError(f"rays: {out['rays']} rays x {columns} floats need "
                          f"{out['rays'] * columns * 4} bytes, the file has {len(data) - at}")
    flux_column = 6 if flags["radiant_flux"] else None
    lum_column = 6 + flags["radiant_flux"] + flags["wavelength"] if flags["luminous_flux"] \
        else None
    sums = {"radiant": 0.0, "luminous": 0.0}
    first = []
    for r in range(out["rays"]):
        ray = struct.unpack_from(f"<{columns}f", data, at + 4 * columns * r)
        if not all(math.isfinite(v) for v in ray):
            raise LayoutError(f"ray {r + 1}: a value is not finite")
        norm = math.sqrt(ray[3] ** 2 + ray[4] ** 2 + ray[5] ** 2)
        if abs(norm - 1) > 1e-3:
            raise LayoutError(f"ray {r + 1}: direction of length {norm}, expected a unit vector")
        for key, column in (("radiant", flux_column), ("luminous", lum_column)):
            if column is not None:
                if ray[column] < 0:
                    raise LayoutError(f"ray {r + 1}: negative {key} flux")
                sums[key] += ray[column]
        if r < 5:
            first.append(list(ray))
    out["flux_sum"] = sums
    out["first_rays"] = first
    return out


def main():
    status = 0
    for path in sys.argv[1:]:
        try:
            print(json.dumps(read(path)))
        except (LayoutError, OSError) as e:
            print(f"{path}: {e}", file=sys.stderr)
            status = 1
    sys.exit(status)


if __name__ == "__main__":
    main()
