// The C runtime's data: in memory (CRuntimeData) and as an emitted C source
// (EmitCRuntimeData); see c_data.h. Both come from the same conversions, so
// a test that runs the in-memory structures also vouches for the emitted
// ones (and another compiles the emitted source with `cc` and runs it).
#include "backend/c/c_data.h"

#include <cmath>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/error_table_check.h"
#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"
#include "calibration/inverse_calibration.h"

namespace smtcal {

bool FitsCRuntime(const cell::Fixture& fixture) {
  const std::size_t trips = ExpectedTrips(fixture).size();
  return trips >= 1 && trips <= kCRuntimeMaxTrips;
}

namespace {

smtcal_axis_table AxisView(const AxisTable& table) {
  return smtcal_axis_table{static_cast<int>(table.nx()), static_cast<int>(table.ny()), table.xs.data(),
                           table.ys.data(), table.error_mm.data()};
}

smtcal_outside_policy CPolicy(OutsidePolicy policy) {
  switch (policy) {
    case OutsidePolicy::kError: return SMTCAL_OUTSIDE_ERROR;
    case OutsidePolicy::kClamp: return SMTCAL_OUTSIDE_CLAMP;
    case OutsidePolicy::kNone: return SMTCAL_OUTSIDE_NONE;
  }
  return SMTCAL_OUTSIDE_ERROR;
}

smtcal_estimator CEstimator(cell::Estimator estimator) {
  switch (estimator) {
    case cell::Estimator::kPaper: return SMTCAL_ESTIMATOR_PAPER;
    case cell::Estimator::kRigid: return SMTCAL_ESTIMATOR_RIGID;
    case cell::Estimator::kRigidScale: return SMTCAL_ESTIMATOR_RIGID_SCALE;
  }
  return SMTCAL_ESTIMATOR_PAPER;
}

}  // namespace

smtcal_region CRuntimeRegion(const cell::Region& region) {
  const TableAnalysis analysis = AnalyzeTable(region.table);
  const Rect domain = TableDomain(region.table);
  smtcal_region r{};
  r.name = region.name.c_str();
  r.x_lo = region.x_mm.lo;
  r.x_hi = region.x_mm.hi;
  r.y_lo = region.y_mm.lo;
  r.y_hi = region.y_mm.hi;
  r.dx = AxisView(region.table[TableAxis::X]);
  r.dy = AxisView(region.table[TableAxis::Y]);
  r.domain_x0 = domain.x0;
  r.domain_x1 = domain.x1;
  r.domain_y0 = domain.y0;
  r.domain_y1 = domain.y1;
  r.contraction = analysis.contraction;
  r.iteration_bound = IterationBound(analysis.contraction, analysis.max_abs_error_mm);
  r.outside = CPolicy(region.outside);
  return r;
}

smtcal_fixture CRuntimeFixture(const cell::Fixture& fixture) {
  SMTCAL_CHECK(FitsCRuntime(fixture), "a fixture with more trips than the C runtime holds");
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture, nominal);
  smtcal_fixture f{};
  f.name = fixture.name.c_str();
  f.estimator = CEstimator(fixture.estimator);
  f.origin_x = nominal.translation().x();
  f.origin_y = nominal.translation().y();
  f.cos_angle = nominal.linear()(0, 0);
  f.sin_angle = nominal.linear()(1, 0);
  f.l1 = fixture.l1_mm;
  f.l2 = fixture.l2_mm;
  for (std::size_t e = 0; e < fixture.edges.size(); ++e) {
    const EdgeLine line = EdgeLineOf(fixture.edges[e]);
    f.edge_normal[e][0] = line.normal.x();
    f.edge_normal[e][1] = line.normal.y();
    f.edge_offset[e] = line.offset;
  }
  f.trip_count = static_cast<int>(expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    f.trip_edge[k] = expected[k].edge;
    f.trip_nominal[k][0] = trips[k].x();
    f.trip_nominal[k][1] = trips[k].y();
  }
  f.trip_window = fixture.trip_window_mm;
  f.max_shift = fixture.max_shift_mm;
  f.max_rotation_deg = fixture.max_rotation_deg;
  f.length_tolerance = fixture.length_tolerance_mm;
  f.squareness_deg = fixture.squareness_deg;
  f.max_line_residual = fixture.max_line_residual_mm;
  return f;
}

CRuntimeData::CRuntimeData(const cell::Cell& cell) {
  for (const cell::Region& region : cell.regions) regions_.push_back(CRuntimeRegion(region));
  for (const cell::Fixture& fixture : cell.fixtures) fixtures_.push_back(CRuntimeFixture(fixture));
}

// ------------------------------------------------------------------ emitting C

