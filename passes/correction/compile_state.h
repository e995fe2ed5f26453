// What the correction passes know about a program compiled for a cell: the
// cell, the program's fixtures bound to the cell's, and every motion target
// the program can reach with its frame, region and correction. The bind pass
// creates it (ir::Program::compile); each later pass fills in its part; the
// emitters and the report read it.
//
// A "target" is one position a motion statement can command: a statement
// inside a loop over layers has one target per layer. Targets are found by
// running the program at compile time (passes/correction/target_trace.h) and are unique
// per (statement, position).
#pragma once

#include <array>
#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include <Eigen/Geometry>

#include "base/source.h"
#include "calibration/cell.h"
#include "calibration/fixture_estimation.h"
#include "calibration/inverse_calibration.h"
#include "calibration/placement_budget.h"
#include "ir/ir.h"

namespace smtcal {

// x, y, z in mm, u in degrees (as in the language).
using Pose4 = std::array<double, 4>;

// A program fixture bound to the cell's fixture of the same name.
struct FixtureBinding {
  std::string name;                  // as the program declares it
  const ir::Stmt* decl = nullptr;    // the program's `Fixture NAME`
  const cell::Fixture* cell_fixture = nullptr;
  Eigen::Affine3d nominal = Eigen::Affine3d::Identity();  // FIX at the cell's nominal pose
  std::optional<Eigen::Affine3d> fix0;  // the teach-time scan's FIX_0 (when the cell has one)
  std::string teach_fault;                 // why the teach-time scan gave no FIX_0
};

// A program's `Fixture NAME` bound to the cell's fixture of that name at its
// nominal pose, without the teach-time scan.
FixtureBinding NominalBinding(const ir::Stmt& stmt, const ir::FixtureDecl& decl, const cell::Fixture& fixture);

// FIX_0 from a fixture's teach-time scan (calibration/fixture_estimation.h does the
// math), or the fault that stopped it.
struct TeachPose {
  std::optional<Eigen::Affine3d> fix;
  std::string fault;
};
TeachPose EstimateTeachPose(const cell::Fixture& fixture, const cell::Cell& cell);


enum class CorrectionKind {
  kStatic,       // base frame, one position: nominal coordinates computed at compile time
  kRunTimeBase,  // base frame, position known only at run time: inverse calibration on the controller
  kFixture,      // fixture frame: FIX_n, then the inverse calibration, on the controller every cycle
  kUncorrected,  // a Jump/Go/Move outside every calibrated region: commanded as written
};
std::string_view CorrectionKindName(CorrectionKind kind);  // static | run-time | fixture | uncorrected

// Text many targets share (the calls they were reached through, what they
// depend on): kept once per compile (CompileState::Share), 8 bytes in each
// Target instead of a string's 32 (a million placements have two million
// targets).
class SharedText {
 public:
  SharedText() : text_(&Empty()) {}
  const std::string& str() const { return *text_; }
  operator const std::string&() const { return *text_; }
  bool empty() const { return text_->empty(); }
  friend bool operator==(const SharedText& a, std::string_view b) { return *a.text_ == b; }

