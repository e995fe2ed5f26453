// The marker scan as the controller drives it: capture range and time (see
// scan_plan.h). Assumes a fixture the cell loader accepted; guarantees a
// capture factor in [0, kMaxCaptureFactor] and finite times.
#include "calibration/scan_plan.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/LU>
#include <fmt/format.h>

#include "calibration/fixture_geometry.h"
#include "calibration/motion_time.h"

namespace smtcal {
namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// The crossing of the leg a..b with the edge e0..e1 as (t along the leg, u
// along the edge), and how it moves with a shift of the board: (t, u) =
// at + gradient * shift. Nullopt when they are parallel.
struct Crossing {
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  Eigen::Matrix2d gradient = Eigen::Matrix2d::Zero();
};
std::optional<Crossing> CrossingOf(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& e0,
                                   const Eigen::Vector2d& e1) {
  // a + t (b - a) = e0 + u (e1 - e0); a shift d of the board adds d to e0, e1.
  Eigen::Matrix2d m;
  m.col(0) = b - a;
  m.col(1) = -(e1 - e0);
  if (std::abs(m.determinant()) <= 1e-12 * (b - a).norm() * (e1 - e0).norm()) return std::nullopt;
  const Eigen::Matrix2d inverse = m.inverse();
  return Crossing{inverse * (e0 - a), inverse};
}

// The distance from the shift 0 to the shifts at which (t, u) of `c` lies in
// [0, 1] x [0, 1] (a parallelogram of shifts): 0 when 0 is in it.
double DistanceToCrossingShifts(const Crossing& c) {
  const Eigen::Matrix2d to_shift = c.gradient.inverse();
  const std::array<Eigen::Vector2d, 4> corners = {to_shift * (Eigen::Vector2d(0, 0) - c.at),
                                                  to_shift * (Eigen::Vector2d(1, 0) - c.at),
                                                  to_shift * (Eigen::Vector2d(1, 1) - c.at),
                                                  to_shift * (Eigen::Vector2d(0, 1) - c.at)};
  bool inside = true;
  double sign = 0, nearest = 1e300;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Eigen::Vector2d& p = corners[i];
    const Eigen::Vector2d& q = corners[(i + 1) % corners.size()];
    const double side = Cross(q - p, -p);
    if (sign == 0) sign = side;
    if (side * sign < 0) inside = false;
    const double s = std::clamp((-p).dot(q - p) / (q - p).squaredNorm(), 0.0, 1.0);
    nearest = std::min(nearest, (p + s * (q - p)).norm());
  }
  return inside ? 0.0 : nearest;
}

// The legs of the scan paths in the base frame at the nominal pose.
struct Leg {
  std::size_t path = 0, index = 0;
  Eigen::Vector2d from, to;
};
std::vector<Leg> LegsOf(const cell::Fixture& fixture) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  std::vector<Leg> legs;
  for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
    const std::vector<cell::Point2>& points = fixture.scan_paths[p].points;
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
      legs.push_back({p, i, ToBase(nominal, points[i]), ToBase(nominal, points[i + 1])});
    }
  }
  return legs;
}

// What a failure concerns: a trip, or a leg (of scan_paths[path]) and the
// edge it crosses besides its trips; -1 where none.
struct Culprit {
  int trip = -1, path = -1, leg = -1, edge = -1;
};

