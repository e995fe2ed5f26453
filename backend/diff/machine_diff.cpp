// The diff on the machine (CompareOnMachine in program_diff.h, docs/diff.md
// "On the machine"): every position of every matched motion statement
// through calibration/machine_model.h, OLD with OLD's cell's constants and
// NEW with NEW's, on one machine: the robot and the boards of NEW's cell (or
// OLD's), at the poses both programs' scans accept.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/fixture_geometry.h"
#include "calibration/machine_model.h"
#include "calibration/tolerances.h"
#include "ir/symbols.h"

#include "backend/diff/program_diff.h"

namespace smtcal::diff {
namespace {

// One position on one side at one pose.
struct Evaluated {
  bool ok = false;
  std::string why;
  Pose4 command{};
  Pose4 lands{};
  Eigen::Vector2d required = Eigen::Vector2d::Zero();
  int region = -1;
};

Evaluated Evaluate(const MachineModel& model, const MachineTarget& target, std::size_t pose) {
  const Eigen::Vector2d xy(target.position[0], target.position[1]);
  MachinePoint point;
  switch (target.kind) {
    case MachineTarget::Kind::kAsWritten: point = model.AsWritten(xy); break;
    case MachineTarget::Kind::kRunTime: point = model.RunTimePoint(xy); break;
    case MachineTarget::Kind::kFixture:
      point = model.FixturePoint(static_cast<std::size_t>(target.fixture), pose, xy);
      break;
  }
  Evaluated out;
  out.ok = point.ok;
  out.why = point.why;
  out.required = point.required;
  out.region = point.region;
  // z passes through; u turns with the board.
  const double u = target.position[3] + point.angle_deg;
  out.command = {point.command.x(), point.command.y(), target.position[2], u};
  out.lands = {point.lands.x(), point.lands.y(), target.position[2], u};
  return out;
}

bool SameTable(const AxisTable& a, const AxisTable& b) { return a.xs == b.xs && a.ys == b.ys && a.error_mm == b.error_mm; }

bool SameRegion(const cell::Region& a, const cell::Region& b) {
  return a.x_mm.lo == b.x_mm.lo && a.x_mm.hi == b.x_mm.hi && a.y_mm.lo == b.y_mm.lo && a.y_mm.hi == b.y_mm.hi &&
         a.outside == b.outside && SameTable(a.table[TableAxis::X], b.table[TableAxis::X]) &&
         SameTable(a.table[TableAxis::Y], b.table[TableAxis::Y]);
}

bool SameFixture(const cell::Fixture& a, const cell::Fixture& b) {
  if (!sema::SameName(a.name, b.name) || a.origin_mm != b.origin_mm || a.angle_deg != b.angle_deg ||
      a.l1_mm != b.l1_mm || a.l2_mm != b.l2_mm || a.estimator != b.estimator || a.trip_window_mm != b.trip_window_mm ||
      a.max_shift_mm != b.max_shift_mm || a.max_rotation_deg != b.max_rotation_deg ||
      a.length_tolerance_mm != b.length_tolerance_mm || a.squareness_deg != b.squareness_deg ||
      a.max_line_residual_mm != b.max_line_residual_mm || a.scan_paths.size() != b.scan_paths.size()) {
    return false;
  }
  for (std::size_t e = 0; e < a.edges.size(); ++e) {
    if (a.edges[e].from != b.edges[e].from || a.edges[e].to != b.edges[e].to) return false;
  }
  for (std::size_t p = 0; p < a.scan_paths.size(); ++p) {
    if (a.scan_paths[p].points != b.scan_paths[p].points) return false;
  }
  return true;
}

// Everything the machine model reads of the two cells is the same: a
// position the programs state alike is commanded alike.
bool SameMachineData(const cell::Cell& a, const cell::Cell& b) {
  if (&a == &b) return true;
  if (a.regions.size() != b.regions.size() || a.fixtures.size() != b.fixtures.size()) return false;
  for (std::size_t r = 0; r < a.regions.size(); ++r) {
    if (!SameRegion(a.regions[r], b.regions[r])) return false;
  }
  for (std::size_t f = 0; f < a.fixtures.size(); ++f) {
    if (!SameFixture(a.fixtures[f], b.fixtures[f])) return false;
  }
  return true;
}

// "region layer1" for every region whose tables, bounds or policy differ;
// regions only one cell has are named with the side.
std::vector<std::string> RegionsThatDiffer(const cell::Cell& old_cell, const cell::Cell& new_cell) {
  std::vector<std::string> differ;
  for (const cell::Region& region : new_cell.regions) {
    const cell::Region* old_region = old_cell.FindRegion(region.name);
    if (old_region == nullptr) {
      differ.push_back(fmt::format("region {} (only in NEW's cell)", region.name));
    } else if (!SameRegion(*old_region, region)) {
      differ.push_back(fmt::format("region {}", region.name));
    }
  }
  for (const cell::Region& region : old_cell.regions) {
    if (new_cell.FindRegion(region.name) == nullptr) {
      differ.push_back(fmt::format("region {} (only in OLD's cell)", region.name));
    }
  }
  for (const cell::Fixture& fixture : new_cell.fixtures) {
    const cell::Fixture* old_fixture = old_cell.FindFixture(fixture.name);
    if (old_fixture != nullptr && !SameFixture(*old_fixture, fixture)) differ.push_back("fixture " + fixture.name);
  }
  return differ;
}

class MachineComparer {
 public:
  MachineComparer(ProgramDiff& diff, const MachineSide& old_side, const MachineSide& new_side, bool old_is_machine)
      : diff_(diff),
        old_(old_side),
        new_(new_side),
        world_(old_is_machine ? *old_side.cell : *new_side.cell),
        old_model_(*old_side.cell, world_),
        new_model_(*new_side.cell, world_),
        same_cells_(SameMachineData(*old_side.cell, *new_side.cell)) {
    diff_.machine = old_is_machine ? "OLD" : "NEW";
  }