namespace {

// A double that reads back exactly (the shortest round-trip form).
std::string Num(double value) {
  SMTCAL_CHECK(std::isfinite(value), "a non-finite number in the C runtime data");
  if (value == 0) value = 0;  // no "-0"
  return fmt::format("{}", value);
}

// A C string literal: printable ASCII as is, everything else (and '?', so no
// trigraph can form) as an octal escape. The file stays ASCII.
std::string CString(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (byte < 0x20 || byte >= 0x7f || c == '?') {
      out += fmt::format("\\{:03o}", byte);
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Text inside a /* */ comment: ASCII, no "*/".
std::string CommentText(std::string_view text) {
  std::string out;
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte < 0x20 || byte >= 0x7f ? '?' : c;
    if (out.size() >= 2 && out.compare(out.size() - 2, 2, "*/") == 0) out.back() = '_';
  }
  return out;
}

std::string NumberArray(const std::vector<double>& values, std::size_t per_line) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += i % per_line == 0 ? "\n    " : " ";
    out += Num(values[i]) + ",";
  }
  return out + "\n";
}

std::string EnumName(smtcal_outside_policy policy) {
  switch (policy) {
    case SMTCAL_OUTSIDE_ERROR: return "SMTCAL_OUTSIDE_ERROR";
    case SMTCAL_OUTSIDE_CLAMP: return "SMTCAL_OUTSIDE_CLAMP";
    case SMTCAL_OUTSIDE_NONE: return "SMTCAL_OUTSIDE_NONE";
  }
  return "SMTCAL_OUTSIDE_ERROR";
}

std::string EnumName(smtcal_estimator estimator) {
  switch (estimator) {
    case SMTCAL_ESTIMATOR_PAPER: return "SMTCAL_ESTIMATOR_PAPER";
    case SMTCAL_ESTIMATOR_RIGID: return "SMTCAL_ESTIMATOR_RIGID";
    case SMTCAL_ESTIMATOR_RIGID_SCALE: return "SMTCAL_ESTIMATOR_RIGID_SCALE";
  }
  return "SMTCAL_ESTIMATOR_PAPER";
}

void EmitTables(std::string& out, std::size_t index, const cell::Region& region) {
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = region.table[axis];
    const std::string prefix = fmt::format("region{}_d{}", index, AxisName(axis));
    out += fmt::format("/* region {}: Delta-{} on {} x {} nodes (mm) */\n", CommentText(region.name), AxisName(axis),
                       t.nx(), t.ny());
    out += fmt::format("static const double {}_xs[{}] = {{{}}};\n", prefix, t.nx(), NumberArray(t.xs, 10));
    out += fmt::format("static const double {}_ys[{}] = {{{}}};\n", prefix, t.ny(), NumberArray(t.ys, 10));
    out += fmt::format("static const double {}_values[{}] = {{{}}};\n\n", prefix, t.error_mm.size(),
                       NumberArray(t.error_mm, t.nx()));
  }
}

std::string EmitRegion(std::size_t index, const cell::Region& region) {
  const smtcal_region r = CRuntimeRegion(region);
  auto axis = [&](const smtcal_axis_table& t, std::string_view name) {
    const std::string prefix = fmt::format("region{}_d{}", index, name);
    return fmt::format("{{{}, {}, {}_xs, {}_ys, {}_values}}", t.nx, t.ny, prefix, prefix, prefix);
  };
  std::string out = "  {\n";
  out += fmt::format("    .name = {},\n", CString(region.name));
  out += fmt::format("    .x_lo = {}, .x_hi = {}, .y_lo = {}, .y_hi = {},\n", Num(r.x_lo), Num(r.x_hi), Num(r.y_lo),
                     Num(r.y_hi));
  out += fmt::format("    .dx = {},\n    .dy = {},\n", axis(r.dx, "x"), axis(r.dy, "y"));
  out += fmt::format("    .domain_x0 = {}, .domain_x1 = {}, .domain_y0 = {}, .domain_y1 = {},\n", Num(r.domain_x0),
                     Num(r.domain_x1), Num(r.domain_y0), Num(r.domain_y1));
  out += fmt::format("    .contraction = {},\n    .iteration_bound = {},\n    .outside = {},\n", Num(r.contraction),
                     r.iteration_bound, EnumName(r.outside));
  return out + "  },\n";
}

