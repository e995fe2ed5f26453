// The semantic diff of two checked .place programs (program_diff.h,
// docs/diff.md). Three steps, each a plain function:
//   1. describe each side: its declarations by name, its functions as
//      flattened statement sequences, every target with its static position;
//   2. match: declarations by name, functions by name, statements by Align;
//   3. compare each matched pair: canonical text (changed?) and position
//      (moved? by how much, in which frames).
#include "backend/diff/program_diff.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <variant>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/fixture_geometry.h"
#include "calibration/tolerances.h"
#include "ir/constant_fold.h"
#include "ir/ir_ops.h"
#include "ir/ir_text.h"
#include "ir/symbols.h"
#include "passes/correction/target_trace.h"

namespace smtcal::diff {

std::string_view ChangeKindName(ChangeKind kind) {
  switch (kind) {
    case ChangeKind::kMoved: return "moved";
    case ChangeKind::kChanged: return "changed";
    case ChangeKind::kAdded: return "added";
    case ChangeKind::kRemoved: return "removed";
    case ChangeKind::kReordered: return "reordered";
  }
  return "changed";
}

// ------------------------------------------------------------------ alignment

namespace {

using Similarity = std::function<double(std::size_t, std::size_t)>;

// Exact alignment of a[0..n) with b[0..m): most matches, then most similarity.
void AlignExactly(const std::vector<std::string>& a, const std::vector<std::string>& b, std::size_t a0,
                  std::size_t n, std::size_t b0, std::size_t m, const Similarity& similarity,
                  std::vector<Aligned>& out) {
  struct Cell {
    int matches = 0;
    float similarity = 0;
    bool operator<(const Cell& o) const {
      return matches != o.matches ? matches < o.matches : similarity < o.similarity;
    }
  };
  // best[i][j]: the best alignment of the suffixes a[i..n), b[j..m).
  std::vector<Cell> best((n + 1) * (m + 1));
  auto at = [&](std::size_t i, std::size_t j) -> Cell& { return best[i * (m + 1) + j]; };
  for (std::size_t i = n + 1; i-- > 0;) {
    for (std::size_t j = m + 1; j-- > 0;) {
      if (i == n || j == m) continue;
      Cell cell = std::max(at(i + 1, j), at(i, j + 1));
      if (a[a0 + i] == b[b0 + j]) {
        Cell match = at(i + 1, j + 1);
        match.matches += 1;
        match.similarity += static_cast<float>(similarity(a0 + i, b0 + j));
        cell = std::max(cell, match);
      }
      at(i, j) = cell;
    }
  }
  std::size_t i = 0, j = 0;
  while (i < n || j < m) {
    if (i < n && j < m && a[a0 + i] == b[b0 + j]) {
      Cell match = at(i + 1, j + 1);
      match.matches += 1;
      match.similarity += static_cast<float>(similarity(a0 + i, b0 + j));
      if (!(match < at(i, j))) {
        out.push_back({a0 + i++, b0 + j++});
        continue;
      }
    }
    // Removals before additions where both are as good: the report then reads
    // "removed X, added Y" like a line diff.
    if (i < n && (j == m || !(at(i + 1, j) < at(i, j)))) {
      out.push_back({a0 + i++, Aligned::npos});
    } else {
      out.push_back({Aligned::npos, b0 + j++});
    }
  }
}

// Myers' greedy O(ND) alignment, for middles too large for AlignExactly. It
// cannot weigh similarity, so elements are equal when their signatures are
// and they are at least kFallbackMinSimilarity alike (otherwise a run of
// Picks from one feeder would slide past an inserted Pick). Beyond
// kDiffMaxEditDistance edits it returns false.
constexpr double kFallbackMinSimilarity = 0.5;

bool AlignMyers(const std::vector<std::string>& a, const std::vector<std::string>& b, std::size_t a0, std::size_t n,
                std::size_t b0, std::size_t m, const Similarity& similarity, std::vector<Aligned>& out) {
  const long N = static_cast<long>(n), M = static_cast<long>(m);
  const long max_d = std::min(N + M, kDiffMaxEditDistance);
  // trace[d] holds V[k] for k = -d..d (index k + d) after step d.
  std::vector<std::vector<long>> trace;
  std::vector<long> v(1, 0);  // step "-1": V[1] = 0, stored as the d = 0 predecessor
  auto equal = [&](long x, long y) {
    return a[a0 + x] == b[b0 + y] && similarity(a0 + x, b0 + y) >= kFallbackMinSimilarity;
  };
  long found = -1;
  for (long d = 0; d <= max_d && found < 0; ++d) {
    std::vector<long> next(2 * d + 1);
    for (long k = -d; k <= d; k += 2) {
      auto prev = [&](long kk) { return v[kk + (d - 1)]; };  // V of step d - 1
      long x;
      if (d == 0) {
        x = 0;
      } else if (k == -d || (k != d && prev(k - 1) < prev(k + 1))) {
        x = prev(k + 1);
      } else {
        x = prev(k - 1) + 1;
      }
      long y = x - k;
      while (x < N && y < M && equal(x, y)) ++x, ++y;
      next[k + d] = x;
      if (x >= N && y >= M) found = d;
    }
    trace.push_back(next);
    v = std::move(next);
  }
  if (found < 0) return false;
  // Walk back from (N, M), collecting the path in reverse.
  std::vector<Aligned> reversed;
  long x = N, y = M;
  for (long d = found; d >= 0; --d) {
    long k = x - y;
    long prev_k = 0, prev_x = 0;
    if (d > 0) {
      const std::vector<long>& pv = trace[d - 1];
      auto prev = [&](long kk) { return pv[kk + (d - 1)]; };
      prev_k = (k == -d || (k != d && prev(k - 1) < prev(k + 1))) ? k + 1 : k - 1;
      prev_x = prev(prev_k);
    }
    long prev_y = prev_x - prev_k;
    long start_x = d > 0 ? (prev_k == k + 1 ? prev_x : prev_x + 1) : 0;
    while (x > start_x) reversed.push_back({a0 + static_cast<std::size_t>(--x), b0 + static_cast<std::size_t>(--y)});
    if (d > 0) {
      if (prev_k == k + 1) {
        reversed.push_back({Aligned::npos, b0 + static_cast<std::size_t>(--y)});  // insertion
      } else {
        reversed.push_back({a0 + static_cast<std::size_t>(--x), Aligned::npos});  // deletion
      }
      SMTCAL_CHECK(x == prev_x && y == prev_y, "Myers backtrack lost its path");
    }
  }
  out.insert(out.end(), reversed.rbegin(), reversed.rend());
  return true;
}

}  // namespace

std::vector<Aligned> Align(const std::vector<std::string>& a, const std::vector<std::string>& b,
                           const Similarity& similarity) {
  std::vector<Aligned> out;
  std::size_t n = a.size(), m = b.size();
  std::size_t prefix = 0;
  while (prefix < n && prefix < m && a[prefix] == b[prefix] && similarity(prefix, prefix) == 1) ++prefix;
  std::size_t suffix = 0;
  while (suffix < n - prefix && suffix < m - prefix && a[n - 1 - suffix] == b[m - 1 - suffix] &&
         similarity(n - 1 - suffix, m - 1 - suffix) == 1) {
    ++suffix;
  }
  for (std::size_t i = 0; i < prefix; ++i) out.push_back({i, i});
  std::size_t mid_n = n - prefix - suffix, mid_m = m - prefix - suffix;
  if (static_cast<double>(mid_n + 1) * static_cast<double>(mid_m + 1) <= kDiffMaxAlignCells) {
    AlignExactly(a, b, prefix, mid_n, prefix, mid_m, similarity, out);
  } else if (!AlignMyers(a, b, prefix, mid_n, prefix, mid_m, similarity, out)) {
    for (std::size_t i = 0; i < mid_n; ++i) out.push_back({prefix + i, Aligned::npos});
    for (std::size_t j = 0; j < mid_m; ++j) out.push_back({Aligned::npos, prefix + j});
  }
  for (std::size_t s = suffix; s-- > 0;) out.push_back({n - 1 - s, m - 1 - s});
  return out;
}

// ------------------------------------------------------------------ one side

namespace {

using sema::Lowercase;

// Where a target is, as far as the program says statically.
struct Placement {
  bool known = true;          // false: a pallet slot chosen at run time
  std::string unknown_because;
  Pose4 written{};            // the constant part, in `frame`
  std::string frame;          // as declared; empty = robot base
  bool taught = false;        // robot coordinates taught on fixture `frame`
  std::string symbolic;       // offsets known only at run time ("+ X(dx)"); empty = none
  bool symbolic_xy = false;   // some of them move x or y
  // The frame chain's root: a fixture (as declared) or "" for the robot base,
  // the constant part there, and the chain's rotation (degrees).
  std::string root;
  Pose4 in_root{};
  double chain_deg = 0;
};

// One line of a flattened function body, or one top-level declaration.
struct Item {
  const ir::Stmt* stmt = nullptr;
  int branch = -1;              // an If's ElseIf/Else line (index into branches)
  std::string key;              // declarations: what they are matched by
  std::string what;             // for the report
  std::string signature;        // statements: what the alignment may match on
  std::string text;             // canonical line without comment, coordinates included
  std::optional<Placement> placement;  // targets
  bool reported = true;         // closing lines (Next, EndIf, EndCycle) only structure the alignment
};

std::string TargetKeywordOf(const ir::Stmt& stmt) {
  if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) return std::string(ir::MotionSpelling(motion->kind));
  if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) return std::string(ir::PickPlaceSpelling(pick->kind));
  return "";
}

