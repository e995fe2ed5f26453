// Registering the set-ups of the artefact (calibration/measurement_registration.h).
#include "calibration/measurement_registration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <tuple>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "base/check.h"
#include "calibration/tolerances.h"

namespace smtcal::measure {
namespace {

// d g(h) / d pose along one axis: x: (1, 0, −(h − o)_y), y: (0, 1, (h − o)_x).
Eigen::RowVector3d Row(const SetupKey& key, const Eigen::Vector2d& h, TableAxis axis) {
  const Eigen::Vector2d d = h - key.origin;
  return axis == TableAxis::X ? Eigen::RowVector3d(1, 0, -d.y()) : Eigen::RowVector3d(0, 1, d.x());
}

int Find(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace

Eigen::Vector2d SetupPose::Displacement(const Eigen::Vector2d& h) const {
  return Eigen::Vector2d(Row(key, h, TableAxis::X).dot(pose), Row(key, h, TableAxis::Y).dot(pose));
}

Eigen::Vector2d SetupPose::Uncertainty(const Eigen::Vector2d& h) const {
  const Eigen::RowVector3d rx = Row(key, h, TableAxis::X), ry = Row(key, h, TableAxis::Y);
  return Eigen::Vector2d(std::sqrt(std::max(0.0, (rx * covariance * rx.transpose())(0))),
                         std::sqrt(std::max(0.0, (ry * covariance * ry.transpose())(0))));
}

Registration RegisterSetups(const std::vector<SetupKey>& setups, const std::vector<SetupReading>& readings,
                            double sigma_mm, bool rigid_artefact) {
  SMTCAL_CHECK(sigma_mm > 0, "a reading's standard deviation is positive");
  Registration out;
  const std::size_t count = setups.size();
  for (const SetupKey& key : setups) out.setups.push_back(SetupPose{key});
  // The mean of each set-up's readings per node and axis.
  struct Mean {
    double sum = 0;
    int n = 0;
    Eigen::Vector2d at = Eigen::Vector2d::Zero();
  };
  std::map<std::tuple<int, int, std::size_t>, Mean> means;  // (node, axis, setup)
  for (const SetupReading& r : readings) {
    SMTCAL_CHECK(r.setup < count, "a reading of a known set-up");
    Mean& m = means[{r.node, static_cast<int>(r.axis), r.setup}];
    m.sum += r.error_mm;
    ++m.n;
    m.at = r.at;
  }
  struct Member {
    std::size_t setup;
    double mean;
    double weight;
    Eigen::RowVector3d row;
  };
  std::vector<std::tuple<int, TableAxis, Eigen::Vector2d, std::vector<Member>>> ties;
  for (auto it = means.begin(); it != means.end();) {
    const int node = std::get<0>(it->first), axis = std::get<1>(it->first);
    std::vector<Member> members;
    const Eigen::Vector2d at = it->second.at;
    for (; it != means.end() && std::get<0>(it->first) == node && std::get<1>(it->first) == axis; ++it) {
      const std::size_t u = std::get<2>(it->first);
      members.push_back({u, it->second.sum / it->second.n, it->second.n / (sigma_mm * sigma_mm),
                         Row(setups[u], at, static_cast<TableAxis>(axis))});
    }
    if (members.size() >= 2) ties.emplace_back(node, static_cast<TableAxis>(axis), at, std::move(members));
  }
  // Groups: set-ups joined by ties.
  std::vector<int> parent(count);
  std::iota(parent.begin(), parent.end(), 0);
  if (rigid_artefact) {
    for (const auto& [node, axis, at, members] : ties) {
      for (const Member& m : members) {
        parent[static_cast<std::size_t>(Find(parent, static_cast<int>(m.setup)))] =
            Find(parent, static_cast<int>(members.front().setup));
      }
    }
  }
  std::map<int, int> group_of_root;
  for (std::size_t u = 0; u < count; ++u) {
    auto [it, fresh] = group_of_root.try_emplace(Find(parent, static_cast<int>(u)), static_cast<int>(group_of_root.size()));
    out.setups[u].group = it->second;
  }
  out.groups = static_cast<int>(group_of_root.size());
  if (!rigid_artefact || count == 0) return out;

  // The normal equations of the ties in the poses (ē eliminated).
  const auto dim = static_cast<Eigen::Index>(3 * count);
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(dim, dim);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(dim);
  int equations = 0;
  std::set<std::pair<std::size_t, int>> tied;  // (set-up, node)
  for (const auto& [node, axis, at, members] : ties) {
    double total = 0;
    for (const Member& m : members) total += m.weight;
    for (const Member& i : members) {
      for (const Member& j : members) {
        const double c = (i.setup == j.setup && &i == &j ? i.weight : 0.0) - i.weight * j.weight / total;
        const auto bi = static_cast<Eigen::Index>(3 * i.setup), bj = static_cast<Eigen::Index>(3 * j.setup);
        normal.block<3, 3>(bi, bj) += c * i.row.transpose() * j.row;
        rhs.segment<3>(bi) -= c * j.mean * i.row.transpose();
      }
    }
    equations += static_cast<int>(members.size()) - 1;
    for (const Member& m : members) {
      if (tied.insert({m.setup, node}).second) ++out.setups[m.setup].tied_nodes;
    }
  }
  // A pose component no tie fixes (a transducer's set-up reads one axis)
  // stays 0: a ridge far below the ties' weights.
  const double scale = std::max(normal.diagonal().cwiseAbs().maxCoeff(), 1.0 / (sigma_mm * sigma_mm));
  normal.diagonal().array() += 1e-12 * scale;
  // The gauge: each group's poses sum to zero (Lagrange multipliers).
  const auto constraints = static_cast<Eigen::Index>(3 * out.groups);
  Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(dim + constraints, dim + constraints);
  kkt.topLeftCorner(dim, dim) = normal;
  for (std::size_t u = 0; u < count; ++u) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index row = dim + 3 * out.setups[u].group + k;
      const Eigen::Index col = static_cast<Eigen::Index>(3 * u) + k;
      kkt(row, col) = 1;
      kkt(col, row) = 1;
    }
  }
  Eigen::VectorXd full_rhs = Eigen::VectorXd::Zero(dim + constraints);
  full_rhs.head(dim) = rhs;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(kkt);
  const Eigen::VectorXd solution = lu.solve(full_rhs);
  const Eigen::MatrixXd inverse = lu.inverse();
  // Chi-square of the ties at the solution.
  double chi2 = 0;
  std::map<std::pair<std::size_t, std::size_t>, TieResidual> worst;  // per set-up pair
  for (const auto& [node, axis, at, members] : ties) {
    double total = 0, mean = 0;
    for (const Member& m : members) {
      total += m.weight;
      mean += m.weight * (m.mean + m.row.dot(solution.segment<3>(static_cast<Eigen::Index>(3 * m.setup))));
    }
    mean /= total;
    for (const Member& m : members) {
      const double r = m.mean + m.row.dot(solution.segment<3>(static_cast<Eigen::Index>(3 * m.setup))) - mean;
      chi2 += m.weight * r * r;
      const double sigma = std::sqrt(std::max(1.0 / m.weight - 1.0 / total, 0.0));
      for (const Member& other : members) {
        if (other.setup == m.setup) continue;
        auto key = std::minmax(m.setup, other.setup);
        TieResidual candidate{node, at, axis, m.setup, r, sigma};
        auto [it, fresh] = worst.try_emplace(key, candidate);
        const auto ratio = [](const TieResidual& t) { return t.sigma_mm > 0 ? std::abs(t.residual_mm) / t.sigma_mm : 0.0; };
        if (!fresh && ratio(candidate) > ratio(it->second)) it->second = candidate;
      }
    }
  }
  int fixed = 0;  // pose components the ties fix
  for (const SetupPose& s : out.setups) fixed += s.tied_nodes > 0 ? 3 : 0;
  for (int g = 0; g < out.groups; ++g) {
    bool tied = false;
    for (const SetupPose& s : out.setups) tied = tied || (s.group == g && s.tied_nodes > 0);
    if (tied) fixed -= 3;
  }
  out.dof = equations - fixed;
  out.chi2_per_dof = out.dof > 0 ? chi2 / out.dof : 0;
  const double inflate = std::max(1.0, out.chi2_per_dof);
  for (std::size_t u = 0; u < count; ++u) {
    const auto b = static_cast<Eigen::Index>(3 * u);
    out.setups[u].pose = solution.segment<3>(b);
    out.setups[u].covariance = inflate * inverse.block<3, 3>(b, b);
    // A component the ridge pinned: no uncertainty worth stating from it.
    for (int k = 0; k < 3; ++k) {
      if (out.setups[u].covariance(k, k) < 0) out.setups[u].covariance(k, k) = 0;
    }
  }
  for (const auto& [key, residual] : worst) out.largest.push_back(residual);
  std::stable_sort(out.largest.begin(), out.largest.end(), [](const TieResidual& a, const TieResidual& b) {
    const double ra = a.sigma_mm > 0 ? std::abs(a.residual_mm) / a.sigma_mm : 0;
    const double rb = b.sigma_mm > 0 ? std::abs(b.residual_mm) / b.sigma_mm : 0;
    return ra > rb;
  });
  return out;
}

}  // namespace smtcal::measure

