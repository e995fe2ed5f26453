// From the measuring program's readings to the robot's error at the nodes
// (`smtcal measure read`, docs/measure.md, "What a reading means"):
//
//   transducer  e = ((measuring - reference) - zero_mm) / slope along the
//               visit's axis: the flank turns the error into a height, the
//               reference takes out the robot's z error (paper, Fig. 4);
//   external    e = measured position - commanded node, both axes;
//   probe       per axis the wall's place (the node + contact radius in the
//               approach's direction, on the chord the perpendicular error
//               puts the stylus on) minus the trip's commanded position, less
//               half a servo period of travel (motion latches the command
//               0 to 1 period after the contact). The trip is commanded up to
//               the contact radius away from the node, so the error there is
//               moved to the node through the field the readings themselves
//               give (bilinear in the grid, iterated to a fixed point).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/cell.h"
#include "calibration/error_table.h"
#include "calibration/measurement_plan.h"

namespace smtcal::measure {

// One reading of the log with what the plan says about its visit.
struct Reading {
  int visit = 0;
  int node = 0;
  int set = 1;
  int repetition = 1;
  std::size_t region = 0;  // the node's region, into Plan::regions
  int station = 1;         // the placement of the artefact it was read in
  int direction = 1;       // +1: reached by the final approach; -1: against it
  MeasuredAxes axes = MeasuredAxes::kXY;
  VisitKind kind = VisitKind::kNode;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  // the node, commanded
  double a = 0, b = 0;  // transducer: measuring, reference; probe: the trips' x, y
  Eigen::Vector2d external = Eigen::Vector2d::Zero();  // external: the position measured
  SourceRange where;  // its log line
};

// One error of one reading at its node.
struct ReadingError {
  TableAxis axis = TableAxis::X;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  VisitKind kind = VisitKind::kNode;
  int set = 1;
  int repetition = 1;
  double error_mm = 0;
  SourceRange where;
  std::size_t reading = 0;  // index into the readings
};

// The errors of `readings` (of the regions `regions`, whose grids move the
// probe's trips to their nodes), measured by `measure` with the robot's
// final approach and servo period, as read in their own placement of the
// artefact (not registered). `registered[k]` is what registration adds to
// reading k's error (the artefact's displacement at its node, zero
// before registering): the probe's field, which moves each trip to its
// node, is built from registered errors, so placements that differ do not
// bend it. For the probe `notes` gets how far the largest trip lay from
// its node and how much moving it there changed the error.
std::vector<ReadingError> ErrorsOfReadings(const cell::Measure& measure, const cell::Robot& robot,
                                           const std::vector<PlanRegion>& regions,
                                           const std::vector<Reading>& readings,
                                           const std::vector<Eigen::Vector2d>& registered,
                                           std::vector<std::string>& notes);

// Every reading checked against what its device can give and against its
// node's other readings, before any is turned into an error at its node
// (the probe's correction spreads each reading to its neighbours):
//   - the probe: each trip within the probe move the program commands
//     (from the node plus the contact radius less overtravel_mm to as far
//     past it, late by up to one servo period of travel); the transducer:
//     both readings within range_mm; the external system: the log holds
//     0,0 (its readings come from the system's file: CheckExternalReadings);
//   - a reading far from the others of its node (calibration/
//     reading_screen.h on what the device read: the trip's distance from
//     the node, the transducers' difference) is an error at its log line.
// `plan_name` names the plan in the messages' resume command.
void CheckReadings(const cell::Measure& measure, const cell::Robot& robot, const std::vector<Reading>& readings,
                   std::string_view plan_name, Diagnostics& diags);

// The external system's positions: a position farther from its node than
// twice the robot's declared error (robot.uncalibrated_accuracy_mm, else
// kPlanAssumedAccuracyMm) cannot be the robot's; `where` per reading is the
// external file's line. Then the same screening against the node's other
// readings as CheckReadings.
void CheckExternalReadings(const cell::Measure& measure, const cell::Robot& robot,
                           const std::vector<Reading>& readings, const std::vector<SourceRange>& where,
                           std::string_view plan_name, Diagnostics& diags);

// The plan file's digest (a 64-bit FNV-1a hash of its bytes with the
// project's constants, 16 hex digits): the
// measuring program writes it into its log, and `measure read` refuses a log
// of another plan.
std::string PlanDigest(std::string_view text);

}  // namespace smtcal::measure