// A point expression's identity for the alignment: the named point, or
// "xy" for a position given in place (XY(...) or a pallet slot, which compile
// turns into the XY(...) that reaches it) — never coordinates, indices or
// offsets.
std::string TargetSignature(const ir::PointExpr& point) {
  if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) return Lowercase(named->name);
  return "xy";
}

std::string VarTypeName(ir::VarType type) { return type == ir::VarType::Integer ? "Integer" : "Real"; }

// The canonical text of a statement's (or an If branch's) own line.
std::string LineText(const ir::Stmt& stmt, int branch) {
  return std::visit(
      [&](const auto& node) -> std::string {
        using Node = std::decay_t<decltype(node)>;
        if constexpr (std::is_same_v<Node, ir::Comment>) {
          return "";
        } else if constexpr (std::is_same_v<Node, ir::ProgramDecl>) {
          return "Program " + node.name;
        } else if constexpr (std::is_same_v<Node, ir::UnitsDecl>) {
          return "Units " + node.unit;
        } else if constexpr (std::is_same_v<Node, ir::FixtureDecl>) {
          return "Fixture " + node.name;
        } else if constexpr (std::is_same_v<Node, ir::LocalDecl>) {
          return "Local " + node.name + " = " + PrintCoords(node.origin) + (node.frame.empty() ? "" : " In " + node.frame);
        } else if constexpr (std::is_same_v<Node, ir::PointDecl>) {
          return std::string(node.taught ? "Taught Point " : "Point ") + node.name + " = " + PrintCoords(node.coords) +
                 (node.frame.empty() ? "" : (node.taught ? " On " : " In ") + node.frame);
        } else if constexpr (std::is_same_v<Node, ir::PalletDecl>) {
          return fmt::format("Pallet {}, {}, {}, {}, {}, {}", node.number, node.corners[0], node.corners[1],
                             node.corners[2], node.columns, node.rows);
        } else if constexpr (std::is_same_v<Node, ir::VacuumDecl>) {
          return fmt::format("Vacuum {}", node.output);
        } else if constexpr (std::is_same_v<Node, ir::VarDecl>) {
          std::string text = VarTypeName(node.type) + " ";
          for (std::size_t i = 0; i < node.names.size(); ++i) text += (i > 0 ? ", " : "") + node.names[i];
          return text;
        } else if constexpr (std::is_same_v<Node, ir::Function>) {
          return "Function " + node.name;
        } else if constexpr (std::is_same_v<Node, ir::Assign>) {
          return node.name + " = " + PrintExpr(*node.value);
        } else if constexpr (std::is_same_v<Node, ir::Motion>) {
          std::string text = std::string(ir::MotionSpelling(node.kind)) + " " + PrintPointExpr(node.target);
          if (node.limz) text += " LimZ " + PrintExpr(*node.limz);
          return text;
        } else if constexpr (std::is_same_v<Node, ir::PickPlace>) {
          std::string text = std::string(ir::PickPlaceSpelling(node.kind)) + " " + PrintPointExpr(node.target);
          if (node.vacuum) text += " Vacuum " + PrintExpr(*node.vacuum);
          if (node.limz) text += " LimZ " + PrintExpr(*node.limz);
          return text;
        } else if constexpr (std::is_same_v<Node, ir::SetOutput>) {
          return (node.on ? "On " : "Off ") + PrintExpr(*node.bit);
        } else if constexpr (std::is_same_v<Node, ir::WaitTime>) {
          return "Wait " + PrintExpr(*node.seconds);
        } else if constexpr (std::is_same_v<Node, ir::WaitSwitch>) {
          return "Wait Sw(" + PrintExpr(*node.bit) + ") = " + (node.on ? "On" : "Off");
        } else if constexpr (std::is_same_v<Node, ir::For>) {
          return "For " + node.var + " = " + PrintExpr(*node.from) + " To " + PrintExpr(*node.to) +
                 (node.step ? " Step " + PrintExpr(*node.step) : "");
        } else if constexpr (std::is_same_v<Node, ir::If>) {
          const ir::IfBranch& b = node.branches[static_cast<std::size_t>(std::max(branch, 0))];
          if (branch <= 0) return "If " + PrintExpr(*b.condition) + " Then";
          return b.condition ? "ElseIf " + PrintExpr(*b.condition) + " Then" : "Else";
        } else if constexpr (std::is_same_v<Node, ir::Call>) {
          return "Call " + node.name;
        } else if constexpr (std::is_same_v<Node, ir::Cycle>) {
          return "Cycle " + node.fixture;
        } else if constexpr (std::is_same_v<Node, ir::Scan>) {
          return "Scan " + node.fixture;
        } else {
          static_assert(std::is_same_v<Node, ir::ExitFunction>, "statement kind without a line");
          return "Exit Function";
        }
      },
      stmt.node);
}

