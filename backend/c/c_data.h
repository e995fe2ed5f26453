// The data the C99 runtime (runtime/c/smtcal_runtime.h) works on: the cell's
// regions with their error tables, its fixtures (nominal pose, marker edge
// lines, expected trips, check limits) and a program's points in their
// fixture frames. `smtcal compile --target c` writes it as a C source of
// const structures (EmitCRuntimeData) that compiles with the runtime under
// -std=c99 -pedantic; tests and benchmarks build the same structures in
// memory (CRuntimeData) to call the runtime directly.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/source.h"
#include "calibration/cell.h"
#include "passes/correction/compile_state.h"
#include "runtime/c/smtcal_runtime.h"

namespace smtcal {

// One point of the program for the runtime: its position in its fixture's
// frame, corrected every cycle with that fixture's FIX.
struct CRuntimePoint {
  std::string name;     // as the program writes the target ("C1", "Pallet(1, 2, 1)")
  std::string fixture;  // the cell fixture's name; empty: the point is in the base frame
  Eigen::Vector2d fix_mm = Eigen::Vector2d::Zero();
  double z_mm = 0;
  double u_deg = 0;
  SourceLoc loc;        // written beside it as a comment
};

// The runtime's fixed trip array: a fixture whose scan paths make more trips
// cannot be emitted (check FitsCRuntime and report it first).
inline constexpr std::size_t kCRuntimeMaxTrips = SMTCAL_MAX_TRIPS;
bool FitsCRuntime(const cell::Fixture& fixture);

// The runtime structures of a cell's regions and fixtures, pointing into the
// cell's tables (the cell must outlive it).
class CRuntimeData {
 public:
  // Every fixture must FitsCRuntime (checked).
  explicit CRuntimeData(const cell::Cell& cell);

  const smtcal_region* regions() const { return regions_.empty() ? nullptr : regions_.data(); }
  int region_count() const { return static_cast<int>(regions_.size()); }
  const std::vector<smtcal_fixture>& fixtures() const { return fixtures_; }

 private:
  std::vector<smtcal_region> regions_;
  std::vector<smtcal_fixture> fixtures_;
};

// The runtime structure of one region (pointers into its table) and of one
// fixture (self-contained but for its name).
smtcal_region CRuntimeRegion(const cell::Region& region);
smtcal_fixture CRuntimeFixture(const cell::Fixture& fixture);

// A C source defining `const smtcal_program smtcal_program_<NAME>` (NAME:
// the program name with every character that is not a letter, digit or '_'
// made '_') with the cell's regions and fixtures (all of them, in cell
// order: a fixture's index is its position in the cell) and the points.
// Numbers are written so they read back exactly; the output is
// deterministic. Every fixture must FitsCRuntime and every point's fixture
// must be in the cell (checked).
std::string EmitCRuntimeData(const cell::Cell& cell, const std::vector<CRuntimePoint>& points,
                             std::string_view program_name);

// The program's fixture targets whose position is known at compile time, as
// points for EmitCRuntimeData.
std::vector<CRuntimePoint> CRuntimeFixturePoints(const CompileState& state);

// The identifier EmitCRuntimeData gives the program structure.
std::string CRuntimeProgramSymbol(std::string_view program_name);

}  // namespace smtcal