// The first condition a board at `pose` fails for some further shift within
// `radius_mm` (S1 moved in the base frame), or "".
std::string FirstFailure(const cell::Fixture& fixture, const std::vector<ExpectedTrip>& expected,
                         const std::vector<Leg>& legs, const Eigen::Affine3d& pose, double radius_mm,
                         Culprit* culprit) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  auto leg_of = [&](const ExpectedTrip& e) -> const Leg& {
    return *std::find_if(legs.begin(), legs.end(), [&](const Leg& l) { return l.path == e.path && l.index == e.leg; });
  };
  std::vector<std::optional<Crossing>> crossings;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const ExpectedTrip& e = expected[k];
    const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(e.edge)];
    const Leg& leg = leg_of(e);
    std::optional<Crossing> c = CrossingOf(leg.from, leg.to, ToBase(pose, edge.from), ToBase(pose, edge.to));
    const std::optional<Crossing> at_nominal =
        CrossingOf(leg.from, leg.to, ToBase(nominal, edge.from), ToBase(nominal, edge.to));
    *culprit = Culprit{static_cast<int>(k)};
    if (!c || !at_nominal) return fmt::format("{} runs along edge {}", TripName(k), edge.name);
    const double leg_length = (leg.to - leg.from).norm(), edge_length = (edge.to - edge.from).norm();
    const double dt = radius_mm * c->gradient.row(0).norm(), du = radius_mm * c->gradient.row(1).norm();
    const double margin = std::min(0.5, fixture.sensor_accuracy_mm / edge_length);
    if (c->at.x() - dt < 0 || c->at.x() + dt > 1) {
      return fmt::format("{} leaves its leg: the edge {} moves off the leg's end", TripName(k), edge.name);
    }
    if (c->at.y() - du < margin || c->at.y() + du > 1 - margin) {
      return fmt::format("{} leaves edge {}'s visible segment (the sensor would see the marker's other side)",
                         TripName(k), edge.name);
    }
    const double window = std::max(std::abs(c->at.x() - dt - at_nominal->at.x()),
                                   std::abs(c->at.x() + dt - at_nominal->at.x())) * leg_length;
    if (window > fixture.trip_window_mm) {
      return fmt::format("{} moves more than trip_window_mm = {} along its leg", TripName(k),
                         fmt::format("{}", fixture.trip_window_mm));
    }
    if (k > 0 && crossings[k - 1] && expected[k - 1].path == e.path && expected[k - 1].leg == e.leg) {
      const Crossing& before = *crossings[k - 1];
      const double gap = c->at.x() - before.at.x();
      if (gap - radius_mm * (c->gradient.row(0) - before.gradient.row(0)).norm() <= 0) {
        return fmt::format("{} and {} swap along their leg", TripName(k - 1), TripName(k));
      }
    }
    crossings.push_back(c);
  }
  *culprit = Culprit{};
  for (const Leg& leg : legs) {
    for (std::size_t e = 0; e < fixture.edges.size(); ++e) {
      const bool expected_here = std::any_of(expected.begin(), expected.end(), [&](const ExpectedTrip& t) {
        return t.path == leg.path && t.leg == leg.index && t.edge == static_cast<int>(e);
      });
      if (expected_here) continue;
      const cell::MarkerEdge& edge = fixture.edges[e];
      std::optional<Crossing> c = CrossingOf(leg.from, leg.to, ToBase(pose, edge.from), ToBase(pose, edge.to));
      if (c && DistanceToCrossingShifts(*c) <= radius_mm) {
        *culprit = Culprit{-1, static_cast<int>(leg.path), static_cast<int>(leg.index), static_cast<int>(e)};
        return fmt::format("leg {} of scan path '{}' crosses edge {} besides its trips", leg.index + 1,
                           fixture.scan_paths[leg.path].name, edge.name);
      }
    }
  }
  return "";
}

// The first failure for any pose within k x the fixture's limits, or "".
std::string FailureWithin(const cell::Fixture& fixture, const std::vector<ExpectedTrip>& expected,
                          const std::vector<Leg>& legs, double k, Culprit* culprit) {
  constexpr int kTurns = 20;  // even: the turn 0 is among the samples
  const double turn = k * fixture.max_rotation_deg * kRadPerDeg;
  for (int i = 0; i <= kTurns; ++i) {
    const double sample = turn * (2.0 * i / kTurns - 1);
    const Eigen::Affine3d pose = PlanarFix(fixture.origin_mm, fixture.angle_deg * kRadPerDeg + sample);
    std::string why = FirstFailure(fixture, expected, legs, pose, k * fixture.max_shift_mm, culprit);
    if (!why.empty()) return why;
  }
  return "";
}

// A probe move from rest toward an edge `distance` ahead at `speed`: its
// time until it stands again and how far past the edge it stops (the trip
// is latched up to one servo period late, half of one on average; then the
// robot brakes).
struct ProbeMove {
  double seconds = 0;
  double past_mm = 0;
};
ProbeMove ProbeTo(double distance, double speed, double accel, double servo_period_s) {
  distance = std::max(0.0, distance);
  const double reach = speed * speed / (2 * accel);
  const double crossing_speed = distance >= reach ? speed : std::sqrt(2 * accel * distance);
  const double to_edge = distance >= reach ? speed / accel + (distance - reach) / speed
                                           : crossing_speed / accel;
  const double late = 0.5 * servo_period_s;
  return {to_edge + late + crossing_speed / accel,
          crossing_speed * late + crossing_speed * crossing_speed / (2 * accel)};
}

}  // namespace

bool ScanMeasuresPose(const cell::Fixture& fixture, const Eigen::Vector2d& shift_mm, double turn_deg,
                      std::string* why) {
  const Eigen::Affine3d pose =
      PlanarFix(fixture.origin_mm + shift_mm, (fixture.angle_deg + turn_deg) * kRadPerDeg);
  Culprit culprit;
  std::string failure = FirstFailure(fixture, ExpectedTrips(fixture), LegsOf(fixture), pose, 0, &culprit);
  if (why != nullptr) *why = failure;
  return failure.empty();
}