// What the alignment may match a statement with: its kind and the names that
// make it a different action (the variable assigned, the function called,
// the target's point or pallet), never numbers that may be re-measured.
std::string Signature(const ir::Stmt& stmt, int branch) {
  return std::visit(
      [&](const auto& node) -> std::string {
        using Node = std::decay_t<decltype(node)>;
        if constexpr (std::is_same_v<Node, ir::Assign>) {
          return "assign " + Lowercase(node.name);
        } else if constexpr (std::is_same_v<Node, ir::Motion> || std::is_same_v<Node, ir::PickPlace>) {
          return Lowercase(TargetKeywordOf(stmt)) + " " + TargetSignature(node.target);
        } else if constexpr (std::is_same_v<Node, ir::SetOutput>) {
          return "output";
        } else if constexpr (std::is_same_v<Node, ir::WaitTime>) {
          return "wait";
        } else if constexpr (std::is_same_v<Node, ir::WaitSwitch>) {
          return "wait sw";
        } else if constexpr (std::is_same_v<Node, ir::For>) {
          return "for " + Lowercase(node.var);
        } else if constexpr (std::is_same_v<Node, ir::If>) {
          if (branch <= 0) return "if";
          return node.branches[static_cast<std::size_t>(branch)].condition ? "elseif" : "else";
        } else if constexpr (std::is_same_v<Node, ir::Call>) {
          return "call " + Lowercase(node.name);
        } else if constexpr (std::is_same_v<Node, ir::Cycle>) {
          return "cycle " + Lowercase(node.fixture);
        } else if constexpr (std::is_same_v<Node, ir::Scan>) {
          return "scan " + Lowercase(node.fixture);
        } else if constexpr (std::is_same_v<Node, ir::VarDecl>) {
          return "var " + Lowercase(LineText(stmt, branch));
        } else {
          return Lowercase(LineText(stmt, branch));
        }
      },
      stmt.node);
}

class SideModel {
 public:
  SideModel(const ir::Program& program) : program_(program), symbols_(sema::SymbolTable::Build(program)) {}

  const sema::SymbolTable& symbols() const { return symbols_; }

  // A point declared at `frame` in this program, through its frame chain.
  void Root(Placement& p) const {
    if (p.taught) {  // robot coordinates, taught against the fixture
      p.root = p.frame;
      p.in_root = p.written;
      p.chain_deg = 0;
      return;
    }
    RootedPose rooted = ResolveFrame(symbols_, p.frame, p.written);
    Pose4 zero{};
    RootedPose origin = ResolveFrame(symbols_, p.frame, zero);
    p.root = rooted.fixture;
    if (!p.root.empty()) p.root = symbols_.Find(p.root)->name;
    p.in_root = rooted.pose;
    p.chain_deg = origin.pose[3];
  }

  Placement OfDecl(const ir::PointDecl& decl) const {
    Placement p;
    p.written = decl.coords.values;
    p.frame = FrameSpelling(decl.frame);
    p.taught = decl.taught;
    Root(p);
    return p;
  }

  Placement OfTarget(const ir::PointExpr& target) const {
    Placement p;
    if (const auto* named = std::get_if<ir::NamedPoint>(&target.base)) {
      const sema::Symbol* symbol = symbols_.Find(*named);
      SMTCAL_CHECK(symbol != nullptr && symbol->kind == sema::SymbolKind::Point, "checked targets name points");
      p = OfDecl(std::get<ir::PointDecl>(symbol->decl->node));
    } else if (const auto* coords = std::get_if<ir::Coords>(&target.base)) {
      p.written = coords->values;
    } else {
      PalletSlot(std::get<ir::PalletPoint>(target.base), p);
    }
    for (const ir::PointOffset& offset : target.offsets) {
      std::optional<sema::Constant> amount = sema::FoldConstant(offset.amount.get());
      if (amount) {
        p.written[ir::AxisIndex(offset.axis)] += offset.negative ? -amount->value : amount->value;
      } else {
        p.symbolic += fmt::format(" {} {}({})", offset.negative ? '-' : '+', ir::AxisSpelling(offset.axis),
                                  PrintExpr(*offset.amount));
        if (offset.axis == ir::Axis::X || offset.axis == ir::Axis::Y) p.symbolic_xy = true;
      }
    }
    Root(p);
    return p;
  }

 private:
  std::string FrameSpelling(const std::string& frame) const {
    if (frame.empty()) return "";
    const sema::Symbol* symbol = symbols_.Find(frame);
    return symbol != nullptr ? symbol->name : frame;
  }

