// Which feeder holds which part, for `smtcal import` (docs/import.md,
// "The feeders file"). Feeders come from the cell's [[feeder]] tables and
// from an optional feeders file (--feeders FEEDERS.toml) that adds feeders
// of its own and [[map]] rules:
//
//   [[feeder]]                          # same keys as the cell's, plus rotation_offset_deg
//   name = "Lane7"
//   pick = [230.0, 10.0, -11.5, 0.0]    # x, y, z mm, u deg (robot base)
//   package = "SOT-23*"                 # globs, any case; a string or an array
//   value = "BC847*"
//   rotation_offset_deg = 180.0         # added to the part's rotation (orientation in the tape)
//   kind = "tape"                       # or "tray" (cell.h, FeederKind)
//   pallet = { last = [..], back = [..], columns = 4, rows = 2 }
//
//   part_number = "BC847B,215"          # for the set-up sheet (these four keys on
//   tape_width_mm = 8                   # [[lane]] too; none of them decides where
//   tape_pitch_mm = 4                   # a part goes)
//   location = "bank 2, slot 7"         # where the operator finds it
//
//   [[map]]                             # first matching rule wins
//   feeder = "Bank1"                    # a feeder of the cell or of this file
//   lane = 3                            # a pallet feeder's pick point k (Pallet(n, k)); default: next pocket
//   package = "R_0603*"                 # at least one of package, value, designator;
//   value = "10k"                       # each a glob or an array of globs
//   designator = ["R1", "R2", "R7*"]
//   rotation_offset_deg = 90.0
//   part_number = "RC0603FR-0710KL"     # the parts it maps, for the set-up sheet
//
//   [[lane]]                            # what a lane (or pocket) holds, for the set-up sheet
//   feeder = "Bank1"                    # a feeder of the cell or of this file
//   lane = 3                            # omitted: every lane of the feeder
//   value = "10k"                       # what it holds (a program has no list to say)
//   package = "0805"
//   part_number = "RC0805FR-0710KL"
//   tape_width_mm = 8
//   tape_pitch_mm = 4
//   location = "bank 1, slot 3"
//
// A part goes to the first [[map]] that matches it; else to the feeder whose
// package and value match it most specifically (both > one > none given is
// never used), the first in order (cell, then file) among equals.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "base/result.h"
#include "calibration/cell.h"
#include "frontend/cad/cad_row.h"

namespace smtcal::cad {

// A feeder as the import sees it, from the cell or the feeders file.
struct FeederSpec {
  std::string name;
  SourceRange name_range;
  SourceRange range;  // its table
  std::array<double, 4> pick{};  // x, y, z mm, u deg (robot base)
  std::optional<std::array<double, 4>> pallet_last;
  std::optional<std::array<double, 4>> pallet_back;
  int columns = 1;
  int rows = 1;
  std::vector<std::string> packages;  // globs; empty = any package
  std::string value;                  // glob; empty = any value
  double rotation_offset_deg = 0;
  cell::FeederKind kind = cell::FeederKind::kTape;  // as the cell's `kind` (cell.h), same default
  bool from_cell = false;
  // For the set-up sheet only (a cell's feeders get them from [[lane]]).
  std::string part_number;
  std::string location;
  std::optional<double> tape_width_mm, tape_pitch_mm;

  bool is_pallet() const { return pallet_last.has_value(); }
  // A pallet of tapes whose `package` array names each lane's package.
  bool lanes_by_package() const {
    return kind == cell::FeederKind::kTape && is_pallet() && pick_points() > 1 &&
           static_cast<int>(packages.size()) == pick_points();
  }
  int pick_points() const { return columns * rows; }
};

// [[map]]: parts matching the patterns go to a feeder.
struct FeederRule {
  std::string feeder;
  SourceRange feeder_range;
  SourceRange range;
  // Globs, each a string or an array in the file (a part matches when one of
  // them matches); empty = any.
  std::vector<std::string> packages;
  std::vector<std::string> values;
  std::vector<std::string> designators;
  std::optional<int> lane;  // 1-based pick point of a pallet feeder
  SourceRange lane_range;
  double rotation_offset_deg = 0;
  std::string part_number;  // of the parts it maps, for the set-up sheet
};

// [[lane]]: what a feeder's lane or pocket holds, for the set-up sheet; it
// decides nothing about where parts go.
struct LaneNote {
  std::string feeder;
  SourceRange feeder_range;
  std::optional<int> lane;  // nullopt: every lane of the feeder
  SourceRange lane_range;
  std::string value, package, part_number, location;
  std::optional<double> tape_width_mm, tape_pitch_mm;
};

struct FeedersFile {
  std::uint32_t file = 0;
  std::vector<FeederSpec> feeders;
  std::vector<FeederRule> rules;
  std::vector<LaneNote> lanes;
};

// What the set-up sheet knows of one lane: [[lane]] for that lane, over
// [[lane]] for its whole feeder, over the feeder's own keys. value and
// package come from [[lane]] only (a feeder's are patterns for matching).
struct LaneDescription {
  std::string value, package, part_number, location;
  std::optional<double> tape_width_mm, tape_pitch_mm;
  bool lane_location = false;  // `location` is the lane's own (else its feeder's, or none)
};

// Reads a feeders file. A file that cannot be read is an Error; mistakes in
// it are diagnostics and then the value is nullopt.
Result<std::optional<FeedersFile>> LoadFeeders(const std::string& path, SourceManager& sources, Diagnostics& diags);

// Where a part is picked: a feeder, and for a pallet feeder a fixed pick
// point (`lane`) or, without one, the next pocket.
struct FeederMatch {
  std::size_t feeder = 0;  // index into FeederTable::feeders()
  std::optional<int> lane;
  double rotation_offset_deg = 0;
  std::string part_number;  // a [[map]]'s, for the set-up sheet
};

class FeederTable {
 public:
  // The cell's feeders, then the file's; rules resolved to feeders. Reports
  // duplicate feeder names, rules naming unknown feeders and lanes beyond a
  // feeder's pallet; nullopt when any was an error.
  static std::optional<FeederTable> Build(const std::vector<cell::Feeder>& cell_feeders, FeedersFile file,
                                          Diagnostics& diags);

  std::optional<FeederMatch> Find(const Row& row) const;
  const std::vector<FeederSpec>& feeders() const { return feeders_; }
  // What the set-up sheet knows of pick point k (1-based) of feeders()[feeder].
  LaneDescription Describe(std::size_t feeder, int k) const;
  // Whether a [[map]] looks at designators (else Find depends only on the
  // package and the value, and its answers can be cached by them).
  bool matches_designators() const {
    for (const FeederRule& rule : rules_) {
      if (!rule.designators.empty()) return true;
    }
    return false;
  }

 private:
  std::vector<FeederSpec> feeders_;
  std::vector<FeederRule> rules_;
  std::vector<std::size_t> rule_feeder_;  // per rule
  std::vector<LaneNote> lanes_;
  std::vector<std::size_t> lane_feeder_;  // per [[lane]]
};

}  // namespace smtcal::cad
