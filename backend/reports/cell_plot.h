// `smtcal cell plot`: the cell as a picture (docs/cell.md, "A picture of the
// cell"). One standalone SVG, robot base frame, y up, mm:
//   - the whole cell: the robot's travel, every calibrated region (its
//     bounds filled, its table's domain dashed), every fixture at its nominal
//     pose (the frame S1-S2-S3, the marker edges, the scan paths with their
//     nominal trips, the pocket boards go into), every feeder's pick points,
//     and, given a program, its placements with each part's orientation;
//   - a close-up of each fixture with the trips numbered (T1, T2, ...) and
//     the placements named (a statement placed several times, as the
//     layers' parts are, with its run: "R1 + X(dx) (2/3)");
//   - a close-up of the feeders with every lane or pocket numbered
//     (Pallet(n, k)'s k);
//   - every finding (an error or a warning of the cell or the program)
//     marked in red where it is, numbered, and listed under the panels with
//     its kind, place and words.
// Each panel has axes in mm and a scale bar; one legend says what every mark
// is. Labels never cover each other or a mark: a name with no room is left
// out and counted. Deterministic: the same cell and program give the same
// bytes. Each panel's group carries its mapping (data-x0-mm, data-y1-mm,
// data-px-per-mm, data-left-px, data-top-px: px = left + (x - x0) * scale,
// py = top + (y1 - y) * scale) and each finding's mark its kind and place
// in mm, so a test can check a mark lies where its finding is.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/cell.h"

namespace smtcal {

// A motion target of a program, where it goes at the fixture's nominal pose.
struct PlottedTarget {
  std::string name;  // as written: "R1", "Pallet(1, 3)"
  double x_mm = 0, y_mm = 0;  // required position, robot base frame
  double u_deg = 0;           // required rotation, robot base frame: the part's orientation
  bool place = false;         // a Place (else a Pick or a move)
  int fixture = -1;           // index into cell.fixtures; -1: the robot base
  SourceRange statement;      // where its statement is (a diagnostic there marks it)
  int run = 1, runs = 1;      // its statement's run-th of `runs` targets (a loop's passes)
};

// One diagnostic of the cell or the program as the picture marks it.
struct PlotFinding {
  DiagKind kind = DiagKind::CellTomlSyntax;
  Severity severity = Severity::Error;
  std::string where;    // "paper.cell.toml:163:1"
  std::string subject;  // what is marked: "trip T1 of fixture 'Board'", "feeder 'Bank3'"
  std::string message;  // the diagnostic's words
  // The places marked, robot base frame; empty when it has no place in the
  // picture (listed only).
  std::vector<Eigen::Vector2d> marks_mm;
  std::vector<Eigen::Vector2d> outline_mm;  // a shape drawn in red with it (a pocket's corners); may be empty
};

// Every diagnostic in `diags` as a finding, in their order (the sources'
// order of Diagnostics::all()), placed by what it is about: a trip outside
// every table at the trip, a capture range at the trip or the leg and edge
// that limit it, a pocket over its region's edge at the corner farthest out
// (and the pocket outlined), a point outside the robot's travel at that
// point, anything else in a [[region]], [[fixture]], [[fixture.scan_path]]
// or [[feeder]] table at what the table describes, a program's diagnostic
// at the targets of its statement; the rest (the [robot] table, a table
// file's rows, the program's declarations) listed without a mark.
std::vector<PlotFinding> LocateFindings(const cell::Cell& cell, const std::vector<PlottedTarget>& targets,
                                        const Diagnostics& diags);

// `title` names the cell file; `program` the program ("" without one);
// `program_note` says why a program's placements are missing ("" when they
// are drawn or there is no program).
std::string PlotCellSvg(const cell::Cell& cell, std::string_view title, std::string_view program,
                        const std::vector<PlottedTarget>& targets, const std::vector<PlotFinding>& findings = {},
                        std::string_view program_note = "");

}  // namespace smtcal