  // Pallet(n, i, j) or Pallet(n, k) with constant indices: the slot in the
  // corners' frame (docs/language.md, Pallet).
  void PalletSlot(const ir::PalletPoint& pallet, Placement& p) const {
    std::optional<int> number = sema::FoldInteger(pallet.number.get());
    std::optional<int> i = sema::FoldInteger(pallet.i.get());
    std::optional<int> j = pallet.j ? sema::FoldInteger(pallet.j.get()) : std::optional<int>(1);
    const sema::SymbolTable::PalletEntry* entry = number ? symbols_.FindPallet(*number) : nullptr;
    if (entry == nullptr || !i || !j) {
      p.known = false;
      p.unknown_because = "the pallet slot is chosen at run time";
      return;
    }
    const ir::PalletDecl& decl = *entry->pallet;
    double column = *i, row = *j;
    if (!pallet.j) {  // k counts along the first row, then the next
      column = (*i - 1) % decl.columns + 1;
      row = (*i - 1) / decl.columns + 1;
    }
    std::array<Placement, 3> corners;
    for (int c = 0; c < 3; ++c) {
      const sema::Symbol* point = symbols_.Find(decl.corners[c]);
      SMTCAL_CHECK(point != nullptr && point->kind == sema::SymbolKind::Point, "checked pallet corners");
      corners[c] = OfDecl(std::get<ir::PointDecl>(point->decl->node));
    }
    double s = decl.columns > 1 ? (column - 1) / (decl.columns - 1) : 0;
    double t = decl.rows > 1 ? (row - 1) / (decl.rows - 1) : 0;
    p = corners[0];
    for (int a = 0; a < 4; ++a) {
      p.written[a] = corners[0].written[a] + s * (corners[1].written[a] - corners[0].written[a]) +
                     t * (corners[2].written[a] - corners[0].written[a]);
    }
  }

  const ir::Program& program_;
  sema::SymbolTable symbols_;
};

// The top-level declarations of a program, keyed for matching.
std::vector<Item> Declarations(const ir::Program& program, const SideModel& model) {
  std::vector<Item> items;
  for (const ir::StmtPtr& stmt : program.items) {
    std::visit(
        [&](const auto& node) {
          using Node = std::decay_t<decltype(node)>;
          Item item;
          item.stmt = stmt.get();
          item.text = LineText(*stmt, -1);
          if constexpr (std::is_same_v<Node, ir::ProgramDecl> || std::is_same_v<Node, ir::UnitsDecl>) {
            // The name has no effect on the machine (and `smtcal import` names
            // a program after its output file) and the unit is always mm.
            return;
          } else if constexpr (std::is_same_v<Node, ir::VacuumDecl>) {
            item.key = "vacuum";
            item.what = item.text;
          } else if constexpr (std::is_same_v<Node, ir::FixtureDecl>) {
            item.key = "name " + Lowercase(node.name);
            item.what = "Fixture " + node.name;
          } else if constexpr (std::is_same_v<Node, ir::LocalDecl>) {
            item.key = "name " + Lowercase(node.name);
            item.what = "Local " + node.name;
            Placement p;  // a frame's origin is compared like a point
            p.written = node.origin.values;
            p.frame = node.frame.empty() ? "" : model.symbols().Find(node.frame)->name;
            model.Root(p);
            item.placement = p;
          } else if constexpr (std::is_same_v<Node, ir::PointDecl>) {
            item.key = "name " + Lowercase(node.name);
            item.what = "point " + node.name;
            item.placement = model.OfDecl(node);
          } else if constexpr (std::is_same_v<Node, ir::PalletDecl>) {
            item.key = fmt::format("pallet {}", node.number);
            item.what = fmt::format("Pallet {}", node.number);
          } else if constexpr (std::is_same_v<Node, ir::VarDecl>) {
            for (const std::string& name : node.names) {  // one item per variable
              Item var = item;
              var.key = "name " + Lowercase(name);
              var.what = "variable " + name;
              var.text = VarTypeName(node.type) + " " + name;
              items.push_back(std::move(var));
            }
            return;
          } else if constexpr (std::is_same_v<Node, ir::Function>) {
            item.key = "name " + Lowercase(node.name);
            item.what = "Function " + node.name;
          } else {
            return;  // comments; statements never stand at the top level of a checked program
          }
          items.push_back(std::move(item));
        },
        stmt->node);
  }
  return items;
}

// A function body as the sequence of its lines, blocks opened and closed.
void Flatten(const ir::Block& block, const SideModel& model, std::vector<Item>& items) {
  auto closer = [&](const ir::Stmt& stmt, const std::string& keyword) {
    Item item;
    item.stmt = &stmt;
    item.signature = item.text = keyword;
    item.reported = false;
    items.push_back(std::move(item));
  };
  for (const ir::StmtPtr& stmt : block) {
    if (std::holds_alternative<ir::Comment>(stmt->node)) continue;
    Item item;
    item.stmt = stmt.get();
    item.signature = Signature(*stmt, -1);
    item.text = LineText(*stmt, -1);
    item.what = item.text;
    if (const auto* motion = std::get_if<ir::Motion>(&stmt->node)) item.placement = model.OfTarget(motion->target);
    if (const auto* pick = std::get_if<ir::PickPlace>(&stmt->node)) item.placement = model.OfTarget(pick->target);
    items.push_back(std::move(item));
    if (const auto* loop = std::get_if<ir::For>(&stmt->node)) {
      Flatten(loop->body, model, items);
      closer(*stmt, "Next");
    } else if (const auto* cycle = std::get_if<ir::Cycle>(&stmt->node)) {
      Flatten(cycle->body, model, items);
      closer(*stmt, "EndCycle");
    } else if (const auto* branch = std::get_if<ir::If>(&stmt->node)) {
      for (std::size_t b = 0; b < branch->branches.size(); ++b) {
        if (b > 0) {
          Item line;
          line.stmt = stmt.get();
          line.branch = static_cast<int>(b);
          line.signature = Signature(*stmt, line.branch);
          line.text = line.what = LineText(*stmt, line.branch);
          items.push_back(std::move(line));
        }
        Flatten(branch->branches[b].body, model, items);
      }
      closer(*stmt, "EndIf");
    }
  }
}

SourceLoc ItemLoc(const Item& item) {
  if (item.branch > 0) return std::get<ir::If>(item.stmt->node).branches[item.branch].loc;
  return item.stmt->loc;
}

// ------------------------------------------------------------------ comparing

constexpr double kUmPerMm = 1000;

}  // namespace

