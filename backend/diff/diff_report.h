// Renderings of a ProgramDiff (backend/diff/program_diff.h): the review text, the
// JSON document (schema in docs/diff.md) and the board plot as SVG. All three
// are deterministic: the same diff gives the same bytes.
#pragma once

#include <string>

#include "backend/diff/program_diff.h"

namespace smtcal::diff {

// One line per change ("NEW.place:33: moved point R1 (was OLD.place:33): ..."),
// then the summary and the gate's verdict.
std::string FormatDiffText(const ProgramDiff& diff);
// {"schema": "smtcal-diff/1", "old", "new", "threshold_um", "changes": [...], "summary": {...}}.
std::string FormatDiffJson(const ProgramDiff& diff);
// The board: one panel per frame the static targets can be drawn in (the
// robot base; a fixture's frame when no cell gave its pose), old positions as
// dots, arrows to the new ones enlarged so micrometre moves are visible (the
// scale is stated), added and removed targets marked, the largest moves
// labelled.
std::string PlotDiffSvg(const ProgramDiff& diff);

}  // namespace smtcal::diff
