// `smtcal diff` on one machine, as a differential test over a matrix of cell
// changes (docs/diff.md, "On the machine"). For each change — the board's
// origin, angle, L1 and L2, each marker edge, a scan path, the teach trips,
// the estimator, every check limit, speeds, each region's table in x or y,
// the marker tables, a feeder, a pallet, place_z — the example (and random
// programs, tests/unit/backend/random_place_program.h) is compiled for the
// example cell (OLD) and for the changed copy (NEW), as .place and for
// LinuxCNC, the way a user does (the smtcal executable), and:
//   - both forms give the same verdict, the same counts and the same moved
//     positions with the same moves;
//   - a second model computes every position's move: the machine is NEW's
//     cell, each program's scan trips found by bisection on F_true (NEW's
//     tables through the C runtime's smtcal_direct) against NEW's true marker
//     edges, its FIX, command and landing from the C runtime (runtime/c:
//     smtcal_scan, smtcal_correct, smtcal_invert with its own cell's data),
//     at the same board poses; the diff's moves (at the nominal pose and the
//     worst over the poses) and its moved set must be that model's, and so
//     must the set it gates.
// Each entry prints its moved count and largest move ("[matrix] ...").
//
// Random programs print their seed; SMTCAL_TEST_SEED repeats one.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "backend/c/c_data.h"
#include "calibration/fixture_geometry.h"
#include "calibration/machine_model.h"
#include "calibration/tolerances.h"
#include "frontend/cell_toml.h"
#include "frontend/parse.h"
#include "ir/ir_walk.h"
#include "passes/machine_targets.h"
#include "passes/pass_manager.h"
#include "tests/unit/backend/random_place_program.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kExample = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell";

// One change of the example cell: text replacements in paper.cell.toml, and
// optionally every x or y error of one table shifted.
struct TableShift {
  std::string file;
  char axis = 'x';
  double mm = 0;
};
struct Entry {
  std::string name;
  std::vector<std::pair<std::string, std::string>> edits;
  std::optional<TableShift> table;
};
void PrintTo(const Entry& entry, std::ostream* out) { *out << entry.name; }

