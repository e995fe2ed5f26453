#!/usr/bin/python3
# generate_kicad_demo_lists.py - placement lists of two real KiCad boards,
# exported by KiCad itself, with the boards' outlines as ground truth.
#
# Needs KiCad 6's pcbnew Python module and the boards of Debian 12's
# kicad-demos package (apt-get install kicad kicad-demos; run with
# /usr/bin/python3). The test suite does not: the files it writes are
# committed. Run from anywhere:
#
#     /usr/bin/python3 tests/golden/import-data/generate_kicad_demo_lists.py
#
# The boards are KiCad's demos (GPL-2+, (c) the KiCad developers; see
# SAMPLES.md): StickHub (a USB hub on a 16.6 x 40.1 mm board, parts on both
# sides) and video (189 parts on both sides). For each, the auxiliary origin
# ("drill/place file origin") is put on the lower left corner of the board's
# outline (the bounding box of its Edge.Cuts), as a user does before
# exporting with "Use drill/place file origin", and the lists are written by
# KiCad's own exporter (PLACE_FILE_EXPORTER, File > Fabrication Outputs >
# Component Placement: ASCII, mm, that option ticked):
#   import-kicad/stickhub_top.pos, stickhub_bottom.pos   one side each
#   import-kicad/video_all.pos                            both sides in one file
# KiCad's lists carry no outline; stickhub-truth.csv holds it (the board's
# width and height, mm) and where KiCad has every footprint (x, y relative to
# the auxiliary origin, y up, seen from the top), so a test can check that
# the top and the bottom of the board land in the same pocket of the fixture.
import os
import sys

import pcbnew

HERE = os.path.dirname(os.path.abspath(__file__))
SUITE = os.path.join(HERE, "..", "import-kicad")
DEMOS = "/usr/share/kicad/demos"


def load(path):
    board = pcbnew.LoadBoard(os.path.join(DEMOS, path))
    box = board.GetBoardEdgesBoundingBox()
    # KiCad's y points down: the lower left corner is (left, bottom).
    board.GetDesignSettings().SetAuxOrigin(pcbnew.wxPoint(box.GetLeft(), box.GetBottom()))
    return board, box


def export(board, name, top=True, bottom=True):
    exporter = pcbnew.PLACE_FILE_EXPORTER(board, True, False, False, top, bottom, False, True)
    text = exporter.GenPositionData()
    with open(os.path.join(SUITE, name), "w", encoding="utf-8", newline="") as out:
        out.write(text)


def truth(board, box, name):
    left, bottom = box.GetLeft(), box.GetBottom()
    lines = ["# outline,%.6f,%.6f" % (box.GetWidth() / 1e6, box.GetHeight() / 1e6),
             "ref,side,x_mm,y_mm"]
    for fp in sorted(board.GetFootprints(), key=lambda f: f.GetReference()):
        pos = fp.GetPosition()
        side = "bottom" if fp.GetLayer() == pcbnew.B_Cu else "top"
        lines.append("%s,%s,%.6f,%.6f" % (fp.GetReference(), side, (pos.x - left) / 1e6, -(pos.y - bottom) / 1e6))
    with open(os.path.join(HERE, name), "w", encoding="utf-8", newline="") as out:
        out.write("\n".join(lines) + "\n")


def main():
    if not pcbnew.GetBuildVersion().startswith("6."):
        sys.exit("this generator is written for KiCad 6 (found %s)" % pcbnew.GetBuildVersion())
    board, box = load("stickhub/StickHub.kicad_pcb")
    export(board, "stickhub_top.pos", bottom=False)
    export(board, "stickhub_bottom.pos", top=False)
    truth(board, box, "stickhub-truth.csv")
    board, box = load("video/video.kicad_pcb")
    export(board, "video_all.pos")


if __name__ == "__main__":
    main()