  void Run() {
    diff_.on_machine = true;
    diff_.old_cell = old_.described;
    diff_.new_cell = new_.described;
    diff_.tables_differ = same_cells_ ? std::vector<std::string>() : RegionsThatDiffer(*old_.cell, *new_.cell);
    // The picture's unchanged marks: positions, not statements or points.
    diff_.unchanged_plot.clear();
    diff_.unchanged_plot_frame.clear();
    diff_.unchanged_plot_statement.clear();
    std::vector<std::pair<std::size_t, Change>> inserts;
    std::vector<bool> drop(diff_.changes.size(), false);
    for (const MatchedStatement& matched : diff_.matched) {
      std::vector<MachineMove> moves;
      std::string count_note;
      Compare(matched, moves, count_note);
      const bool report = !moves.empty() || !count_note.empty();
      if (matched.change != MatchedStatement::npos) {
        Change& change = diff_.changes[matched.change];
        change.machine = std::move(moves);
        change.moved = std::any_of(change.machine.begin(), change.machine.end(),
                                   [](const MachineMove& m) { return m.moved; });
        if (!count_note.empty()) {
          change.kind = ChangeKind::kChanged;
          change.note = change.note.empty() ? count_note : change.note + "; " + count_note;
        }
        // Its text moved, but nothing on the machine did (a Local and a
        // point moved against each other, a table that makes up for it).
        if (change.kind == ChangeKind::kMoved && !report) drop[matched.change] = true;
        continue;
      }
      if (!report) continue;
      Change change;
      change.kind = count_note.empty() ? ChangeKind::kMoved : ChangeKind::kChanged;
      change.what = matched.text;
      change.function = matched.function;
      change.is_target = true;
      change.old_side = {matched.old_loc, matched.text};
      change.new_side = {matched.new_loc, matched.text};
      change.note = count_note;
      change.machine = std::move(moves);
      change.moved = std::any_of(change.machine.begin(), change.machine.end(),
                                 [](const MachineMove& m) { return m.moved; });
      inserts.emplace_back(matched.insert_at, std::move(change));
    }
    // The new changes in NEW's order among the others.
    std::vector<Change> merged;
    merged.reserve(diff_.changes.size() + inserts.size());
    std::size_t next = 0;
    for (std::size_t i = 0; i <= diff_.changes.size(); ++i) {
      while (next < inserts.size() && inserts[next].first == i) merged.push_back(std::move(inserts[next++].second));
      if (i < diff_.changes.size() && !drop[i]) merged.push_back(std::move(diff_.changes[i]));
    }
    diff_.changes = std::move(merged);
    diff_.matched.clear();  // their change indices no longer hold
    for (const auto& [board, poses] : refused_) {
      diff_.refused_poses.push_back(fmt::format("{} of {}'s poses", poses.size(), board));
    }
    Summarize(diff_);
  }

