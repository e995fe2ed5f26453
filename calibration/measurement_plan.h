// The measurement plan (`smtcal measure plan`, docs/measure.md): the paper's
// robot calibration procedure (3.2.1-3.2.2) as a list of visits. Each region
// is discretized on a rectilinear grid that covers its bounds with a margin
// for the robot's error; every node (and a few check points between nodes,
// which measure how far the robot's error departs from the interpolation) is
// visited in sets of repetitions (the paper: 2 sets of 10), always reached
// by the cell's final approach, so the robot's backlash sits in the table as
// it does in production moves. The plan knows how long it takes at the
// cell's speeds.
//
// Assumes a cell loaded with CellLoadOptions::tables_may_be_missing (a region
// without a table has its bounds) that has a [measure] table and the robot's
// final_approach_mm. Guarantees: every visit's point lies inside the robot's
// limits, on the grid of its region (or a check point strictly between grid
// lines), and for the transducer on a groove of the plate of its station.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/cell.h"

namespace smtcal::measure {

// What a visit measures: the x error, the y error, or both at once.
enum class MeasuredAxes { kX, kY, kXY };
std::string_view MeasuredAxesName(MeasuredAxes axes);  // x | y | xy

// What a visit is for: a node of its region's table; a check point
// between the nodes; a tie (a node of another station's region measured
// here too, so the two placements of the artefact can be registered to
// each other); a closure (the station's first point again at the end of a
// set: a plate that moved during the set reads differently).
enum class VisitKind { kNode, kCheck, kTie, kClosure };
std::string_view VisitKindName(VisitKind kind);  // node | check | tie | closure

// The default pitch (without --pitch) comes from the interpolation-error
// estimate verify budgets (calibration/interpolation_error.h), the pitch at
// which it is kInterpolationShareOfTolerance of the region's tolerance: with
// a previous table, that table's grid advice (AdviseGrid of the region's
// estimate; its own pitch again when it is within the share); before any
// table, PlannedPitchMm of the declared roughness (robot.uncalibrated_*),
// which nodes not measured yet cannot rule out. Then the largest round pitch
// (1, 2, 2.5 or 5 x 10^k mm) not above it, and onto the artefact's lattice.
// Never below this (a tolerance of nothing would ask for a pitch of 0).
inline constexpr double kPlanSmallestPitchMm = 0.1;
// Without robot.uncalibrated_accuracy_mm the plan assumes this error (the
// paper's robot after its gripper was mounted) and says so.
inline constexpr double kPlanAssumedAccuracyMm = 0.25;
// The probing cycle's margin beyond what the cell declares: a probe move
// starts at least the robot's error, the artefact's placement and turn and
// this far short of the wall it expects, and a stylus never comes closer
// to a wall than this outside a probe move.
inline constexpr double kProbeSafetyMarginMm = 0.05;
// A plate moved when its closure visit reads this far or more from the
// set's first reading of the same point (and beyond the readings' noise):
// the probe reads in steps of a servo period's travel.
inline constexpr double kPlateMovedFloorMm = 0.005;

struct PlanRegion {
  std::string name;
  // Not in the cell: a region under a fixture's markers that the cell lacks
  // (the plan measures it; the cell needs a [[region]] for its table).
  bool proposed = false;
  cell::Interval x_mm, y_mm;  // the bounds it serves (required positions)
  double tolerance_mm = 0;
  std::vector<double> xs, ys;  // the grid lines, covering the bounds and the margin
  double margin_mm = 0;        // how far the grid reaches past the bounds, at least
  double pitch_mm = 0;
  std::string pitch_reason;    // why this pitch: "given", "from the tolerance ...", "from the previous table ..."
  int sets = 0;
  int repetitions = 0;
  int nodes = 0;         // grid nodes
  int check_points = 0;  // per measured axis: check points (x and y may differ for the transducer)
  int stations = 1;      // the placements of the artefact (stations) that hold its nodes
  double time_s = 0;     // the visits of this region at the cell's speeds
};

// One placement of the artefact: the stations are numbered 1, 2, ... in
// plan order; each is one measuring program (the transducer: per axis).
// Its visits measure the nodes (and check points) of one or more regions,
// and as ties nodes of the stations it is tied to.
struct PlanStation {
  int number = 0;
  MeasuredAxes axes = MeasuredAxes::kXY;
  std::vector<std::size_t> regions;  // whose nodes it measures as nodes, into Plan::regions
  // Where the artefact goes: its reference (the probe's corner hole, the
  // transducer's first groove) at `origin`, covering the box from there to
  // `far` (every point the station measures).
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  Eigen::Vector2d far = Eigen::Vector2d::Zero();
  std::vector<int> tied_to;  // stations whose nodes it measures (or shares), ascending
  int ties = 0;              // tie points it measures
};

struct Visit {
  int number = 0;          // 1-based, in plan order
  std::size_t region = 0;  // index into Plan::regions
  MeasuredAxes axes = MeasuredAxes::kXY;
  int station = 1;         // transducer: which mounting of the plate (1-based)
  VisitKind kind = VisitKind::kNode;
  int node = 0;            // 1-based, unique in the plan (nodes, then check points, region by region)
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  // the commanded position (robot base, mm)
  int set = 1;             // 1-based
  int repetitions = 1;
  int direction = 1;       // +1: reached by the final approach; -1: against it (a bidirectional plan)
};

struct Plan {
  std::string cell_name;
  cell::MeasureDevice device = cell::MeasureDevice::kProbe;
  Eigen::Vector2d approach_mm = Eigen::Vector2d::Zero();  // robot.final_approach_mm
  std::vector<PlanRegion> regions;
  std::vector<PlanStation> stations;
  std::vector<Visit> visits;
  double time_s = 0;
  // How far a wall may lie from where a probe move expects it: the robot's
  // error, the artefact's placement and its turn over the largest station
  // (0 for other devices).
  double probe_reach_mm = 0;
  std::vector<std::string> notes;  // what the plan assumed or could not do, for the summary
};

struct PlanOptions {
  std::vector<std::string> regions;  // empty: every region of the cell and the markers' proposed ones
  std::optional<double> pitch_mm;
  int sets = 2;          // the paper's
  int repetitions = 10;  // the paper's
  bool check_points = true;
  // ISO 230-2's bidirectional measurement: every node also approached
  // against the final approach, for its reversal value (the backlash).
  bool bidirectional = false;
};

// The plan for `cell`. Reports (at the cell's keys): no [measure] table, no
// final approach, a region name the cell lacks (at the cell file), a grid the
// transducer's plate cannot reach, a grid outside the robot's limits.
// nullopt when anything was an error.
std::optional<Plan> MakePlan(const cell::Cell& cell, const PlanOptions& options, Diagnostics& diags);

// The time one visit takes after `previous` (nullptr: the first), at the
// cell's speeds: up to the clear z, across to the approach point, the final
// approach, down, the dwell and the device's reading, per repetition.
double VisitTimeS(const cell::Cell& cell, const Visit& visit, const Visit* previous);

// The effective radius of the probe's holes: hole minus stylus, halved.
double ProbeContactRadiusMm(const cell::MeasureProbe& probe);

// The groups of visits one program measures: one station of the artefact,
// one axis (x, y or both), in plan order (`region`: its first visit's).
struct VisitGroup {
  std::size_t region = 0;
  MeasuredAxes axes = MeasuredAxes::kXY;
  int station = 1;
  std::size_t first = 0;  // index into Plan::visits
  std::size_t count = 0;
};
std::vector<VisitGroup> GroupVisits(const std::vector<Visit>& visits);

}  // namespace smtcal::measure
