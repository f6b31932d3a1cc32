#!/usr/bin/env python3
"""Reads EULUMDAT (.ldt) files as the format's public layout describes them and checks them
against it, sharing nothing with lumislab's reader; prints one JSON line per file (what it read)
and exits 1 naming the file and the line when a file breaks the layout.

No EULUMDAT reader could be found in the npm registry or Debian's archive (docs/formats.md §17),
so this one is written from the layout as published:
  * A. W. Stockmar, "EULUMDAT - ein Leuchtendatenformat fuer den europaeischen
    Beleuchtungsplaner", Licht '90, pp. 641-644; the field table as reproduced by Helios32
    (http://www.helios32.com/Eulumdat.htm), Photometric Toolbox's documentation
    (https://docs.agi32.com/PhotometricToolbox/Content/Open_Tool/eulumdat_file_format.htm) and
    Zumtobel's COPHOS appendix (http://www.ltblight.com/English.lproj/LTBLhelp/pages/
    eulumdatformat.html, which adds: every field ends with an MS-DOS CR+LF pair).
  * Lines 1-25 one field each; line 26 n, the number of standard lamp sets; n times six lines
    26a-26f (number of lamps, type, total flux, colour temperature, colour rendering, wattage);
    ten direct ratios (line 27, room indices 0.60 ... 5.00); Mc C angles (line 28); Ng gamma
    angles (line 29); then the intensities in cd/klm, Ng per stored C plane, one value a line.
  * Stored C planes by Isym: 0 all Mc, 1 one, 2 and 3 Mc/2 + 1, 4 Mc/4 + 1.
  * Ityp: 1 point source symmetric about the vertical axis, 2 linear, 3 any other point source
    (Helios32's and COPHOS's table; Photometric Toolbox also lists 0).

Usage: ldt_read.py file.ldt...
"""
import json
import math
import sys


class LayoutError(Exception):
    pass


def number(text, where):
    try:
        v = float(text.strip().replace(",", "."))
    except ValueError:
        raise LayoutError(f"{where}: expected a number, got {text.strip()!r}")
    if not math.isfinite(v):
        raise LayoutError(f"{where}: expected a finite number, got {text.strip()!r}")
    return v


def integer(text, where, lo, hi):
    v = number(text, where)
    if v != int(v) or not lo <= v <= hi:
        raise LayoutError(f"{where}: expected an integer in [{lo}, {hi}], got {text.strip()!r}")
    return int(v)


def read(path):
    raw = open(path, "rb").read()
    text = raw.decode("latin-1")  # the format predates Unicode: one byte a character
    crlf = text.count("\r\n")
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    lines = [l[:-1] if l.endswith("\r") else l for l in lines]
    pos = 0

    def take(name):
        nonlocal pos
        if pos >= len(lines):
            raise LayoutError(f"line {pos + 1} ({name}): the file ends before it")
        pos += 1
        return lines[pos - 1]

    out = {"file": path, "lines": len(lines), "crlf_lines": crlf}
    out["company"] = take("company")
    out["ityp"] = integer(take("Ityp"), "line 2 (Ityp)", 1, 3)
    out["isym"] = integer(take("Isym"), "line 3 (Isym)", 0, 4)
    out["mc"] = integer(take("Mc"), "line 4 (Mc)", 1, 721)
    out["dc"] = number(take("Dc"), "line 5 (Dc)")
    out["ng"] = integer(take("Ng"), "line 6 (Ng)", 1, 361)
    out["dg"] = number(take("Dg"), "line 7 (Dg)")
    for n, key in ((8, "report"), (9, "luminaire"), (10, "luminaire_number"), (11, "file_name"),
                   (12, "date_user")):
        out[key] = take(key)
    for n, key in enumerate(("length", "width", "height", "area_length", "area_width",
                             "area_height_c0", "area_height_c90", "area_height_c180",
                             "area_height_c270", "dff", "lorl", "conversion", "tilt"), 13):
        out[key] = number(take(key), f"line {n} ({key})")
    for n in (1, 8, 9, 10, 12):  # text fields: at most 78 characters
        if len(lines[n - 1]) > 78:
            raise LayoutError(f"line {n}: more than 78 characters")
    if not 0 <= out["dff"] <= 100:
        raise LayoutError(f"line 22 (DFF): expected a percentage, got {out['dff']}")
    sets = integer(take("n"), "line 26 (number of lamp sets)", 1, 100)
    out["lamp_sets"] = []
    for s in range(sets):
        where = f"lamp set {s + 1}"
        count = number(take("26a"), f"line 26a of {where} (number of lamps)")
        if count != int(count) or count == 0:
            raise LayoutError(f"line 26a of {where}: expected a non-zero integer, got {count}")
        lamp_type = take("26b")
        flux = number(take("26c"), f"line 26c of {where} (total flux)")
        if not flux > 0:
            raise LayoutError(f"line 26c of {where}: expected a flux > 0, got {flux}")
        cct, cri = take("26d"), take("26e")
        watts = number(take("26f"), f"line 26f of {where} (wattage)")
        out["lamp_sets"].append({"count": int(count), "type": lamp_type, "flux": flux,
                                 "colour_temperature": cct, "colour_rendering": cri,
                                 "watts": watts})
    out["direct_ratios"] = [number(take("27"), f"direct ratio {k + 1} (line 27)")
                            for k in range(10)]
    for k, r in enumerate(out["direct_ratios"]):
        if not 0 <= r <= 1:
            raise LayoutError(f"direct ratio {k + 1}: expected a fraction in [0, 1], got {r}")
    out["c"] = [number(take("28"), f"C angle {k + 1} (line 28)") for k in range(out["mc"])]
    out["gamma"] = [number(take("29"), f"gamma angle {k + 1} (line 29)")
                    for k in range(out["ng"])]
    for name, angles, top in (("C", out["c"], 360), ("gamma", out["gamma"], 180)):
        for k in range(len(angles)):
            if not 0 <= angles[k] <= top or (k and angles[k] <= angles[k - 1]):
                raise LayoutError(f"{name} angle {k + 1}: {angles[k]} out of order or range")
    mc, isym = out["mc"], out["isym"]
    planes = {0: mc, 1: 1, 2: mc // 2 + 1, 3: mc // 2 + 1, 4: mc // 4 + 1}[isym]
    out["stored_planes"] = planes
    out["intensities"] = []  # cd/klm, [plane][gamma]
    for p in range(planes):
        out["intensities"].append(
            [number(take("30"), f"intensity {g + 1} of stored plane {p + 1}")
             for g in range(out["ng"])])
    if pos != len(lines):
        raise LayoutError(f"line {pos + 1}: {len(lines) - pos} line(s) after the last intensity")
    for p, row in enumerate(out["intensities"]):
        for g, v in enumerate(row):
            if v < 0:
                raise LayoutError(f"intensity {g + 1} of stored plane {p + 1}: negative ({v})")
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