 private:
  void Compare(const MatchedStatement& matched, std::vector<MachineMove>& moves, std::string& count_note) {
    const std::span<const MachineTarget> a = old_.targets->Of(matched.old_stmt);
    const std::span<const MachineTarget> b = new_.targets->Of(matched.new_stmt);
    if (a.size() != b.size()) {
      count_note = fmt::format("it commands {} position{} on the machine, was {}", b.size(), b.size() == 1 ? "" : "s",
                               a.size());
    }
    const std::size_t count = std::max(a.size(), b.size());
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
      ++diff_.positions_compared;
      MachineMove move;
      move.index = i;
      move.count = count;
      if (ComparePosition(a[i], b[i], move)) {
        moves.push_back(std::move(move));
      } else {
        Unchanged(b[i]);
      }
    }
  }

  // Fills `move`; true when it is worth reporting (moved or not comparable).
  bool ComparePosition(const MachineTarget& a, const MachineTarget& b, MachineMove& move) {
    // Where the picture draws it when it cannot be compared: where NEW's
    // program puts it with the board at its nominal pose.
    if (b.known || a.known) {
      move.required = b.known ? NominalPlace(b, *new_.cell) : NominalPlace(a, *old_.cell);
      move.located = true;
    }
    if (!a.known || !b.known) {
      // The same unknown position under the same tables moves nothing.
      if (!a.known && !b.known && same_cells_ && a.kind == b.kind && a.fixture == b.fixture) return false;
      move.comparable = false;
      const std::string& because = !b.known ? new_.targets->UnknownBecause(b) : old_.targets->UnknownBecause(a);
      move.note = fmt::format("its position is known only at run time ({}), and {}", because,
                              same_cells_ ? "the program changed" : "the cells differ");
      return true;
    }
    if (same_cells_ && a.kind == b.kind && a.fixture == b.fixture && a.position == b.position) return false;
    // The poses: those of the board either side's position is on.
    const bool a_board = a.kind == MachineTarget::Kind::kFixture, b_board = b.kind == MachineTarget::Kind::kFixture;
    std::size_t poses = 1;
    if (a_board || b_board) {
      const std::string& a_name = a_board ? old_.cell->fixtures[static_cast<std::size_t>(a.fixture)].name : "";
      const std::string& b_name = b_board ? new_.cell->fixtures[static_cast<std::size_t>(b.fixture)].name : "";
      if (a_board && b_board && !sema::SameName(a_name, b_name)) {
        move.comparable = false;
        move.note = fmt::format("it moved from fixture {} to fixture {}", a_name, b_name);
        return true;
      }
      move.board = b_board ? b_name : a_name;
      SharePoses(move.board);
      poses = b_board ? new_model_.Poses(static_cast<std::size_t>(b.fixture)).size()
                      : old_model_.Poses(static_cast<std::size_t>(a.fixture)).size();
      diff_.poses = std::max(diff_.poses, poses);
    }
    const std::vector<BoardPose>* pose_list =
        b_board   ? &new_model_.Poses(static_cast<std::size_t>(b.fixture))
        : a_board ? &old_model_.Poses(static_cast<std::size_t>(a.fixture))
                  : nullptr;
    Evaluated old_fixed, new_fixed;  // a base position is the same at every pose
    if (!a_board) old_fixed = Evaluate(old_model_, a, 0);
    if (!b_board) new_fixed = Evaluate(new_model_, b, 0);
    double worst = -1;
    for (std::size_t p = 0; p < poses; ++p) {
      if (pose_list != nullptr) {
        // A scan that refuses the board stops the whole cycle, base targets
        // and all: both refusing is the same on the machine; one refusing is
        // a difference whatever the target.
        std::string old_why, new_why;
        const bool old_refused = Refuses(old_model_, move.board, p, old_why);
        const bool new_refused = Refuses(new_model_, move.board, p, new_why);
        if (old_refused && new_refused) {
          refused_[move.board].insert(p);
          continue;
        }
        if (old_refused || new_refused) {
          move.comparable = false;
          move.note = fmt::format("with {} {} {}'s scan refuses the board ({}) and {}'s does not", move.board,
                                  AtPose((*pose_list)[p]), old_refused ? "OLD" : "NEW", old_refused ? old_why : new_why,
                                  old_refused ? "NEW" : "OLD");
          return true;
        }
      }
      const Evaluated old_at = a_board ? Evaluate(old_model_, a, p) : old_fixed;
      const Evaluated new_at = b_board ? Evaluate(new_model_, b, p) : new_fixed;
      // Both controllers refuse the point at this pose: the same on the
      // machine, nothing to compare there.
      if (!old_at.ok && !new_at.ok) continue;
      if (!old_at.ok || !new_at.ok) {
        move.comparable = false;
        const std::string where =
            pose_list != nullptr ? fmt::format(" with {} {}", move.board, AtPose((*pose_list)[p])) : "";
        move.note = !old_at.ok ? fmt::format("OLD commands nothing{}: {}", where, old_at.why)
                               : fmt::format("NEW commands nothing{}: {}", where, new_at.why);
        return true;
      }
      const Displacement command = DisplacementBetween("robot base", old_at.command, new_at.command);
      const Displacement lands = DisplacementBetween("robot base", old_at.lands, new_at.lands);
      if (p == 0) {
        move.command = command;
        move.lands = lands;
        move.required = {new_at.required.x(), new_at.required.y(), b.position[2], b.position[3]};
        move.region = new_at.region >= 0 ? new_.cell->regions[static_cast<std::size_t>(new_at.region)].name : "";
      }
      move.moved = move.moved || !IsZero(command) || !IsZero(lands);
      const Displacement& larger = lands.d_um > command.d_um ? lands : command;
      if (larger.d_um > worst) {
        worst = larger.d_um;
        move.worst = larger;
        move.worst_pose = pose_list != nullptr ? DescribeBoardPose((*pose_list)[p]) : "";
      }
    }
    if (worst < 0) {  // refused at every pose by both
      move.comparable = false;
      move.note = "neither program commands it at any pose evaluated";
      return true;
    }
    return move.moved;
  }

