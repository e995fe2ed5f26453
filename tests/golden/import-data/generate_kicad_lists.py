#!/usr/bin/python3
# generate_kicad_lists.py - makes the KiCad placement lists of
# tests/golden/import-kicad and their ground truth, with KiCad itself.
#
# Needs KiCad 6's pcbnew Python module (Debian 12: apt-get install kicad; run
# with /usr/bin/python3). The test suite does not: the files it writes are
# committed. Run from anywhere:
#
#     /usr/bin/python3 tests/golden/import-data/generate_kicad_lists.py
#
# It builds a board in pcbnew (our own parts: footprints with real KiCad
# library names, two or three pads each at places that make every rotation
# visible), turns some parts over to the bottom with pcbnew's own Flip (both
# of KiCad's flip directions), and exports the placement lists with KiCad's
# own exporter (PLACE_FILE_EXPORTER, the code behind File > Fabrication
# Outputs > Component Placement):
#   kicad6_bottom.pos        ASCII .pos, mm, bottom side, auxiliary origin
#   kicad6_csv_bottom.csv    CSV, mm, bottom side, auxiliary origin
#   kicad6_bottom_inch.pos   ASCII .pos, inches, bottom side, auxiliary origin
#   kicad6_top.pos           ASCII .pos, mm, top side, auxiliary origin
#   kicad6_all_page.pos      ASCII .pos, mm, both sides, page origin
# KiCad 6 writes bottom-side x negated (as seen from the bottom) and every
# rotation as seen from the top. KiCad 7 and later write x as seen from the
# top unless "negative X" is asked for; no KiCad 7 is packaged for Debian 12,
# so one list in KiCad 8's layout is written here from the same board, byte
# for byte as KiCad 8's place_file_exporter.cpp formats it:
#   kicad8_bottom.pos        KiCad 8 layout, mm, bottom side, auxiliary origin
#
# The ground truth, import-data/kicad-truth.csv: for every pad of every
# part, where KiCad put it on the board (pcbnew's own pad position, seen
# from the top, y up, mm, relative to the auxiliary origin) and where the pad
# is in the footprint as drawn in the library (y up, mm). A correct import
# places each part so that its library pads land on KiCad's pads once the
# board is turned over (tests/unit/backend/cad_import_test.cpp checks it).
import datetime
import os
import sys

import pcbnew

HERE = os.path.dirname(os.path.abspath(__file__))
SUITE = os.path.join(HERE, "..", "import-kicad")
MM = pcbnew.FromMM

# The auxiliary origin: the board's lower left corner (KiCad's y points down).
AUX = (90.0, 140.0)

# Footprint library name, value, library pads (number, x, y in KiCad's
# footprint frame: y down, mm).
KINDS = {
    "C_0805_2012Metric": ("10uF", [("1", -0.95, 0.0), ("2", 0.95, 0.0)]),
    "R_0402_1005Metric": ("10k", [("1", -0.51, 0.0), ("2", 0.51, 0.0)]),
    "SOT-23": ("BC847", [("1", -0.95, 1.1), ("2", 0.95, 1.1), ("3", 0.0, -1.1)]),
    "LED_WS2812B_PLCC4_5.0x5.0mm_P3.2mm": ("WS2812B", [("1", 2.45, -1.6), ("2", 2.45, 1.6), ("3", -2.45, 1.6)]),
    "SOIC-8_3.9x4.9mm_P1.27mm": ("LM358", [("1", -2.475, -1.905), ("4", -2.475, 1.905), ("8", 2.475, -1.905)]),
    "C_0603_1608Metric": ("100n", [("1", -0.775, 0.0), ("2", 0.775, 0.0)]),
}

# Designator, footprint, x, y (KiCad page coordinates, y down, mm),
# orientation (deg), side: "top", or the bottom flipped top/bottom
# ("bottom") or left/right ("bottom-lr").
PARTS = [
    ("C1", "C_0805_2012Metric", 100.0, 120.0, 0.0, "top"),
    ("C2", "C_0805_2012Metric", 104.0, 120.0, 90.0, "bottom"),
    ("C3", "C_0603_1608Metric", 108.0, 121.5, 180.0, "bottom"),
    ("C4", "C_0603_1608Metric", 112.0, 118.25, -90.0, "bottom-lr"),
    ("R1", "R_0402_1005Metric", 100.0, 110.0, 45.0, "top"),
    ("R2", "R_0402_1005Metric", 104.5, 110.0, 30.0, "bottom"),
    ("R3", "R_0402_1005Metric", 109.0, 111.0, -135.0, "bottom"),
    ("R4", "R_0402_1005Metric", 113.0, 109.0, 12.5, "bottom-lr"),
    ("Q1", "SOT-23", 120.0, 120.0, 0.0, "bottom"),
    ("Q2", "SOT-23", 126.0, 118.0, 270.0, "bottom"),
    ("Q3", "SOT-23", 132.0, 121.0, 135.0, "top"),
    ("D1", "LED_WS2812B_PLCC4_5.0x5.0mm_P3.2mm", 122.0, 105.0, 0.0, "bottom"),
    ("D2", "LED_WS2812B_PLCC4_5.0x5.0mm_P3.2mm", 132.0, 104.0, 60.0, "bottom-lr"),
    ("U1", "SOIC-8_3.9x4.9mm_P1.27mm", 145.0, 112.0, 90.0, "bottom"),
    ("U2", "SOIC-8_3.9x4.9mm_P1.27mm", 155.0, 112.0, 0.0, "top"),
]