Displacement DisplacementBetween(const std::string& frame, const Pose4& a, const Pose4& b) {
  Displacement d;
  d.frame = frame;
  d.dx_um = (b[0] - a[0]) * kUmPerMm;
  d.dy_um = (b[1] - a[1]) * kUmPerMm;
  d.dz_um = (b[2] - a[2]) * kUmPerMm;
  d.du_deg = b[3] - a[3];
  d.d_um = std::hypot(d.dx_um, d.dy_um);
  d.direction_deg = d.d_um > 0 ? std::atan2(d.dy_um, d.dx_um) * kDegPerRad : 0;
  return d;
}

bool IsZero(const Displacement& d) {
  return std::hypot(d.d_um, d.dz_um) <= kDiffSamePositionMm * kUmPerMm && std::fabs(d.du_deg) <= kDiffSameAngleDeg;
}

namespace {

Displacement Between(const std::string& frame, const Pose4& a, const Pose4& b) {
  return DisplacementBetween(frame, a, b);
}
bool Zero(const Displacement& d) { return IsZero(d); }

std::string FrameLabel(const std::string& frame, bool taught) {
  if (taught && !frame.empty()) return "robot base, taught on " + frame;
  return frame.empty() ? "robot base" : frame;
}

class Comparer {
 public:
  explicit Comparer(const DiffOptions& options) : options_(options) {}

  // The root-frame pose mapped to the robot base through the fixture's nominal
  // pose, when the cell gives it.
  std::optional<Pose4> InBase(const Placement& p) const {
    if (p.root.empty() || p.taught) return p.in_root;
    const cell::Fixture* fixture = FixtureInCell(p.root);
    if (fixture == nullptr) return std::nullopt;
    Eigen::Vector2d base = ToBase(NominalFix(*fixture), {p.in_root[0], p.in_root[1]});
    return Pose4{base.x(), base.y(), p.in_root[2], p.in_root[3] + fixture->angle_deg};
  }

  // "robot base, Board at its nominal pose": the fixture(s) the numbers went through.
  static std::string BaseLabel(const Placement& a, const Placement& b) {
    std::string fixtures = b.root.empty() ? a.root : b.root;
    if (!a.root.empty() && !b.root.empty() && !sema::SameName(a.root, b.root)) fixtures = a.root + " and " + b.root;
    return "robot base, " + fixtures + " at " + (a.root.empty() || b.root.empty() || sema::SameName(a.root, b.root)
                                                     ? "its nominal pose"
                                                     : "their nominal poses");
  }

  // Fills change.moves, note and the plot positions. Returns false when the
  // positions cannot be compared.
  bool Compare(const Placement& a, const Placement& b, Change& change) const {
    if (!a.known || !b.known) {
      change.note = !a.known ? a.unknown_because : b.unknown_because;
      return false;
    }
    if (a.symbolic != b.symbolic) {
      change.note = "the run-time offsets differ";
      return false;
    }
    const bool same_frame = sema::SameName(a.frame, b.frame) && a.taught == b.taught;
    if (same_frame) change.moves.push_back(Between(FrameLabel(b.frame, b.taught), a.written, b.written));
    // With X/Y offsets known only at run time, a frame chain that turned
    // moves each run's target differently: only the written frame is exact.
    const bool chains_agree = !a.symbolic_xy || std::fabs(a.chain_deg - b.chain_deg) <= kDiffSameAngleDeg;
    const bool same_root = sema::SameName(a.root, b.root) && a.taught == b.taught;
    if (!a.taught && same_root && chains_agree && (!same_frame || !sema::SameName(b.frame, b.root))) {
      change.moves.push_back(Between(FrameLabel(b.root, false), a.in_root, b.in_root));
    }
    std::optional<Pose4> base_a = InBase(a), base_b = InBase(b);
    // Through a fixture's nominal pose: adds nothing when both chains end in the base.
    if (base_a && base_b && chains_agree && !a.taught && !b.taught && (!a.root.empty() || !b.root.empty())) {
      change.moves.push_back(Between(BaseLabel(a, b), *base_a, *base_b));
    }
    if (!same_frame) {
      change.note = fmt::format("frame {} -> {}", FrameLabel(a.frame, a.taught), FrameLabel(b.frame, b.taught));
    }
    if (a.symbolic.empty()) {
      change.plot_frame = PlotFrame(b);
      if (PlotFrame(a) == change.plot_frame) {
        change.old_plot = PlotPose(a);
        change.new_plot = PlotPose(b);
      }
    }
    return !change.moves.empty();
  }

  std::string PlotFrame(const Placement& p) const {
    if (p.taught || p.root.empty()) return "robot base";
    return InBase(p) ? "robot base" : p.root;
  }
  Pose4 PlotPose(const Placement& p) const {
    std::optional<Pose4> base = InBase(p);
    return base ? *base : p.in_root;
  }

 private:
  const cell::Fixture* FixtureInCell(const std::string& name) const {
    if (options_.cell == nullptr) return nullptr;
    for (const cell::Fixture& fixture : options_.cell->fixtures) {
      if (sema::SameName(fixture.name, name)) return &fixture;
    }
    return nullptr;
  }

  const DiffOptions& options_;
};

// ------------------------------------------------------------------ building

// Targets this close are alike enough for the large-function alignment to
// match them (a re-measured table moves commands by micrometres; parts on a
// board are rarely closer than this to each other).
constexpr double kAlikeMm = 0.2;

class Differ {
 public:
  Differ(const ir::Program& old_program, const ir::Program& new_program, const DiffOptions& options,
         Diagnostics& diags)
      : old_(old_program),
        new_(new_program),
        options_(options),
        diags_(diags),
        old_model_(old_program),
        new_model_(new_program),
        comparer_(options) {}

  ProgramDiff Run() {
    diff_.threshold_um = options_.threshold_um;
    const SourceManager& sources = diags_.sources();
    diff_.old_file = sources.File(old_.file).name;
    diff_.new_file = sources.File(new_.file).name;
    std::vector<Item> old_decls = Declarations(old_, old_model_);
    std::vector<Item> new_decls = Declarations(new_, new_model_);
    CheckComparable(old_decls, new_decls);
    if (diags_.has_errors()) return std::move(diff_);
    // Without fixtures every frame chain ends in the robot base.
    diff_.base_frame_known = options_.cell != nullptr ||
                             (FindDecl<ir::FixtureDecl>(old_) == nullptr && FindDecl<ir::FixtureDecl>(new_) == nullptr);
    MatchDeclarations(old_decls, new_decls);
    Summarize(diff_);
    return std::move(diff_);
  }