  // The poses of `board`, the same for both programs (CommonPoses), set once;
  // and where their scans accept different boards, what they accept.
  void SharePoses(const std::string& board) {
    if (!shared_.insert(sema::Lowercase(board)).second) return;
    std::vector<std::pair<MachineModel*, std::size_t>> models;
    std::vector<std::pair<const MachineModel*, std::size_t>> scanners;
    for (MachineModel* model : {&old_model_, &new_model_}) {
      if (const cell::Fixture* fixture = model->side().FindFixture(board)) {
        models.emplace_back(model, static_cast<std::size_t>(fixture - model->side().fixtures.data()));
        scanners.emplace_back(models.back());
      }
    }
    const std::vector<BoardPose> poses = CommonPoses(scanners);
    for (const auto& [model, fixture] : models) model->SetPoses(fixture, poses);
    if (scanners.size() == 2 && !same_cells_) DescribeAcceptance(board, scanners);
  }

  // "Board: OLD's scan accepts ... NEW's ..." where the two scans accept the
  // board out to other poses (beyond the bisection's 1/1024).
  void DescribeAcceptance(const std::string& board,
                          const std::vector<std::pair<const MachineModel*, std::size_t>>& scanners) {
    double shift = 0, rotation = 0;
    for (const auto& [model, fixture] : scanners) {
      shift = std::max(shift, model->side().fixtures[fixture].max_shift_mm);
      rotation = std::max(rotation, model->side().fixtures[fixture].max_rotation_deg);
    }
    const std::vector<BoardPose> limits = CheckLimitPoses(shift, rotation);
    const std::vector<double> a = AcceptedFractions(*scanners[0].first, scanners[0].second, limits);
    const std::vector<double> b = AcceptedFractions(*scanners[1].first, scanners[1].second, limits);
    std::size_t differ = 0, widest = 0;
    double widest_gap = 0;
    for (std::size_t p = 0; p < limits.size(); ++p) {
      const double gap = std::fabs(a[p] - b[p]);
      if (gap <= 1.5 / 1024) continue;
      ++differ;
      if (gap > widest_gap) {
        widest_gap = gap;
        widest = p;
      }
    }
    if (differ == 0) return;
    diff_.acceptance.push_back(fmt::format(
        "{}: the scans accept other boards in {} of {} directions (the most toward {}: OLD's out to {}, NEW's to "
        "{}); only poses both accept are compared",
        board, differ, limits.size(), DescribeBoardPose(limits[widest]),
        a[widest] == 0 ? "none" : DescribeBoardPose(ScaledPose(limits[widest], a[widest])),
        b[widest] == 0 ? "none" : DescribeBoardPose(ScaledPose(limits[widest], b[widest]))));
  }

