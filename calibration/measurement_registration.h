// Registering the set-ups of the artefact (docs/measure.md, "Registering the
// set-ups"). Each time the artefact (the probe's hole plate, the
// transducers' grooved plate) is put down it lies a little off where the
// plan puts it: a set-up u has an unknown small pose p_u = (t_x, t_y, θ),
// and a point h of the artefact really lies at h + g_u(h),
//
//   g_u(h) = t_u + θ_u J (h − o_u),   J = [[0, −1], [1, 0]],
//
// about the set-up's reference o_u (where the plan asks for the plate's
// corner hole). A reading there measures the robot's error less the plate's
// displacement: m_u(h) = e(h) − g_u(h) + noise. One set-up alone cannot
// tell the two apart; a node measured in two set-ups can (the plan's ties:
// regions sharing a set-up, neighbouring set-ups measuring a line of each
// other's nodes, every set of a station the same nodes again). With
// ē(h) the weighted mean of m_u(h) + g_u(h) over the set-ups that measured
// h, the poses minimise
//
//   Σ_h Σ_u w_u(h) |m_u(h) + g_u(h) − ē(h)|²,   w = n / σ²,
//
// a linear least-squares problem in the poses alone (ē eliminated), with
// the poses of every group of tied set-ups summing to zero (the gauge: the
// group's mean placement is the plan's). Its covariance (scaled up by the
// ties' chi-square per degree of freedom when that exceeds 1) gives each
// node's registration uncertainty; set-ups that no tie joins are separate
// groups, whose relative placement nothing measured.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/cell.h"
#include "calibration/error_table.h"
#include "calibration/measurement_plan.h"
#include "calibration/measurement_reading.h"

namespace smtcal::measure {

// One set-up: a station of the plan (one placement of the artefact) in
// one set (every set may find the plate moved).
struct SetupKey {
  int station = 0;
  int set = 0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // o_u, the plate's reference
};

struct SetupPose {
  SetupKey key;
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  // t_x, t_y in mm, θ in rad
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int group = 0;          // set-ups joined by ties share a group (0-based)
  int tied_nodes = 0;     // nodes it shares with other set-ups of its group
  // g_u(h): how far the artefact's point h lies from where the plan puts it.
  Eigen::Vector2d Displacement(const Eigen::Vector2d& h) const;
  // The standard uncertainty of g_u(h) per axis.
  Eigen::Vector2d Uncertainty(const Eigen::Vector2d& h) const;
};

// One error as read in a set-up (not yet registered).
struct SetupReading {
  std::size_t setup = 0;  // index into the set-ups
  int node = 0;           // the plan's node number
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  TableAxis axis = TableAxis::X;
  double error_mm = 0;
};

struct TieResidual {
  int node = 0;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  TableAxis axis = TableAxis::X;
  std::size_t setup = 0;
  double residual_mm = 0;  // m_u + g_u − ē at the node
  double sigma_mm = 0;     // its standard deviation from the readings' noise
};

struct Registration {
  std::vector<SetupPose> setups;  // in the order given
  int groups = 0;
  int dof = 0;                    // tie equations less the poses they fix
  double chi2_per_dof = 0;        // of the ties (1: as noisy as the readings say)
  std::vector<TieResidual> largest;  // the ties' largest normalised residual per set-up pair, worst first
};

// The set-ups' poses from their readings; `sigma_mm` is one reading's
// standard deviation. `rigid_artefact` false (an external system measures
// in the robot's frame, with no artefact): every pose is zero, every
// set-up its own group. Deterministic.
Registration RegisterSetups(const std::vector<SetupKey>& setups, const std::vector<SetupReading>& readings,
                            double sigma_mm, bool rigid_artefact = true);

// --- From the readings of a plan's stations to registered errors with
// their uncertainty (`measure read`, docs/measure.md) -------------------

// One reading's error along one axis, registered (the artefact's
// displacement added, its certificate's pitch error corrected), with its
// standard uncertainty from everything but the readings' scatter.
struct RegisteredError {
  std::size_t reading = 0;  // into the readings
  TableAxis axis = TableAxis::X;
  double error_mm = 0;
  double u_mm = 0;
  // The budget's terms (standard uncertainties, mm): the certificate, the
  // stylus and hole diameters, the probe's latency, the registration of
  // the placements, the placement of stations no tie joins.
  double artefact_mm = 0, diameters_mm = 0, latency_mm = 0, registration_mm = 0, placement_mm = 0;
};

struct ReadOutcome {
  std::vector<RegisteredError> errors;
  Registration registration;
  std::vector<std::size_t> setup_of;  // per reading: its set-up
  int plan_groups = 1;                // groups of the plan's stations that no tie joins
  double sigma_mm = 0;                // one reading's standard deviation the registration assumed
  std::vector<std::string> notes;
};

// The readings (every reading of the stations a region needs: its own and
// those tied to them) as errors at their nodes, checked and registered:
// each set's closure visit against the set's first reading of the same
// point (MeasurePlateMoved, an error naming the visit to measure again);
// the placements' poses by least squares over the ties (RegisterSetups),
// iterated with the probe's field; warnings for an artefact that moved
// between sets (registered apart) and for ties that disagree. `plan_name`
// names the plan in the resume command.
ReadOutcome RegisterReadings(const cell::Cell& cell, const Plan& plan, const std::vector<Reading>& readings,
                             std::string_view plan_name, Diagnostics& diags);

// The raw file's comment lines on the measurement's uncertainty budget
// (GUM, each term named, the largest at a node of `region`) and on the
// placements' registration.
std::vector<std::string> DescribeBudget(const cell::Cell& cell, const Plan& plan, const ReadOutcome& outcome,
                                        std::size_t region, const std::vector<Reading>& readings);

}  // namespace smtcal::measure