const std::vector<Entry>& Entries() {
  static const std::vector<Entry> entries = {
      {"origin_x", {{"origin_mm = [138, 40]", "origin_mm = [138.02, 40]"}}, {}},
      {"origin_y", {{"origin_mm = [138, 40]", "origin_mm = [138, 39.98]"}}, {}},
      {"angle", {{"angle_deg = 0\n", "angle_deg = 0.01\n"}}, {}},
      // The board re-measured: marker 2 20 µm further out (the L1 example).
      {"l1",
       {{"l1_mm = 190\n", "l1_mm = 190.02\n"},
        {"p3 = { from_mm = [190, 82], to_mm = [190, 90] }", "p3 = { from_mm = [190.02, 82], to_mm = [190.02, 90] }"},
        {"p4 = { from_mm = [182, 90], to_mm = [190, 90] }", "p4 = { from_mm = [182.02, 90], to_mm = [190.02, 90] }"}},
       {}},
      {"l2",
       {{"l2_mm = 90\n", "l2_mm = 90.02\n"},
        {"p4 = { from_mm = [182, 90], to_mm = [190, 90] }", "p4 = { from_mm = [182, 90.02], to_mm = [190, 90.02] }"}},
       {}},
      // p1 and p2 along their lines (the sensor sees less of them); p3 and p4
      // turned 0.2 mrad about the corner they make with p1 and p2 (S2 and S3
      // stay where L1 and L2 put them).
      {"edge_p1", {{"p1 = { from_mm = [0, 0], to_mm = [8, 0] }", "p1 = { from_mm = [0.5, 0], to_mm = [7.5, 0] }"}}, {}},
      {"edge_p2", {{"p2 = { from_mm = [0, 0], to_mm = [0, 8] }", "p2 = { from_mm = [0, 0.5], to_mm = [0, 7.5] }"}}, {}},
      {"edge_p3",
       {{"p3 = { from_mm = [190, 82], to_mm = [190, 90] }", "p3 = { from_mm = [190.0164, 82], to_mm = [190.018, 90] }"}},
       {}},
      {"edge_p4",
       {{"p4 = { from_mm = [182, 90], to_mm = [190, 90] }", "p4 = { from_mm = [182, 90.0364], to_mm = [190, 90.038] }"}},
       {}},
      {"scan_path",
       {{"points_mm = [[194.1, 85.9], [185.9, 85.9], [185.9, 94.1], [186.1, 94.1], [186.1, 86.1], [194.1, 86.1]]",
         "points_mm = [[194.1, 85.6], [185.6, 85.6], [185.6, 94.1], [186.4, 94.1], [186.4, 86.4], [194.1, 86.4]]"}},
       {}},
      // The teach-time scan 10 µm further in x: the taught point with it.
      {"teach_trips",
       {{"[328.0450, 126.0158], [323.9414, 130.1122], [324.1414, 130.1124], [328.0448, 126.2158],",
         "[328.0550, 126.0158], [323.9514, 130.1122], [324.1514, 130.1124], [328.0548, 126.2158],"},
        {"[138.1166, 43.8500], [142.0200, 39.9534], [142.2200, 39.9536], [138.1164, 44.0500],",
         "[138.1266, 43.8500], [142.0300, 39.9534], [142.2300, 39.9536], [138.1264, 44.0500],"}},
       {}},
      {"estimator", {{"estimator = \"rigid\"", "estimator = \"rigid-scale\""}}, {}},
      {"max_shift", {{"max_shift_mm = 2 ", "max_shift_mm = 1.5 "}}, {}},
      {"max_rotation", {{"max_rotation_deg = 0.5", "max_rotation_deg = 0.4"}}, {}},
      {"trip_window", {{"trip_window_mm = 4.5", "trip_window_mm = 4.2"}}, {}},
      {"length_tolerance", {{"length_tolerance_mm = 0.1", "length_tolerance_mm = 0.05"}}, {}},
      {"squareness", {{"squareness_deg = 0.2", "squareness_deg = 0.1"}}, {}},
      {"line_residual", {{"max_line_residual_mm = 0.07", "max_line_residual_mm = 0.05"}}, {}},
      {"scan_speeds", {{"scan_speed_mm_s = 40", "scan_speed_mm_s = 30"}, {"latch_speed_mm_s = 8", "latch_speed_mm_s = 6"}}, {}},
      {"robot_speed", {{"xy_speed_mm_s = 800", "xy_speed_mm_s = 700"}}, {}},
      {"layer1_x", {}, TableShift{"placing-table.csv", 'x', 0.012}},
      {"layer1_y", {}, TableShift{"placing-table.csv", 'y', 0.012}},
      {"layer2_x", {}, TableShift{"layer2-table.csv", 'x', 0.012}},
      {"layer3_y", {}, TableShift{"layer3-table.csv", 'y', -0.012}},
      {"feeders_x", {}, TableShift{"feeders-table.csv", 'x', 0.012}},
      {"marker1_x", {}, TableShift{"marker1-table.csv", 'x', 0.012}},
      {"marker2_y", {}, TableShift{"marker2-table.csv", 'y', 0.012}},
      {"feeder", {{"pick = [160, 10, -12, 0]", "pick = [161, 10, -12, 0]"}}, {}},
      {"pallet", {{"pallet = { last = [240, 10, -11.5, 0]", "pallet = { last = [241, 10, -11.5, 0]"}}, {}},
      {"place_z", {{"place_z_mm = -3 ", "place_z_mm = -2.9 "}}, {}},
  };
  return entries;
}

std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

// The example's cell and tables copied into `dir`, changed by `entry`.
void WriteCell(const Entry& entry, const fs::path& dir) {
  fs::create_directories(dir);
  for (const fs::directory_entry& file : fs::directory_iterator(kExample)) {
    const std::string extension = file.path().extension().string();
    if (extension != ".csv" && extension != ".toml") continue;
    fs::copy_file(file.path(), dir / file.path().filename(), fs::copy_options::overwrite_existing);
  }
  std::string cell = test::ReadFileText(kExample / "paper.cell.toml");
  for (const auto& [from, to] : entry.edits) {
    const std::size_t at = cell.find(from);
    ASSERT_NE(at, std::string::npos) << entry.name << ": " << from;
    cell.replace(at, from.size(), to);
  }
  std::ofstream(dir / "paper.cell.toml", std::ios::binary) << cell;
  if (!entry.table) return;
  std::istringstream in(test::ReadFileText(kExample / entry.table->file));
  std::ofstream out(dir / entry.table->file, std::ios::binary);
  for (std::string line; std::getline(in, line);) {
    if (line.size() > 2 && line[0] == entry.table->axis && line[1] == ',') {
      // axis,x_mm,y_mm,error_mm[,...]
      std::vector<std::size_t> commas;
      for (std::size_t i = 0; i < line.size(); ++i) {
        if (line[i] == ',') commas.push_back(i);
      }
      const std::size_t end = commas.size() > 3 ? commas[3] : line.size();
      const double error = std::stod(line.substr(commas[2] + 1, end - commas[2] - 1));
      line = line.substr(0, commas[2] + 1) + fmt::format("{:.6f}", error + entry.table->mm) + line.substr(end);
    }
    out << line << '\n';
  }
}