namespace smtcal::measure {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSqrt3 = 1.7320508075688772;

const PlanStation* StationOf(const Plan& plan, int number) {
  for (const PlanStation& s : plan.stations) {
    if (s.number == number) return &s;
  }
  return nullptr;
}

// The groups of the plan's stations that no tie joins.
int PlanGroups(const Plan& plan) {
  std::map<int, int> parent;
  for (const PlanStation& s : plan.stations) parent[s.number] = s.number;
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i];
    return i;
  };
  for (const PlanStation& s : plan.stations) {
    for (int t : s.tied_to) {
      if (parent.contains(t)) parent[find(s.number)] = find(t);
    }
  }
  int groups = 0;
  for (const auto& [station, p] : parent) groups += station == p ? 1 : 0;
  return groups;
}

std::string Signed(double v, int decimals) {
  if (std::abs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0;
  return fmt::format("{:+.{}f}", v, decimals);
}

}  // namespace

ReadOutcome RegisterReadings(const cell::Cell& cell, const Plan& plan, const std::vector<Reading>& readings,
                             std::string_view plan_name, Diagnostics& diags) {
  ReadOutcome out;
  const cell::Measure& m = *cell.measure;
  const bool probe = m.device == cell::MeasureDevice::kProbe;
  const bool rigid = m.device != cell::MeasureDevice::kExternal;
  const double latency_u = probe ? m.probe.speed_mm_s * cell.robot.servo_period_s / (2 * kSqrt3) : 0.0;
  out.sigma_mm = std::max(std::hypot(m.noise_mm, latency_u), kNoisyNodeFloorMm);
  out.plan_groups = rigid ? PlanGroups(plan) : 1;
  // The set-ups: each station in each set.
  std::vector<SetupKey> keys;
  std::map<std::pair<int, int>, std::size_t> setup_index;
  for (const Reading& r : readings) {
    auto [it, fresh] = setup_index.try_emplace({r.station, r.set}, keys.size());
    if (fresh) {
      const PlanStation* station = StationOf(plan, r.station);
      keys.push_back({r.station, r.set, station != nullptr ? station->origin : r.at});
    }
    out.setup_of.push_back(it->second);
  }
  std::vector<Eigen::Vector2d> shift(readings.size(), Eigen::Vector2d::Zero());
  std::vector<ReadingError> errors;
  for (int pass = 0; pass < 4; ++pass) {
    std::vector<std::string> notes;
    errors = ErrorsOfReadings(m, cell.robot, plan.regions, readings, shift, notes);
    if (pass == 0) {
      // The closures: each set's first point again at its end.
      std::map<std::pair<std::size_t, TableAxis>, std::pair<double, int>> first_sum, closure_sum;
      std::map<std::size_t, int> first_visit;  // per set-up: its first (non-closure) visit
      for (const Reading& r : readings) {
        if (r.kind == VisitKind::kClosure) continue;
        auto [it, fresh] = first_visit.try_emplace(out.setup_of[static_cast<std::size_t>(&r - readings.data())], r.visit);
        if (!fresh) it->second = std::min(it->second, r.visit);
      }
      std::map<std::size_t, const Reading*> closure_reading;
      for (const ReadingError& e : errors) {
        const Reading& r = readings[e.reading];
        const std::size_t u = out.setup_of[e.reading];
        if (r.kind == VisitKind::kClosure) {
          auto& sum = closure_sum[{u, e.axis}];
          sum.first += e.error_mm;
          ++sum.second;
          closure_reading.try_emplace(u, &r);
        } else if (r.visit == first_visit[u] && r.direction > 0) {
          auto& sum = first_sum[{u, e.axis}];
          sum.first += e.error_mm;
          ++sum.second;
        }
      }
      for (const auto& [u, closing] : closure_reading) {
        double worst = 0, allowed = 0;
        for (TableAxis axis : kTableAxes) {
          auto c = closure_sum.find({u, axis});
          auto f = first_sum.find({u, axis});
          if (c == closure_sum.end() || f == first_sum.end()) continue;
          const double d = std::abs(c->second.first / c->second.second - f->second.first / f->second.second);
          const double limit = std::max(
              kPlateMovedFloorMm, 5 * out.sigma_mm * std::sqrt(1.0 / c->second.second + 1.0 / f->second.second));
          if (d - limit > worst - allowed) {
            worst = d;
            allowed = limit;
          }
        }
        if (worst > allowed) {
          diags.Report(DiagKind::MeasurePlateMoved, closing->where, keys[u].station, keys[u].set, closing->visit,
                       closing->node, fmt::format("{:.4f}", worst), first_visit[u], fmt::format("{:.4f}", allowed),
                       plan_name, first_visit[u]);
        }
      }
      if (diags.has_errors()) return out;
    }
    if (pass == 3) {
      out.notes = notes;
      break;
    }
    std::vector<SetupReading> setup_readings;
    for (const ReadingError& e : errors) {
      if (readings[e.reading].direction < 0) continue;  // the reversal carries the backlash besides
      setup_readings.push_back({out.setup_of[e.reading], readings[e.reading].node, readings[e.reading].at, e.axis,
                                e.error_mm});
    }
    out.registration = RegisterSetups(keys, setup_readings, out.sigma_mm, rigid);
    for (std::size_t k = 0; k < readings.size(); ++k) {
      shift[k] = out.registration.setups[out.setup_of[k]].Displacement(readings[k].at);
    }
  }
  // Registered errors and their budget.
  const double k_ppm = m.artefact_pitch_error_ppm * 1e-6;
  const double u_ppm = m.artefact_pitch_u_ppm * 1e-6;
  const double diameters = probe ? 0.5 * std::hypot(m.probe.hole_diameter_u_mm, m.probe.stylus_diameter_u_mm) : 0.0;
  const double placement = m.placement_mm.value_or(cell.robot.uncalibrated_accuracy_mm.value_or(kPlanAssumedAccuracyMm));
  const double turn = m.placement_deg * kPi / 180;
  for (const ReadingError& e : errors) {
    const Reading& r = readings[e.reading];
    const SetupPose& pose = out.registration.setups[out.setup_of[e.reading]];
    const int a = static_cast<int>(e.axis);
    const Eigen::Vector2d from = r.at - pose.key.origin;
    RegisteredError reg;
    reg.reading = e.reading;
    reg.axis = e.axis;
    reg.error_mm = e.error_mm + shift[e.reading][a] + (rigid ? from[a] * k_ppm : 0.0);
    reg.artefact_mm = rigid ? std::abs(from[a]) * u_ppm : 0.0;
    reg.diameters_mm = diameters;
    reg.latency_mm = latency_u;
    reg.registration_mm = pose.Uncertainty(r.at)[a];
    reg.placement_mm = out.plan_groups > 1 ? std::hypot(placement, turn * from.norm()) / kSqrt3 : 0.0;
    reg.u_mm = std::sqrt(reg.artefact_mm * reg.artefact_mm + reg.diameters_mm * reg.diameters_mm +
                         reg.latency_mm * reg.latency_mm + reg.registration_mm * reg.registration_mm +
                         reg.placement_mm * reg.placement_mm);
    out.errors.push_back(reg);
  }
  // An artefact that moved between sets: registered apart, said.
  std::map<int, std::vector<std::size_t>> sets_of_station;
  for (std::size_t u = 0; u < out.registration.setups.size(); ++u) {
    sets_of_station[out.registration.setups[u].key.station].push_back(u);
  }
  for (const auto& [station_number, setups] : sets_of_station) {
    const PlanStation* station = StationOf(plan, station_number);
    if (station == nullptr) continue;
    for (std::size_t i = 1; i < setups.size(); ++i) {
      const SetupPose& a = out.registration.setups[setups[i - 1]];
      const SetupPose& b = out.registration.setups[setups[i]];
      double moved = 0, allowed = 0;
      for (const Eigen::Vector2d& corner : {station->origin, station->far, Eigen::Vector2d(station->origin.x(), station->far.y()),
                                            Eigen::Vector2d(station->far.x(), station->origin.y())}) {
        const double d = (b.Displacement(corner) - a.Displacement(corner)).norm();
        if (d > moved) {
          moved = d;
          allowed = std::max(kPlateMovedFloorMm, 4 * std::hypot(a.Uncertainty(corner).norm(), b.Uncertainty(corner).norm()));
        }
      }
      if (moved <= allowed) continue;
      const Reading* at = nullptr;
      for (const Reading& r : readings) {
        if (r.station == station_number && r.set == b.key.set && (at == nullptr || r.visit < at->visit)) at = &r;
      }
      const Eigen::Vector3d d = b.pose - a.pose;
      diags.Report(DiagKind::MeasurePlateMovedBetweenSets, at != nullptr ? at->where : SourceRange(), station_number,
                   a.key.set, b.key.set, fmt::format("{:.4f}", moved), Signed(d.x(), 4), Signed(d.y(), 4),
                   Signed(d.z() * 180 / kPi, 4));
    }
  }
  // Ties that disagree beyond the readings' noise.
  int said = 0;
  for (const TieResidual& t : out.registration.largest) {
    if (said >= 3 || t.sigma_mm <= 0) break;
    const double ratio = std::abs(t.residual_mm) / t.sigma_mm;
    if (ratio <= 5 || std::abs(t.residual_mm) <= kPlateMovedFloorMm) continue;
    const Reading* at = nullptr;
    for (const Reading& r : readings) {
      if (r.node == t.node && out.setup_of[static_cast<std::size_t>(&r - readings.data())] == t.setup) {
        at = &r;
        break;
      }
    }
    diags.Report(DiagKind::MeasureTieResidual, at != nullptr ? at->where : SourceRange(), t.node, AxisName(t.axis),
                 fmt::format("{:.4f}", std::abs(t.residual_mm)), out.registration.setups[t.setup].key.station,
                 fmt::format("{:.1f}", ratio), fmt::format("{:.2f}", std::sqrt(std::max(1.0, out.registration.chi2_per_dof))));
    ++said;
  }
  return out;
}