 private:
  // ---------------------------------------------------------------- checks

  void CheckComparable(const std::vector<Item>& old_decls, const std::vector<Item>& new_decls) {
    std::map<std::string, const Item*> old_by_key;
    for (const Item& item : old_decls) old_by_key.emplace(item.key, &item);
    bool shared = false;
    for (const Item& item : new_decls) {
      // Every program has a Function Main; sharing only that proves nothing.
      if (item.key.rfind("name ", 0) == 0 && item.key != "name main" && old_by_key.contains(item.key)) shared = true;
    }
    const ir::Stmt* new_program_line = FindDecl<ir::ProgramDecl>(new_);
    const ir::Stmt* old_program_line = FindDecl<ir::ProgramDecl>(old_);
    // Two versions of one program keep its name, even when they declare nothing else.
    if (old_program_line != nullptr && new_program_line != nullptr &&
        sema::SameName(std::get<ir::ProgramDecl>(old_program_line->node).name,
                       std::get<ir::ProgramDecl>(new_program_line->node).name)) {
      shared = true;
    }
    SourceRange at = new_program_line != nullptr ? SourceRange(std::get<ir::ProgramDecl>(new_program_line->node).name_loc,
                                                              NameLength(new_program_line))
                                                : SourceRange(SourceLoc{new_.file, 1, 1});
    if (!shared) {
      diags_.Report(DiagKind::DiffNothingInCommon, at, diff_.new_file, diff_.old_file);
      return;
    }
    if (IsCompiled(old_) != IsCompiled(new_)) {
      const ir::Program& source = IsCompiled(old_) ? new_ : old_;
      const ir::Stmt* line = FindDecl<ir::ProgramDecl>(source);
      SourceRange where = line != nullptr ? SourceRange(line->loc, 7) : SourceRange(SourceLoc{source.file, 1, 1});
      const std::string& compiled_name = IsCompiled(old_) ? diff_.old_file : diff_.new_file;
      diags_.Report(DiagKind::DiffCompiledWithSource, where, diags_.sources().File(source.file).name, compiled_name);
    }
    for (const ir::Program* program : {&old_, &new_}) {
      const cell::Cell* cell = program == &old_ && options_.old_cell != nullptr ? options_.old_cell : options_.cell;
      if (cell == nullptr) continue;
      std::vector<std::string> cell_names;
      for (const cell::Fixture& fixture : cell->fixtures) cell_names.push_back(fixture.name);
      for (const ir::StmtPtr& stmt : program->items) {
        const auto* fixture = std::get_if<ir::FixtureDecl>(&stmt->node);
        if (fixture == nullptr) continue;
        bool found = std::any_of(cell_names.begin(), cell_names.end(),
                                 [&](const std::string& n) { return sema::SameName(n, fixture->name); });
        if (found) continue;
        std::string suggestion = ClosestName(fixture->name, cell_names);
        diags_.Report(DiagKind::DiffFixtureNotInCell, sema::NameAt(fixture->name_loc, fixture->name), fixture->name,
                      cell->path, suggestion.empty() ? "" : fmt::format(" (did you mean '{}'?)", suggestion));
      }
    }
  }

  static std::uint32_t NameLength(const ir::Stmt* program_line) {
    return static_cast<std::uint32_t>(std::get<ir::ProgramDecl>(program_line->node).name.size());
  }

  template <typename Node>
  static const ir::Stmt* FindDecl(const ir::Program& program) {
    for (const ir::StmtPtr& stmt : program.items) {
      if (std::holds_alternative<Node>(stmt->node)) return stmt.get();
    }
    return nullptr;
  }

  // `smtcal compile --target place` output opens with this comment.
  static bool IsCompiled(const ir::Program& program) { return ir::CorrectedHeader(program) != nullptr; }

  // ---------------------------------------------------------------- declarations

  void MatchDeclarations(const std::vector<Item>& old_decls, const std::vector<Item>& new_decls) {
    std::map<std::string, const Item*> old_by_key;
    for (const Item& item : old_decls) old_by_key.emplace(item.key, &item);
    std::map<std::string, const Item*> new_by_key;
    for (const Item& item : new_decls) new_by_key.emplace(item.key, &item);
    std::vector<std::pair<const Item*, const Item*>> functions;
    for (const Item& item : new_decls) {
      auto it = old_by_key.find(item.key);
      const Item* old_item = it != old_by_key.end() ? it->second : nullptr;
      // A name that is now something else (a point that became a Local) is
      // one removed and one added declaration.
      if (old_item != nullptr && old_item->stmt->node.index() != item.stmt->node.index()) old_item = nullptr;
      if (std::holds_alternative<ir::Function>(item.stmt->node)) {
        functions.emplace_back(old_item, &item);
        continue;
      }
      if (old_item == nullptr) {
        Added(item, "");
      } else {
        ComparePair(*old_item, item, "");
      }
    }
    for (const Item& item : old_decls) {
      auto it = new_by_key.find(item.key);
      if (it == new_by_key.end() || it->second->stmt->node.index() != item.stmt->node.index()) {
        if (std::holds_alternative<ir::Function>(item.stmt->node)) {
          functions.emplace_back(&item, nullptr);
        } else {
          Removed(item, "");
        }
      }
    }
    for (const auto& [old_item, new_item] : functions) MatchFunction(old_item, new_item);
  }

  // ---------------------------------------------------------------- functions