// ------------------------------------------------------------------ the second model

// The machine of the second model: NEW's cell through the C runtime.
class CMachine {
 public:
  explicit CMachine(const cell::Cell& cell) : cell_(cell), data_(cell) {}
  const cell::Cell& cell() const { return cell_; }
  const CRuntimeData& data() const { return data_; }
  // F_true: through the first region whose tables' domain holds the command.
  Eigen::Vector2d Forward(const Eigen::Vector2d& command) const {
    for (int r = 0; r < data_.region_count(); ++r) {
      const smtcal_region& region = data_.regions()[r];
      if (command.x() < region.domain_x0 || command.x() > region.domain_x1 || command.y() < region.domain_y0 ||
          command.y() > region.domain_y1) {
        continue;
      }
      const double in[2] = {command.x(), command.y()};
      double out[2];
      smtcal_direct(&region, in, out);
      return {out[0], out[1]};
    }
    return command;
  }

 private:
  const cell::Cell& cell_;
  CRuntimeData data_;
};

// Turned by `deg` about the origin, then shifted: a board pose's map.
Eigen::Vector2d Place(const Eigen::Vector2d& origin, double deg, const Eigen::Vector2d& p) {
  const double a = deg * M_PI / 180;
  return origin + Eigen::Vector2d(std::cos(a) * p.x() - std::sin(a) * p.y(), std::sin(a) * p.x() + std::cos(a) * p.y());
}

// One program's controller in the second model.
class CProgram {
 public:
  CProgram(const cell::Cell& cell, const CMachine& machine) : cell_(cell), data_(cell), machine_(machine) {}

  // FIX of fixture `k` with the machine's board of its name at `pose`: the
  // trips by bisection along the program's own legs, then smtcal_scan.
  std::optional<smtcal_fix> Scan(std::size_t k, const BoardPose& pose) const {
    const cell::Fixture& own = cell_.fixtures[k];
    const cell::Fixture& board = *machine_.cell().FindFixture(own.name);
    const Eigen::Vector2d board_origin = board.origin_mm + Eigen::Vector2d(pose.shift_x_mm, pose.shift_y_mm);
    const double board_angle = board.angle_deg + pose.rotation_deg;
    std::vector<double> xy;
    std::vector<unsigned char> tripped;
    for (const ExpectedTrip& trip : ExpectedTrips(own)) {
      const std::vector<cell::Point2>& points = own.scan_paths[trip.path].points;
      const Eigen::Vector2d from = Place(own.origin_mm, own.angle_deg, points[trip.leg]);
      const Eigen::Vector2d to = Place(own.origin_mm, own.angle_deg, points[trip.leg + 1]);
      const cell::MarkerEdge& edge = board.edges[static_cast<std::size_t>(trip.edge)];
      const Eigen::Vector2d a = Place(board_origin, board_angle, edge.from);
      const Eigen::Vector2d b = Place(board_origin, board_angle, edge.to);
      const Eigen::Vector2d normal(a.y() - b.y(), b.x() - a.x());
      const auto side = [&](double t) { return normal.dot(machine_.Forward(from + t * (to - from)) - a); };
      // The crossing: a sign change on a fine walk along the leg, then bisection.
      std::optional<double> found;
      constexpr int kSteps = 400;
      double t0 = 0, s0 = side(0);
      for (int i = 1; i <= kSteps && !found; ++i) {
        const double t1 = static_cast<double>(i) / kSteps, s1 = side(t1);
        if (s0 == 0) found = t0;
        if (!found && (s0 < 0) != (s1 < 0)) {
          double lo = t0, hi = t1;
          for (int step = 0; step < 80; ++step) {
            const double mid = 0.5 * (lo + hi);
            ((side(mid) < 0) == (s0 < 0) ? lo : hi) = mid;
          }
          found = 0.5 * (lo + hi);
        }
        t0 = t1;
        s0 = s1;
      }
      const Eigen::Vector2d at = found ? Eigen::Vector2d(from + *found * (to - from)) : Eigen::Vector2d::Zero();
      xy.push_back(at.x());
      xy.push_back(at.y());
      tripped.push_back(found ? 1 : 0);
    }
    smtcal_scan_result result;
    smtcal_scan(&data_.fixtures()[k], data_.regions(), data_.region_count(), xy.data(), tripped.data(), nullptr,
                &result);
    if (!result.has_fix) return std::nullopt;
    return result.fix;
  }