  // "at its nominal pose", "shifted 1.980 mm toward 0°": after "with Board".
  static std::string AtPose(const BoardPose& pose) {
    return pose.nominal() ? std::string("at its nominal pose") : DescribeBoardPose(pose);
  }

  // Whether `model`'s controller refuses the scan of `board` at pose `p`
  // (false when its cell has no such fixture: its program scans none).
  static bool Refuses(const MachineModel& model, const std::string& board, std::size_t p, std::string& why) {
    const cell::Fixture* fixture = model.side().FindFixture(board);
    if (fixture == nullptr) return false;
    const auto index = static_cast<std::size_t>(fixture - model.side().fixtures.data());
    return !model.ScanFix(index, p, &why).has_value();
  }

  // A position in the base frame with its board at the nominal pose `cell` gives it.
  static Pose4 NominalPlace(const MachineTarget& target, const cell::Cell& cell) {
    Pose4 at = target.position;
    if (target.kind == MachineTarget::Kind::kFixture) {
      const cell::Fixture& fixture = cell.fixtures[static_cast<std::size_t>(target.fixture)];
      const Eigen::Vector2d base = ToBase(NominalFix(fixture), {at[0], at[1]});
      at = {base.x(), base.y(), at[2], at[3] + fixture.angle_deg};
    }
    return at;
  }

  // An unmoved position in the picture: where NEW wants it at the nominal pose.
  void Unchanged(const MachineTarget& target) {
    if (!target.known) return;
    diff_.unchanged_plot.push_back(NominalPlace(target, *new_.cell));
    diff_.unchanged_plot_frame.push_back("robot base");
    diff_.unchanged_plot_statement.push_back(true);
  }

  std::map<std::string, std::set<std::size_t>> refused_;  // per board: the poses both programs' scans refuse
  std::set<std::string> shared_;                          // boards whose poses are set (lowercase)
  ProgramDiff& diff_;
  const MachineSide& old_;
  const MachineSide& new_;
  MachineWorld world_;
  MachineModel old_model_;
  MachineModel new_model_;
  bool same_cells_;
};

}  // namespace

void CompareOnMachine(ProgramDiff& diff, const MachineSide& old_side, const MachineSide& new_side,
                      bool old_is_machine) {
  SMTCAL_CHECK(old_side.cell != nullptr && new_side.cell != nullptr && old_side.targets != nullptr &&
                   new_side.targets != nullptr,
               "both sides of the machine comparison have a cell and targets");
  MachineComparer(diff, old_side, new_side, old_is_machine).Run();
}

}  // namespace smtcal::diff