  void MatchFunction(const Item* old_item, const Item* new_item) {
    if (old_item == nullptr || new_item == nullptr) {  // the whole function; its targets count once each
      const Item& item = old_item != nullptr ? *old_item : *new_item;
      const SideModel& model = old_item != nullptr ? old_model_ : new_model_;
      std::vector<Item> body;
      Flatten(std::get<ir::Function>(item.stmt->node).body, model, body);
      std::size_t targets = std::count_if(body.begin(), body.end(), [](const Item& i) { return i.placement.has_value(); });
      std::string detail = fmt::format("{} statements, {} targets",
                                       std::count_if(body.begin(), body.end(), [](const Item& i) { return i.reported; }),
                                       targets);
      old_item != nullptr ? Removed(item, "", detail) : Added(item, "", detail);
      return;
    }
    const std::string& name = std::get<ir::Function>(new_item->stmt->node).name;
    std::vector<Item> a, b;
    Flatten(std::get<ir::Function>(old_item->stmt->node).body, old_model_, a);
    Flatten(std::get<ir::Function>(new_item->stmt->node).body, new_model_, b);
    std::vector<std::string> sig_a, sig_b;
    for (const Item& item : a) sig_a.push_back(item.signature);
    for (const Item& item : b) sig_b.push_back(item.signature);
    auto similarity = [&](std::size_t i, std::size_t j) -> double {
      if (a[i].text == b[j].text) return 1;
      if (!a[i].placement || !b[j].placement) return 0.5;
      // Nearer targets are likelier the same step: 0.9 for a micrometre, 0.5
      // at kAlikeMm (Align's fallback matches no farther), 0.15 at 1 mm.
      const Pose4& p = a[i].placement->written;
      const Pose4& q = b[j].placement->written;
      return 0.9 / (1 + std::hypot(p[0] - q[0], p[1] - q[1]) / (1.25 * kAlikeMm));
    };
    const std::vector<Aligned> aligned = Align(sig_a, sig_b, similarity);
    // A statement only OLD has at one place and only NEW at another, the same
    // line both times, moved in the sequence: reordered (each pairs the first
    // of its kind not yet paired, in order).
    std::map<std::size_t, std::size_t> moved_from;  // NEW's index -> OLD's
    std::set<std::size_t> moved_away;               // OLD's indices paired
    {
      std::multimap<std::string, std::size_t> removed;
      for (const Aligned& pair : aligned) {
        if (pair.new_index == Aligned::npos && a[pair.old_index].reported && !IsBlockLine(a[pair.old_index])) {
          removed.emplace(a[pair.old_index].text, pair.old_index);
        }
      }
      for (const Aligned& pair : aligned) {
        if (pair.old_index != Aligned::npos || !b[pair.new_index].reported || IsBlockLine(b[pair.new_index])) continue;
        auto found = removed.find(b[pair.new_index].text);
        if (found == removed.end()) continue;
        moved_from[pair.new_index] = found->second;
        moved_away.insert(found->second);
        removed.erase(found);
      }
    }
    for (const Aligned& pair : aligned) {
      if (pair.old_index == Aligned::npos) {
        auto from = moved_from.find(pair.new_index);
        if (from != moved_from.end()) {
          Reordered(a[from->second], b[pair.new_index], name);
        } else if (b[pair.new_index].reported) {
          Added(b[pair.new_index], name);
        }
      } else if (pair.new_index == Aligned::npos) {
        if (a[pair.old_index].reported && !moved_away.contains(pair.old_index)) Removed(a[pair.old_index], name);
      } else if (a[pair.old_index].reported) {
        ComparePair(a[pair.old_index], b[pair.new_index], name);
      }
    }
  }

  // A line that opens or closes a block (For, If, Cycle ...): moved in the
  // sequence, it changes what the statements around it do.
  static bool IsBlockLine(const Item& item) {
    return item.branch > 0 || std::holds_alternative<ir::For>(item.stmt->node) ||
           std::holds_alternative<ir::If>(item.stmt->node) || std::holds_alternative<ir::Cycle>(item.stmt->node);
  }

  // The same line at another place of the sequence: one change; a motion is
  // compared on the machine like any matched one (its positions may move
  // there when the cells differ).
  void Reordered(const Item& a, const Item& b, const std::string& function) {
    Change change = Make(ChangeKind::kReordered, &a, &b, function);
    change.note = "the same, in another order";
    if (a.branch <= 0 && ir::MotionTarget(*a.stmt) != nullptr && ir::MotionTarget(*b.stmt) != nullptr) {
      RememberMatched(a, b, change, function);
      diff_.matched.back().change = diff_.changes.size();
      ++diff_.statements_compared;
    }
    if (a.placement && b.placement && a.placement->known && b.placement->known && a.placement->symbolic.empty()) {
      change.plot_frame = comparer_.PlotFrame(*b.placement);
      change.old_plot = comparer_.PlotPose(*a.placement);
      change.new_plot = comparer_.PlotPose(*b.placement);
    }
    diff_.changes.push_back(std::move(change));
  }

  // A matched motion statement, remembered for CompareOnMachine; its change
  // (if any) is the next one pushed.
  void RememberMatched(const Item& a, const Item& b, const Change& change, const std::string& function) {
    MatchedStatement matched;
    matched.old_stmt = a.stmt;
    matched.new_stmt = b.stmt;
    matched.old_loc = change.old_side.loc;
    matched.new_loc = change.new_side.loc;
    matched.text = b.text;
    matched.function = function;
    matched.insert_at = diff_.changes.size();
    diff_.matched.push_back(std::move(matched));
  }

  // ---------------------------------------------------------------- changes

  Change Make(ChangeKind kind, const Item* a, const Item* b, const std::string& function) {
    Change change;
    change.kind = kind;
    const Item& any = b != nullptr ? *b : *a;
    change.what = any.what;
    change.function = function;
    change.is_target = any.placement.has_value() && !std::holds_alternative<ir::LocalDecl>(any.stmt->node);
    if (a != nullptr) change.old_side = {ItemLoc(*a), a->text};
    if (b != nullptr) change.new_side = {ItemLoc(*b), b->text};
    return change;
  }

  void Added(const Item& item, const std::string& function, const std::string& note = "") {
    Change change = Make(ChangeKind::kAdded, nullptr, &item, function);
    change.note = note;
    if (item.placement && item.placement->known && item.placement->symbolic.empty()) {
      change.plot_frame = comparer_.PlotFrame(*item.placement);
      change.new_plot = comparer_.PlotPose(*item.placement);
    }
    diff_.changes.push_back(std::move(change));
  }

  void Removed(const Item& item, const std::string& function, const std::string& note = "") {
    Change change = Make(ChangeKind::kRemoved, &item, nullptr, function);
    change.note = note;
    if (item.placement && item.placement->known && item.placement->symbolic.empty()) {
      change.plot_frame = comparer_.PlotFrame(*item.placement);
      change.old_plot = comparer_.PlotPose(*item.placement);
    }
    diff_.changes.push_back(std::move(change));
  }