  // The command of a position and where it lands; nullopt when the runtime commands nothing.
  std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>> Point(const MachineTarget& target,
                                                                   const std::optional<smtcal_fix>& fix) const {
    const double xy[2] = {target.position[0], target.position[1]};
    smtcal_corrected out;
    Eigen::Vector2d command(xy[0], xy[1]);
    if (target.kind == MachineTarget::Kind::kFixture) {
      if (!fix) return std::nullopt;
      if (smtcal_correct(&*fix, data_.regions(), data_.region_count(), xy, &out) >= SMTCAL_POINT_OUTSIDE) {
        return std::nullopt;
      }
      command = {out.command[0], out.command[1]};
    } else if (target.kind == MachineTarget::Kind::kRunTime) {
      if (smtcal_invert(data_.regions(), data_.region_count(), xy, &out) >= SMTCAL_POINT_OUTSIDE) return std::nullopt;
      command = {out.command[0], out.command[1]};
    }
    return std::pair{command, machine_.Forward(command)};
  }

 private:
  const cell::Cell& cell_;
  CRuntimeData data_;
  const CMachine& machine_;
};

// A compiled program parsed, checked and traced for its cell.
struct Traced {
  SourceManager sources;
  std::unique_ptr<Diagnostics> diags;
  ir::Program program;
  std::optional<cell::Cell> cell;
  MachineTargets targets;
};
void Trace(const fs::path& program, const fs::path& cell_path, Traced& out) {
  out.diags = std::make_unique<Diagnostics>(out.sources);
  Result<std::optional<cell::Cell>> cell = cell::LoadCell(cell_path.string(), out.sources, *out.diags);
  ASSERT_TRUE(cell && cell.value()) << cell_path;
  out.cell = std::move(*cell.value());
  Result<std::uint32_t> file = out.sources.Load(program.string());
  ASSERT_TRUE(file) << program;
  out.program = ParseProgram(file.value(), *out.diags);
  std::vector<const PassInfo*> checks;
  for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
  RunPasses(out.program, *out.diags, checks, false);
  out.targets = CompiledProgramTargets(out.program, *out.cell, *out.diags);
  ASSERT_FALSE(out.diags->has_errors()) << program;
}

// Every position's move by the second model: (NEW's line, position index)
// -> (the landing's move at the nominal pose, the worst of command and
// landing over the poses), in µm; nullopt where one program commands nothing.
struct SecondMove {
  double lands_um = 0, worst_um = 0;
  bool comparable = true;
};
std::map<std::pair<std::uint32_t, std::size_t>, SecondMove> SecondModel(const Traced& old_side, const Traced& new_side) {
  std::map<std::pair<std::uint32_t, std::size_t>, SecondMove> moves;
  const CMachine machine(*new_side.cell);
  const CProgram old_program(*old_side.cell, machine), new_program(*new_side.cell, machine);
  // The poses: the diff's (CommonPoses selects them; the second model only
  // samples the same boards).
  const MachineWorld world(*new_side.cell);
  MachineModel old_model(*old_side.cell, world), new_model(*new_side.cell, world);
  const std::vector<BoardPose> poses = CommonPoses({{&old_model, 0}, {&new_model, 0}});
  std::vector<std::optional<smtcal_fix>> old_fix, new_fix;
  for (const BoardPose& pose : poses) {
    old_fix.push_back(old_program.Scan(0, pose));
    new_fix.push_back(new_program.Scan(0, pose));
  }
  const std::vector<const ir::Stmt*> a = test::Motions(old_side.program), b = test::Motions(new_side.program);
  EXPECT_EQ(a.size(), b.size());
  for (std::size_t s = 0; s < std::min(a.size(), b.size()); ++s) {
    const std::span<const MachineTarget> pa = old_side.targets.Of(a[s]), pb = new_side.targets.Of(b[s]);
    EXPECT_EQ(pa.size(), pb.size()) << "statement at new line " << b[s]->loc.line;
    for (std::size_t i = 0; i < std::min(pa.size(), pb.size()); ++i) {
      if (!pa[i].known || !pb[i].known) continue;
      const bool board = pa[i].kind == MachineTarget::Kind::kFixture || pb[i].kind == MachineTarget::Kind::kFixture;
      SecondMove move;
      double worst = -1;
      for (std::size_t p = 0; p < (board ? poses.size() : 1); ++p) {
        if (board && !old_fix[p] && !new_fix[p]) continue;  // both refuse the board: the same on the machine
        const auto x = old_program.Point(pa[i], old_fix[p]);
        const auto y = new_program.Point(pb[i], new_fix[p]);
        if (!x && !y) continue;
        if (!x || !y) {
          move.comparable = false;
          break;
        }
        const double command = (y->first - x->first).norm() * 1000, lands = (y->second - x->second).norm() * 1000;
        if (p == 0) move.lands_um = lands;
        worst = std::max({worst, command, lands});
      }
      move.worst_um = std::max(worst, 0.0);
      moves[{b[s]->loc.line, i}] = move;
    }
  }
  return moves;
}