CaptureRange ScanCaptureRange(const cell::Fixture& fixture) {
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const std::vector<Leg> legs = LegsOf(fixture);
  CaptureRange range;
  Culprit culprit;
  std::string why = FailureWithin(fixture, expected, legs, kMaxCaptureFactor, &culprit);
  if (why.empty()) {
    range.factor = kMaxCaptureFactor;
  } else {
    double lo = 0, hi = kMaxCaptureFactor;
    std::string at_zero = FailureWithin(fixture, expected, legs, 0, &culprit);
    if (!at_zero.empty()) {
      why = at_zero;
    } else {
      for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        Culprit mid_culprit;
        std::string mid_why = FailureWithin(fixture, expected, legs, mid, &mid_culprit);
        if (mid_why.empty()) {
          lo = mid;
        } else {
          hi = mid;
          why = mid_why;
          culprit = mid_culprit;
        }
      }
    }
    range.factor = lo;
    range.limited_by = why;
    range.trip = culprit.trip;
    range.leg_path = culprit.path;
    range.leg = culprit.leg;
    range.edge = culprit.edge;
  }
  range.shift_mm = range.factor * fixture.max_shift_mm;
  range.rotation_deg = range.factor * fixture.max_rotation_deg;
  return range;
}

namespace {

// The runtime makes no probe move shorter than this in both axes (LinuxCNC
// refuses one shorter than 0.01 mm: "start point too close to probe point").
constexpr double kShortestProbeMoveMm = 0.02;

// A trip of a path as the runtime reaches it: its leg in the base frame at
// the nominal pose (start, unit direction) and where along it the edge is.
struct PathTrip {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
  std::size_t leg = 0;
  double along_mm = 0;
  Eigen::Vector2d At(double along) const { return start + along * direction; }
};
std::vector<PathTrip> TripsOfPath(const cell::Fixture& fixture, const std::vector<ExpectedTrip>& expected,
                                  std::size_t p) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const std::vector<cell::Point2>& points = fixture.scan_paths[p].points;
  std::vector<PathTrip> trips;
  for (const ExpectedTrip& trip : expected) {
    if (trip.path != p) continue;
    const Eigen::Vector2d a = ToBase(nominal, points[trip.leg]), b = ToBase(nominal, points[trip.leg + 1]);
    trips.push_back({a, (b - a).normalized(), trip.leg, trip.along_mm});
  }
  return trips;
}

// Up from `at` to the safe z and across to `to` (when `at` is known), then
// down to the scan z.
double JumpSeconds(const cell::Robot& robot, const cell::Fixture& fixture, bool known, const ScanPoint& at,
                   const Eigen::Vector2d& to) {
  double seconds = 0;
  if (known) {
    seconds += MoveTime(robot.safe_limz_mm - at.z(), robot.z_speed_mm_s, robot.z_accel_mm_s2);
    seconds += MoveTime((to - at.head<2>()).norm(), robot.xy_speed_mm_s, robot.xy_accel_mm_s2);
  }
  return seconds + MoveTime(robot.safe_limz_mm - fixture.scan_z_mm, robot.z_speed_mm_s, robot.z_accel_mm_s2);
}

double RiseSeconds(const cell::Robot& robot, const cell::Fixture& fixture) {
  return MoveTime(robot.safe_limz_mm - fixture.scan_z_mm, robot.z_speed_mm_s, robot.z_accel_mm_s2);
}

// The moves' turnarounds and the total, the scan ending at `end`.
ScanTiming Finished(ScanTiming timing, const cell::Robot& robot, const ScanPoint& end) {
  timing.turnaround_s = timing.probe_moves * robot.probe_turnaround_s;
  timing.seconds = timing.travel_s + timing.search_s + timing.latch_s + timing.turnaround_s;
  timing.end = end;
  return timing;
}

}  // namespace