 private:
  friend struct CompileState;
  explicit SharedText(const std::string* text) : text_(text) {}
  static const std::string& Empty();
  const std::string* text_;
};

struct Target {
  const ir::Stmt* stmt = nullptr;  // the Motion or PickPlace statement
  std::string text;                // the target as written: "Pallet(1, 2, 1)", "R1 + X(dx)"
  SharedText call_path;            // "Main > PlaceLayers" (where it was reached first)
  int fixture = -1;                // index into CompileState::fixtures; -1 = robot base
  const ir::Stmt* taught_decl = nullptr;  // a taught point's declaration
  Pose4 taught_offset{};           // taught targets: the offsets written after the point
  bool known = true;               // false: depends on values known only at run time
  SharedText unknown_because;      // what it depends on, for messages
  // The position in its frame: the fixture's (fixture targets) or the base's.
  Pose4 in_frame{};
  // Required position in the robot base frame (fixture targets: at the
  // fixture's nominal pose; taught ones: after FIXPOS_0 is known).
  Pose4 required{};
  const cell::Region* region = nullptr;
  CorrectionKind kind = CorrectionKind::kStatic;
  // Nominal (commanded) position and the inverse's result: static targets;
  // fixture targets at the nominal fixture pose, for the report.
  Pose4 nominal{};
  double residual_mm = 0;
  int iterations = 0;
  int iteration_bound = 0;   // fixture and run-time targets: what the runtime may need
  // The tolerance budget (verify; calibration/placement_budget.h): at 4
  // sigma, and the hard worst case. CompileState::BudgetOf has the parts.
  double budget_mm = 0;
  double worst_case_mm = 0;
  bool budget_bounded = true;  // false: the cell does not declare what would bound it
  bool is_placement() const;  // a Place statement
};

// A taught point on a fixture, converted to its fixture coordinates.
struct TaughtPoint {
  const ir::Stmt* decl = nullptr;
  Pose4 taught{};   // robot coordinates as taught (ROBOT_0)
  Pose4 reached{};  // F(ROBOT_0): where the robot really was
  Pose4 fixpos0{};  // FIX_0^-1 . F(ROBOT_0)
  const cell::Region* region = nullptr;
};

// One assembling cycle's estimated time (the first execution of each Cycle).
struct CycleEstimate {
  const ir::Stmt* cycle = nullptr;
  std::string fixture;
  double motion_s = 0;  // moves, picks, places and waits
  double scan_s = 0;    // the marker scan prologue, as every cycle after the first runs it (predicted, when the
                        // fixture has predicted_window_mm: calibration/scan_plan.h)
  double first_scan_s = 0;  // the first cycle's scan, and a fallback's: every leg searched in full
  double scan_floor_s = 0;  // what no scan of these paths goes below (ScanFloor)
  int placements = 0;
  double total_s() const { return motion_s + scan_s; }
};

// One motion or timed event of the first execution of a Cycle, in order.
struct TraceEvent {
  enum class Kind { kMotion, kWait } kind = Kind::kMotion;
  std::size_t target = 0;          // kMotion: index into CompileState::targets
  double wait_s = 0;               // kWait
};

struct CompileState {
  const cell::Cell* cell = nullptr;
  std::vector<FixtureBinding> fixtures;
  std::vector<Target> targets;
  std::vector<TaughtPoint> taught;
  // The event sequence of the first execution of each Cycle statement.
  std::map<const ir::Stmt*, std::vector<TraceEvent>> cycle_traces;
  std::vector<CycleEstimate> cycles;
  bool trace_complete = true;  // false: the run hit its step limit (reported)
  // false: verify sets every target's budget but reports no BudgetOverTolerance
  // or FixtureBudgetUnbounded (simulate measures what the budget predicts and
  // counts the findings from the targets; reported, they could fill the
  // error limit and stop it)
  bool report_budget_findings = true;

  int FindFixture(std::string_view name) const;  // index or -1, case-insensitive
  // The one copy of `text` this compile keeps.
  SharedText Share(std::string_view text);
  // One solver per region, made on first use (tables are validated at load).
  const InverseSolver& SolverFor(const cell::Region& region);
  // The fixture's scan as a source of placement error, made on first use.
  const FixtureErrorModel& ErrorModelFor(const cell::Fixture& fixture) const;
  // Every part of a known target's tolerance budget: static targets from
  // their region, fixture targets also through their fixture's scan.
  ErrorBudget BudgetOf(const Target& target) const;

 private:
  std::map<const cell::Region*, std::unique_ptr<InverseSolver>> solvers_;
  std::deque<std::string> shared_;  // deque: SharedText's pointers stay valid
  std::unordered_map<std::string_view, const std::string*> shared_by_text_;
  // A cache: the models depend only on the cell.
  mutable std::map<const cell::Fixture*, std::unique_ptr<FixtureErrorModel>> error_models_;
  // The cell's RegionTableNoise, found on first use and shared by the
  // static budgets and the fixtures' error models.
  const std::vector<Eigen::Vector2d>& RegionTableNoiseOnce() const;
  mutable std::vector<Eigen::Vector2d> region_table_se_;
};

// Which base-frame statements the compiler commands as written: those whose
// every target the compile-time run found is one known position (static,
// or uncorrected outside every region); the others are corrected on the
// controller. Keyed by every statement with a base-frame target (fixture
// targets are left out: a CAD-sized program's million of them need no map).
// The regions pass decides a target's kind by it, and so does `smtcal diff`
// when it reads a compiled program back.
std::unordered_map<const ir::Stmt*, bool> BaseStatementsCommandedAsWritten(const std::vector<Target>& targets);

// The base-frame position of a fixture-frame pose through FIX.
Pose4 PoseToBase(const Eigen::Affine3d& fix, const Pose4& in_fixture);
// The fixture-frame pose of a base-frame pose (FIX^-1).
Pose4 PoseToFixture(const Eigen::Affine3d& fix, const Pose4& in_base);
// "Pick", "Place", "Jump", "Go" or "Move": a target statement's keyword, for messages.
std::string_view TargetKeyword(const ir::Stmt& stmt);
// Coordinates a pass writes into the corrected program are rounded to 1e-10
// mm (degrees): shorter text, and far below kInverseResidualTolMm.
double RoundForProgramText(double value);
inline double Radians(double degrees) { return degrees * kRadPerDeg; }
// x and y of a pose, for the 2-D calibration math.
inline Eigen::Vector2d Xy(const Pose4& pose) { return {pose[0], pose[1]}; }

}  // namespace smtcal

// Shared texts format as their text (diagnostics take them as arguments).
template <>
struct fmt::formatter<smtcal::SharedText> : fmt::formatter<std::string_view> {
  template <typename FormatContext>
  auto format(const smtcal::SharedText& text, FormatContext& ctx) const {
    return fmt::formatter<std::string_view>::format(text.str(), ctx);
  }
};