  // A matched pair: changed text other than coordinates -> changed; a
  // position that moved -> moved; neither -> nothing to report.
  void ComparePair(const Item& a, const Item& b, const std::string& function) {
    Change change = Make(ChangeKind::kMoved, &a, &b, function);
    bool text_changed = StripCoordinates(a) != StripCoordinates(b);
    bool moved = false;
    // A motion statement may move on the machine whatever its text says: remembered for CompareOnMachine.
    const bool motion = a.branch <= 0 && ir::MotionTarget(*a.stmt) != nullptr && ir::MotionTarget(*b.stmt) != nullptr;
    if (motion) RememberMatched(a, b, change, function);
    // Pushes the change, remembering it for the matched statement.
    auto push = [&](Change&& made) {
      if (motion) diff_.matched.back().change = diff_.changes.size();
      diff_.changes.push_back(std::move(made));
    };
    if (a.placement && b.placement) {
      if (change.is_target) ++(motion ? diff_.statements_compared : diff_.declarations_compared);
      bool comparable = comparer_.Compare(*a.placement, *b.placement, change);
      if (!comparable) {
        // Identical text in both programs around a run-time slot: nothing
        // the diff can see changed; anything else cannot be judged.
        if (a.text == b.text && change.note == a.placement->unknown_because && !text_changed) return;
        change.comparable = false;
        text_changed = true;
      } else {
        moved = std::any_of(change.moves.begin(), change.moves.end(), [](const Displacement& d) { return !Zero(d); });
        change.gate_um = change.moves.back().d_um;
        if (!change.note.empty()) text_changed = true;  // a new frame is more than a move
      }
    }
    if (!text_changed && !moved) {
      if (change.old_plot && change.is_target) {
        diff_.unchanged_plot.push_back(*change.new_plot);
        diff_.unchanged_plot_frame.push_back(change.plot_frame);
        diff_.unchanged_plot_statement.push_back(motion);
      }
      return;
    }
    change.kind = text_changed ? ChangeKind::kChanged : ChangeKind::kMoved;
    change.moved = moved;
    // A target in a new frame keeps its zero moves ("0.0 µm in Board": the
    // same place); any other unmoved change has nothing to show.
    if (!moved && change.note.empty()) change.moves.clear();
    push(std::move(change));
  }

  // The line with every XY(...) and every constant number in a target's
  // offsets and pallet indices replaced, for "changed other than by
  // coordinates". Lines without a target compare whole.
  static std::string StripCoordinates(const Item& item) {
    if (!item.placement) return Lowercase(item.text);
    const ir::PointExpr* target = ir::MotionTarget(*item.stmt);
    std::string text = Lowercase(item.text);
    if (target == nullptr) {  // a declaration: everything but its coordinates
      std::size_t open = text.find("xy(");
      std::size_t close = text.find(')', open);
      return open == std::string::npos ? text : text.substr(0, open) + "xy" + text.substr(close + 1);
    }
    // The target's own text is judged by the position; the rest of the line is not.
    std::string target_text = Lowercase(PrintPointExpr(*target));
    std::size_t at = text.find(target_text);
    std::string shape = TargetSignature(*target);
    for (const ir::PointOffset& offset : target->offsets) {
      if (!sema::FoldConstant(offset.amount.get())) shape += " " + Lowercase(PrintExpr(*offset.amount));
    }
    return at == std::string::npos ? text : text.substr(0, at) + "<" + shape + ">" + text.substr(at + target_text.size());
  }

  const ir::Program& old_;
  const ir::Program& new_;
  const DiffOptions& options_;
  Diagnostics& diags_;
  SideModel old_model_, new_model_;
  ProgramDiff diff_;
  Comparer comparer_;
};

}  // namespace

void RemapLines(ProgramDiff& diff, bool new_side, const std::vector<std::uint32_t>& map) {
  for (Change& change : diff.changes) {
    SourceLoc& loc = new_side ? change.new_side.loc : change.old_side.loc;
    if (loc.known() && loc.line >= 1 && loc.line <= map.size()) {
      loc.line = map[loc.line - 1];
      loc.column = 1;
    }
  }
}

void Summarize(ProgramDiff& diff) {
  Summary s;
  s.targets_compared = diff.declarations_compared + (diff.on_machine ? diff.positions_compared : diff.statements_compared);
  auto largest = [&](double um, std::size_t change, std::size_t position) {
    if (um <= s.largest_um) return;
    s.largest_um = um;
    s.largest = change;
    s.largest_position = position;
  };
  for (std::size_t i = 0; i < diff.changes.size(); ++i) {
    Change& change = diff.changes[i];
    switch (change.kind) {
      case ChangeKind::kAdded: ++s.added; break;
      case ChangeKind::kRemoved: ++s.removed; break;
      case ChangeKind::kChanged: ++s.changed; break;
      case ChangeKind::kReordered: ++s.reordered; break;
      case ChangeKind::kMoved: break;
    }
    if (!change.is_target) continue;
    const bool both = change.kind == ChangeKind::kMoved || change.kind == ChangeKind::kChanged ||
                      change.kind == ChangeKind::kReordered;
    if (diff.on_machine && both && !change.function.empty()) {  // a motion statement: its positions
      change.beyond_threshold = false;
      for (std::size_t p = 0; p < change.machine.size(); ++p) {
        MachineMove& move = change.machine[p];
        if (!move.comparable) {
          ++s.not_comparable;
          continue;
        }
        if (!move.moved) continue;
        ++s.targets_moved;
        move.beyond_threshold = move.worst.d_um > diff.threshold_um;
        if (move.beyond_threshold) ++s.beyond_threshold;
        change.beyond_threshold = change.beyond_threshold || move.beyond_threshold;
        largest(move.worst.d_um, i, p);
      }
      continue;
    }
    if (!change.comparable) ++s.not_comparable;
    // On the machine a point's coordinates are text: what it moves shows in
    // the positions of the statements that use it, and the gate judges those
    // (a taught point converted with a re-measured table moves in the text
    // and not on the machine).
    if (change.moved && diff.on_machine) {
      ++s.points_moved_in_text;
      change.beyond_threshold = false;
    } else if (change.moved) {
      ++s.targets_moved;
      change.beyond_threshold = change.gate_um > diff.threshold_um;
      if (change.beyond_threshold) ++s.beyond_threshold;
      largest(change.gate_um, i, 0);
    }
  }
  diff.summary = s;
}

ProgramDiff DiffPrograms(const ir::Program& old_program, const ir::Program& new_program, const DiffOptions& options,
                         Diagnostics& diags) {
  return Differ(old_program, new_program, options, diags).Run();
}

}  // namespace smtcal::diff
