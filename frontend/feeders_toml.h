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
//   [[map]]                             # first matching rule wins
//   feeder = "Bank1"                    # a feeder of the cell or of this file
//   lane = 3                            # a pallet feeder's pick point k (Pallet(n, k)); default: next pocket
//   package = "R_0603*"                 # at least one of package, value, designator;
//   value = "10k"                       # each a glob or an array of globs
//   designator = ["R1", "R2", "R7*"]
//   rotation_offset_deg = 90.0
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
};

struct FeedersFile {
  std::uint32_t file = 0;
  std::vector<FeederSpec> feeders;
  std::vector<FeederRule> rules;
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
};

}  // namespace smtcal::cad