std::vector<std::string> DescribeBudget(const cell::Cell& cell, const Plan& plan, const ReadOutcome& outcome,
                                        std::size_t region, const std::vector<Reading>& readings) {
  const cell::Measure& m = *cell.measure;
  const bool probe = m.device == cell::MeasureDevice::kProbe;
  std::array<RegisteredError, 2> largest{};  // per axis: each term's largest over the region's nodes
  std::array<bool, 2> has{false, false};
  for (const RegisteredError& e : outcome.errors) {
    if (readings[e.reading].region != region) continue;
    RegisteredError& l = largest[static_cast<std::size_t>(e.axis)];
    has[static_cast<std::size_t>(e.axis)] = true;
    l.artefact_mm = std::max(l.artefact_mm, e.artefact_mm);
    l.diameters_mm = std::max(l.diameters_mm, e.diameters_mm);
    l.latency_mm = std::max(l.latency_mm, e.latency_mm);
    l.registration_mm = std::max(l.registration_mm, e.registration_mm);
    l.placement_mm = std::max(l.placement_mm, e.placement_mm);
    l.u_mm = std::max(l.u_mm, e.u_mm);
  }
  auto both = [&](double RegisteredError::*term) {
    std::string out;
    for (std::size_t a = 0; a < 2; ++a) {
      if (!has[a]) continue;
      out += fmt::format("{}{}: {:.4f}", out.empty() ? "" : ", ", a == 0 ? "x" : "y", largest[a].*term);
    }
    return out + " mm";
  };
  std::vector<std::string> lines;
  lines.push_back(fmt::format(
      "the measurement's uncertainty (GUM, standard uncertainties, the largest at a node of region {}; the "
      "readings' own scatter is the table's stddev_mm / sqrt(n), type A; the terms below are type B, in the "
      "u_mm column combined):",
      plan.regions[region].name));
  if (m.device != cell::MeasureDevice::kExternal) {
    lines.push_back(fmt::format("  the artefact's certificate (pitch error {} ppm corrected, uncertain by {} ppm): {}",
                                m.artefact_pitch_error_ppm, m.artefact_pitch_u_ppm, both(&RegisteredError::artefact_mm)));
  }
  if (probe) {
    lines.push_back(fmt::format("  the stylus and hole diameters (uncertain by {} and {} mm): {}",
                                m.probe.stylus_diameter_u_mm, m.probe.hole_diameter_u_mm,
                                both(&RegisteredError::diameters_mm)));
    lines.push_back(fmt::format("  the probe's latency (a trip latched 0 to 1 servo period late; half a period taken "
                                "off): {}",
                                both(&RegisteredError::latency_mm)));
  }
  if (m.device != cell::MeasureDevice::kExternal) {
    lines.push_back(fmt::format("  the registration of the artefact's placements (least squares over the ties): {}",
                                both(&RegisteredError::registration_mm)));
    if (outcome.plan_groups > 1) {
      lines.push_back(fmt::format("  the placement of stations no tie joins ({} groups: their relative placement was "
                                  "not measured, up to {} mm and {} degree, uniform): {}",
                                  outcome.plan_groups,
                                  m.placement_mm.value_or(cell.robot.uncalibrated_accuracy_mm.value_or(
                                      kPlanAssumedAccuracyMm)),
                                  m.placement_deg, both(&RegisteredError::placement_mm)));
    }
  }
  lines.push_back("  thermal expansion: not in the budget (the log holds no temperatures)");
  lines.push_back(fmt::format("  combined (u_mm): {}", both(&RegisteredError::u_mm)));
  if (m.device != cell::MeasureDevice::kExternal) {
    const Registration& reg = outcome.registration;
    lines.push_back(fmt::format(
        "registration: {} placement{} of the artefact (stations x sets) in {} group{}; the ties: {} degree{} of "
        "freedom, chi-square per degree of freedom {:.2f}{}",
        reg.setups.size(), reg.setups.size() == 1 ? "" : "s", reg.groups, reg.groups == 1 ? "" : "s", reg.dof,
        reg.dof == 1 ? "" : "s", reg.chi2_per_dof, reg.chi2_per_dof > 1 ? " (the uncertainty scaled up by it)" : ""));
    for (const SetupPose& pose : reg.setups) {
      const Eigen::Vector3d sd = pose.covariance.diagonal().cwiseMax(0).cwiseSqrt();
      // A component no reading fixes (a transducer's placement reads one
      // axis) is not measured: it is held at 0.
      auto value = [](double v, double u, double scale, int decimals) {
        return u * scale > 1 ? std::string("not measured") : Signed(v * scale, decimals);
      };
      auto spread = [](double u, double scale) {
        return u * scale > 1 ? std::string("-") : fmt::format("{:.4f}", u * scale);
      };
      lines.push_back(fmt::format(
          "  station {} set {}: the artefact lay {} mm, {} mm off and turned {} degree about ({}, {}) (standard "
          "uncertainty {} mm, {} mm, {} degree; {} tied node{})",
          pose.key.station, pose.key.set, value(pose.pose.x(), sd.x(), 1, 4), value(pose.pose.y(), sd.y(), 1, 4),
          value(pose.pose.z(), sd.z(), 180 / kPi, 4), FormatMm(pose.key.origin.x()), FormatMm(pose.key.origin.y()),
          spread(sd.x(), 1), spread(sd.y(), 1), spread(sd.z(), 180 / kPi), pose.tied_nodes,
          pose.tied_nodes == 1 ? "" : "s"));
    }
  }
  return lines;
}

}  // namespace smtcal::measure