def make_board():
    board = pcbnew.BOARD()
    board.GetDesignSettings().SetAuxOrigin(pcbnew.wxPoint(MM(AUX[0]), MM(AUX[1])))
    for ref, fpname, x, y, angle, side in PARTS:
        value, pads = KINDS[fpname]
        fp = pcbnew.FOOTPRINT(board)
        fp.SetFPIDAsString(fpname)
        fp.SetReference(ref)
        fp.SetValue(value)
        fp.SetAttributes(pcbnew.FP_SMD)
        for number, px, py in pads:
            pad = pcbnew.PAD(fp)
            pad.SetNumber(number)
            pad.SetAttribute(pcbnew.PAD_ATTRIB_SMD)
            pad.SetShape(pcbnew.PAD_SHAPE_RECT)
            pad.SetSize(pcbnew.wxSize(MM(0.5), MM(0.5)))
            pad.SetLayerSet(pad.SMDMask())
            pad.SetPos0(pcbnew.wxPoint(MM(px), MM(py)))
            pad.SetPosition(pcbnew.wxPoint(MM(px), MM(py)))
            fp.Add(pad)
        board.Add(fp)
        fp.SetPosition(pcbnew.wxPoint(MM(x), MM(y)))
        fp.SetOrientationDegrees(angle)
        if side.startswith("bottom"):
            fp.Flip(fp.GetPosition(), side == "bottom-lr")
    return board


def export(board, name, mm=True, top=True, bottom=True, csv=False, aux=True):
    exporter = pcbnew.PLACE_FILE_EXPORTER(board, mm, False, False, top, bottom, csv, aux)
    text = exporter.GenPositionData()
    with open(os.path.join(SUITE, name), "w", encoding="utf-8", newline="") as out:
        out.write(text)


def kicad8_bottom(board, date):
    # KiCad 8.0's place_file_exporter.cpp, ASCII form, bottom side, mm,
    # auxiliary origin, "negative X" not asked for.
    rows = []
    for fp in board.GetFootprints():
        if fp.GetLayer() != pcbnew.B_Cu:
            continue
        pos = fp.GetPosition()
        x = (pos.x - MM(AUX[0])) / 1e6
        y = -(pos.y - MM(AUX[1])) / 1e6
        rows.append((fp.GetReference(), fp.GetValue(), str(fp.GetFPID().GetLibItemName()), x, y,
                     fp.GetOrientationDegrees()))
    rows.sort(key=lambda r: (r[0].rstrip("0123456789"), int(r[0][len(r[0].rstrip("0123456789")):])))
    len_ref = max([8] + [len(r[0]) for r in rows])
    len_val = max([8] + [len(r[1]) for r in rows])
    len_pkg = max([16] + [len(r[2]) for r in rows])
    text = "### Footprint positions - created on %s ###\n" % date
    text += "### Printed by KiCad version 8.0.3\n"
    text += "## Unit = mm, Angle = deg.\n"
    text += "## Side : bottom\n"
    text += "%-*s  %-*s  %-*s  %9.9s  %9.9s  %8.8s  %s\n" % (len_ref, "# Ref", len_val, "Val", len_pkg, "Package",
                                                           "PosX", "PosY", "Rot", "Side")
    for ref, val, pkg, x, y, rot in rows:
        text += "%-*s  %-*s  %-*s  %9.4f  %9.4f  %8.4f  %s\n" % (len_ref, ref, len_val, val, len_pkg, pkg, x, y, rot,
                                                                "bottom")
    text += "## End\n"
    with open(os.path.join(SUITE, "kicad8_bottom.pos"), "w", encoding="utf-8", newline="") as out:
        out.write(text)


def truth(board):
    lines = ["ref,side,pad,library_x_mm,library_y_mm,board_x_mm,board_y_mm"]
    for ref, fpname, *_ in PARTS:
        fp = board.FindFootprintByReference(ref)
        library = {number: (px, -py) for number, px, py in KINDS[fpname][1]}
        side = "bottom" if fp.GetLayer() == pcbnew.B_Cu else "top"
        for pad in fp.Pads():
            p = pad.GetPosition()
            lx, ly = library[pad.GetNumber()]
            lines.append("%s,%s,%s,%.6f,%.6f,%.6f,%.6f" % (ref, side, pad.GetNumber(), lx, ly,
                                                          (p.x - MM(AUX[0])) / 1e6, -(p.y - MM(AUX[1])) / 1e6))
    with open(os.path.join(HERE, "kicad-truth.csv"), "w", encoding="utf-8", newline="") as out:
        out.write("\n".join(lines) + "\n")


def main():
    if not pcbnew.GetBuildVersion().startswith("6."):
        sys.exit("this generator is written for KiCad 6 (found %s)" % pcbnew.GetBuildVersion())
    os.makedirs(SUITE, exist_ok=True)
    board = make_board()
    export(board, "kicad6_bottom.pos", top=False)
    export(board, "kicad6_csv_bottom.csv", top=False, csv=True)
    export(board, "kicad6_bottom_inch.pos", mm=False, top=False)
    export(board, "kicad6_top.pos", bottom=False)
    export(board, "kicad6_all_page.pos", aux=False)
    kicad8_bottom(board, "2024-07-04T11:35:51+0200")
    truth(board)


if __name__ == "__main__":
    main()