// ------------------------------------------------------------------ the diff

struct DiffResult {
  std::string gate;
  json summary;
  // (NEW's line, position index) -> the position's entry.
  std::map<std::pair<std::uint32_t, std::size_t>, json> positions;
  // Form-independent: (required x, y in 0.1 µm, position, of) -> worst move in µm.
  std::map<std::tuple<long, long, std::size_t, std::size_t>, double> moved;
  std::string text;
};

DiffResult RunDiff(const std::string& old_path, const std::string& new_path, const fs::path& dir) {
  DiffResult result;
  test::SmtcalRun run = test::RunSmtcal(fmt::format("diff {} {} --json", old_path, new_path), dir);
  EXPECT_TRUE(run.exit_code == 0 || run.exit_code == 1) << run.err;
  const json diff = json::parse(run.out);
  result.gate = diff["summary"]["gate"];
  result.summary = diff["summary"];
  for (const json& change : diff["changes"]) {
    for (const json& position : change["machine"]) {
      const std::size_t index = position["position"].get<std::size_t>() - 1;
      result.positions[{change["new"]["line"].get<std::uint32_t>(), index}] = position;
      if (!position["comparable"].get<bool>()) continue;
      result.moved[{std::lround(position["required"]["x_mm"].get<double>() * 1e4),
                    std::lround(position["required"]["y_mm"].get<double>() * 1e4), index,
                    position["of"].get<std::size_t>()}] = position["worst"]["d_um"].get<double>();
    }
  }
  result.text = test::RunSmtcal(fmt::format("diff {} {}", old_path, new_path), dir).out;
  return result;
}

// The moves the diff and the second model agree on to this much (µm): the
// JSON's 0.0001 µm, the inverses' 1e-9 mm, the trips' and the fits' rounding.
constexpr double kAgreeUm = 0.002;