std::string EmitFixture(const cell::Fixture& fixture) {
  const smtcal_fixture f = CRuntimeFixture(fixture);
  std::string out = "  {\n";
  out += fmt::format("    .name = {},\n    .estimator = {},\n", CString(fixture.name), EnumName(f.estimator));
  out += fmt::format("    .origin_x = {}, .origin_y = {},\n", Num(f.origin_x), Num(f.origin_y));
  out += fmt::format("    .cos_angle = {}, .sin_angle = {},\n", Num(f.cos_angle), Num(f.sin_angle));
  out += fmt::format("    .l1 = {}, .l2 = {},\n", Num(f.l1), Num(f.l2));
  out += "    .edge_normal = {";
  for (int e = 0; e < SMTCAL_EDGE_COUNT; ++e) {
    out += fmt::format("{}{{{}, {}}}", e == 0 ? "" : ", ", Num(f.edge_normal[e][0]), Num(f.edge_normal[e][1]));
  }
  out += "},\n    .edge_offset = {";
  for (int e = 0; e < SMTCAL_EDGE_COUNT; ++e) out += fmt::format("{}{}", e == 0 ? "" : ", ", Num(f.edge_offset[e]));
  out += fmt::format("}},  /* {}, {}, {}, {} */\n", CommentText(fixture.edges[0].name),
                     CommentText(fixture.edges[1].name), CommentText(fixture.edges[2].name),
                     CommentText(fixture.edges[3].name));
  out += fmt::format("    .trip_count = {},\n    .trip_edge = {{", f.trip_count);
  for (int k = 0; k < f.trip_count; ++k) out += fmt::format("{}{}", k == 0 ? "" : ", ", f.trip_edge[k]);
  out += "},\n    .trip_nominal = {";
  for (int k = 0; k < f.trip_count; ++k) {
    out += fmt::format("{}{{{}, {}}}", k == 0 ? "" : ", ", Num(f.trip_nominal[k][0]), Num(f.trip_nominal[k][1]));
  }
  out += "},\n";
  out += fmt::format("    .trip_window = {},\n    .max_shift = {}, .max_rotation_deg = {},\n", Num(f.trip_window),
                     Num(f.max_shift), Num(f.max_rotation_deg));
  out += fmt::format("    .length_tolerance = {}, .squareness_deg = {}, .max_line_residual = {},\n",
                     Num(f.length_tolerance), Num(f.squareness_deg), Num(f.max_line_residual));
  return out + "  },\n";
}

int FixtureIndex(const cell::Cell& cell, const std::string& name) {
  if (name.empty()) return -1;
  const cell::Fixture* fixture = cell.FindFixture(name);
  SMTCAL_CHECK(fixture != nullptr, "a C runtime point on a fixture the cell does not describe");
  return static_cast<int>(fixture - cell.fixtures.data());
}

}  // namespace

std::string CRuntimeProgramSymbol(std::string_view program_name) {
  std::string symbol = "smtcal_program_";
  for (char c : program_name) {
    const bool word = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    symbol += word ? c : '_';
  }
  return symbol;
}

std::string EmitCRuntimeData(const cell::Cell& cell, const std::vector<CRuntimePoint>& points,
                             std::string_view program_name) {
  const std::string symbol = CRuntimeProgramSymbol(program_name);
  std::string out;
  out += fmt::format(
      "/* Runtime data of program {} for cell {}, written by smtcal {} (smtcal compile --target c).\n"
      " * Do not edit: compile the program again. Link it with runtime/c/smtcal_runtime.c and\n"
      " * declare `extern const smtcal_program {};` where it is used.\n"
      " * Fixture points are in their fixture's frame (mm, degrees); fixtures are indexed in cell order. */\n",
      CommentText(program_name), CommentText(cell.name), SMTCAL_VERSION, symbol);
  out += "#include \"smtcal_runtime.h\"\n\n";
  out += fmt::format("extern const smtcal_program {};\n\n", symbol);

  for (std::size_t r = 0; r < cell.regions.size(); ++r) EmitTables(out, r, cell.regions[r]);
  if (!cell.regions.empty()) {
    out += fmt::format("static const smtcal_region regions[{}] = {{\n", cell.regions.size());
    for (std::size_t r = 0; r < cell.regions.size(); ++r) out += EmitRegion(r, cell.regions[r]);
    out += "};\n\n";
  }
  if (!cell.fixtures.empty()) {
    out += fmt::format("static const smtcal_fixture fixtures[{}] = {{\n", cell.fixtures.size());
    for (const cell::Fixture& fixture : cell.fixtures) out += EmitFixture(fixture);
    out += "};\n\n";
  }
  if (!points.empty()) {
    out += fmt::format("static const smtcal_point points[{}] = {{\n", points.size());
    for (const CRuntimePoint& point : points) {
      out += fmt::format("  {{{}, {}, {}, {}, {}, {}}},", CString(point.name), FixtureIndex(cell, point.fixture),
                         Num(point.fix_mm.x()), Num(point.fix_mm.y()), Num(point.z_mm), Num(point.u_deg));
      out += point.loc.line != 0 ? fmt::format("  /* line {} */\n", point.loc.line) : "\n";
    }
    out += "};\n\n";
  }
  out += fmt::format("const smtcal_program {} = {{\n", symbol);
  out += fmt::format("  {},\n", CString(program_name));
  out += cell.regions.empty() ? "  0, 0,\n" : fmt::format("  regions, {},\n", cell.regions.size());
  out += cell.fixtures.empty() ? "  0, 0,\n" : fmt::format("  fixtures, {},\n", cell.fixtures.size());
  out += points.empty() ? "  0, 0,\n" : fmt::format("  points, {},\n", points.size());
  return out + "};\n";
}

std::vector<CRuntimePoint> CRuntimeFixturePoints(const CompileState& state) {
  std::vector<CRuntimePoint> points;
  for (const Target& target : state.targets) {
    if (target.kind != CorrectionKind::kFixture || !target.known) continue;
    points.push_back(CRuntimePoint{target.text, state.fixtures[target.fixture].cell_fixture->name,
                                   Eigen::Vector2d(target.in_frame[0], target.in_frame[1]), target.in_frame[2],
                                   target.in_frame[3], target.stmt->loc});
  }
  return points;
}

}  // namespace smtcal