ScanTiming ScanTime(const cell::Robot& robot, const cell::Fixture& fixture, const std::optional<ScanPoint>& from,
                    ScanSearch search) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const double a = robot.xy_accel_mm_s2, latch = fixture.latch_speed_mm_s;
  const double period = robot.servo_period_s;
  const double window = fixture.predicted_window_mm;
  ScanTiming timing;
  bool known = from.has_value();  // where the robot stands (a plain flag and point: GCC warns on optional<Eigen>)
  ScanPoint at = known ? *from : ScanPoint::Zero();
  if (search == ScanSearch::kPredicted && window > 0) {
    // runtime/linuxcnc/smtcal_probe_predicted.ngc at the nominal pose: every
    // trip in its window.
    for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
      const std::vector<PathTrip> trips = TripsOfPath(fixture, expected, p);
      if (trips.empty()) continue;
      Eigen::Vector2d here = Eigen::Vector2d::Zero();
      std::size_t here_leg = 0;
      double here_along = 0;
      for (std::size_t i = 0; i < trips.size(); ++i) {
        const PathTrip& trip = trips[i];
        const double start = std::max(0.0, trip.along_mm - window);  // the window's start, on the leg
        double to_edge = trip.along_mm - start;
        if (i == 0) {
          timing.travel_s += JumpSeconds(robot, fixture, known, at, trip.At(start));
          ++timing.probe_moves;  // the descent: stops on an unexpected trip
        } else if (here_leg == trip.leg && here_along >= start) {
          to_edge = trip.along_mm - here_along;  // the window begins behind: latch on from here
        } else if (const Eigen::Vector2d way = trip.At(start) - here;
                   std::abs(way.x()) >= kShortestProbeMoveMm || std::abs(way.y()) >= kShortestProbeMoveMm) {
          timing.search_s += MoveTime(way.norm(), robot.xy_speed_mm_s, a);
          ++timing.probe_moves;
        }
        const ProbeMove latched = ProbeTo(to_edge, fixture.TripLatchSpeedMmS(), a, period);
        timing.latch_s += latched.seconds;
        ++timing.probe_moves;
        here_leg = trip.leg;
        here_along = trip.along_mm + latched.past_mm;
        here = trip.At(here_along);
      }
      timing.travel_s += RiseSeconds(robot, fixture);
      at = ScanPoint(here.x(), here.y(), robot.safe_limz_mm);
      known = true;
    }
    return Finished(timing, robot, at);
  }
  const double search_speed = fixture.scan_speed_mm_s;
  for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
    const std::vector<cell::Point2>& points = fixture.scan_paths[p].points;
    const Eigen::Vector2d start = ToBase(nominal, points.front());
    timing.travel_s += JumpSeconds(robot, fixture, known, at, start);
    for (std::size_t leg = 0; leg + 1 < points.size(); ++leg) {
      const double length = (points[leg + 1] - points[leg]).norm();
      double along = 0;  // where the robot stands on the leg
      for (const ExpectedTrip& trip : expected) {
        if (trip.path != p || trip.leg != leg) continue;
        const ProbeMove find = ProbeTo(trip.along_mm - along, search_speed, a, period);
        timing.search_s += find.seconds;
        ++timing.probe_moves;
        along = trip.along_mm + find.past_mm;
        if (latch > 0) {
          const ProbeMove back = ProbeTo(find.past_mm, latch, a, period);
          const ProbeMove forward = ProbeTo(back.past_mm, latch, a, period);
          timing.latch_s += back.seconds + forward.seconds;
          timing.probe_moves += 2;
          along = trip.along_mm + forward.past_mm;
        }
      }
      // The rest of the leg: at the scan feed with one stage, a traverse with two.
      timing.search_s += MoveTime(length - along, latch > 0 ? robot.xy_speed_mm_s : search_speed, a);
    }
    timing.travel_s += RiseSeconds(robot, fixture);
    const Eigen::Vector2d end = ToBase(nominal, points.back());
    at = ScanPoint(end.x(), end.y(), robot.safe_limz_mm);
    known = true;
  }
  return Finished(timing, robot, at);
}

ScanTiming ScanFloor(const cell::Robot& robot, const cell::Fixture& fixture, const std::optional<ScanPoint>& from) {
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const double a = robot.xy_accel_mm_s2, v = fixture.TripLatchSpeedMmS();
  // A latch from rest that reaches the latch feed at the edge, and brakes.
  const ProbeMove latch = ProbeTo(v * v / (2 * a), v, a, robot.servo_period_s);
  ScanTiming floor;
  bool known = from.has_value();
  ScanPoint at = known ? *from : ScanPoint::Zero();
  for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
    const std::vector<PathTrip> trips = TripsOfPath(fixture, expected, p);
    if (trips.empty()) continue;
    floor.travel_s += JumpSeconds(robot, fixture, known, at, trips.front().At(trips.front().along_mm));
    floor.travel_s += RiseSeconds(robot, fixture);
    floor.latch_s += static_cast<double>(trips.size()) * latch.seconds;
    floor.probe_moves += static_cast<int>(trips.size());
    const Eigen::Vector2d last = trips.back().At(trips.back().along_mm);
    at = ScanPoint(last.x(), last.y(), robot.safe_limz_mm);
    known = true;
  }
  return Finished(floor, robot, at);  // search_s is 0
}

}  // namespace smtcal