class DiffMatrix : public testing::TestWithParam<Entry> {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / fmt::format("smtcal_diff_matrix_{}", ::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // Compiles `program` for OLD (the example cell) and the entry's cell, in
  // both forms, and checks the diffs against each other and the second model.
  // The .place diff's moved count and largest move, for the record.
  std::pair<std::size_t, double> Check(const Entry& entry, const fs::path& program, const std::string& tag) {
    const fs::path dir = dir_ / fmt::format("{}_{}", entry.name, tag);
    WriteCell(entry, dir / "cell");
    const fs::path old_cell = kExample / "paper.cell.toml", new_cell = dir / "cell" / "paper.cell.toml";
    for (const auto& [cell, out] : {std::pair{old_cell, std::string("old")}, std::pair{new_cell, std::string("new")}}) {
      for (const std::string target : {"place", "linuxcnc"}) {
        const std::string output = target == "place" ? out + ".place" : out;
        test::SmtcalRun run = test::RunSmtcal(
            fmt::format("compile {} --cell {} --target {} -o {}", Quote(program), Quote(cell), target, output), dir);
        EXPECT_EQ(run.exit_code, 0) << entry.name << " " << tag << ": " << run.err;
        if (run.exit_code != 0) return {};
      }
    }
    const DiffResult place = RunDiff("old.place", "new.place", dir);
    const DiffResult linuxcnc = RunDiff("old", "new", dir);
    // The two forms: the same verdict, counts and moves.
    EXPECT_EQ(place.gate, linuxcnc.gate) << place.text << linuxcnc.text;
    for (const char* key : {"targets_moved", "beyond_threshold", "not_comparable", "added", "removed", "changed"}) {
      EXPECT_EQ(place.summary[key], linuxcnc.summary[key]) << key << "\n" << place.text << linuxcnc.text;
    }
    EXPECT_EQ(place.moved.size(), linuxcnc.moved.size());
    for (const auto& [key, worst] : place.moved) {
      auto found = linuxcnc.moved.find(key);
      EXPECT_TRUE(found != linuxcnc.moved.end()) << "moved in the .place form only: " << std::get<0>(key) * 1e-4
                                                 << ", " << std::get<1>(key) * 1e-4;
      if (found != linuxcnc.moved.end()) {
        EXPECT_NEAR(found->second, worst, kAgreeUm);
      }
    }
    // The second model.
    Traced old_traced, new_traced;
    Trace(dir / "old.place", old_cell, old_traced);
    Trace(dir / "new.place", new_cell, new_traced);
    if (testing::Test::HasFatalFailure()) return {};
    const auto second = SecondModel(old_traced, new_traced);
    const double threshold = 10;
    std::size_t moved = 0;
    double largest = 0;
    for (const auto& [key, expected] : second) {
      const std::string where = fmt::format("{} {}: new.place:{} position {}", entry.name, tag, key.first, key.second + 1);
      auto found = place.positions.find(key);
      if (!expected.comparable) {
        EXPECT_TRUE(found != place.positions.end() && !found->second["comparable"].get<bool>()) << where;
        continue;
      }
      if (found == place.positions.end()) {
        // Not listed: nothing moved, at any pose.
        EXPECT_LT(expected.worst_um, kAgreeUm) << where << "\n" << place.text;
        continue;
      }
      const json& position = found->second;
      if (!position["comparable"].get<bool>()) {
        ADD_FAILURE() << where << ": " << position["note"];
        continue;
      }
      EXPECT_NEAR(position["lands"]["d_um"].get<double>(), expected.lands_um, kAgreeUm) << where;
      EXPECT_NEAR(position["worst"]["d_um"].get<double>(), expected.worst_um, kAgreeUm) << where;
      if (std::fabs(expected.worst_um - threshold) > kAgreeUm) {
        EXPECT_EQ(position["beyond_threshold"].get<bool>(), expected.worst_um > threshold) << where;
      }
      ++moved;
      largest = std::max(largest, position["worst"]["d_um"].get<double>());
    }
    // Every position the diff lists, the second model has.
    for (const auto& [key, position] : place.positions) {
      EXPECT_TRUE(second.contains(key) || !position["comparable"].get<bool>())
          << entry.name << " " << tag << ": new.place:" << key.first << " is not a position of the second model";
    }
    return {moved, largest};
  }

  static fs::path dir_;
};
fs::path DiffMatrix::dir_;

TEST_P(DiffMatrix, TheExample) {
  const Entry& entry = GetParam();
  const auto [moved, largest] = Check(entry, kExample / "layers.place", "example");
  std::cout << fmt::format("[matrix] {}: {} positions moved, largest {:.1f} µm\n", entry.name, moved, largest);
}

// A random program per change, with its seed.
TEST_P(DiffMatrix, RandomPrograms) {
  const Entry& entry = GetParam();
  const char* fixed = std::getenv("SMTCAL_TEST_SEED");
  std::uint64_t first = 1;
  for (char c : entry.name) first = (first * 131 + static_cast<unsigned char>(c)) % 100000;
  if (fixed != nullptr) first = std::strtoull(fixed, nullptr, 10);
  for (std::uint64_t seed = first; seed < first + 1; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
    const fs::path program = dir_ / fmt::format("gen{}.place", seed);
    std::ofstream(program, std::ios::binary) << test::RandomPlaceProgram(seed);
    Check(entry, program, fmt::format("seed{}", seed));
  }
}

INSTANTIATE_TEST_SUITE_P(Cell, DiffMatrix, testing::ValuesIn(Entries()),
                         [](const testing::TestParamInfo<Entry>& info) { return info.param.name; });

}  // namespace
}  // namespace smtcal
