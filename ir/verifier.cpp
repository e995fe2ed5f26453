#include "ir/verifier.h"

#include <array>
#include <cmath>

#include <fmt/format.h>

namespace smtcal {
namespace {

// Names of ir::Stmt's alternatives, in the variant's order.
constexpr std::array<const char*, 22> kStmtNames = {
    "Comment",   "ProgramDecl", "UnitsDecl",  "FixtureDecl", "LocalDecl", "PointDecl",
    "PalletDecl", "VacuumDecl", "VarDecl",    "Function",    "Assign",    "Motion",
    "PickPlace", "SetOutput",   "WaitTime",   "WaitSwitch",  "For",       "If",
    "Call",      "Cycle",       "Scan",       "ExitFunction"};
static_assert(kStmtNames.size() == std::variant_size_v<decltype(ir::Stmt::node)>,
              "kStmtNames must name every ir::Stmt alternative");

constexpr std::array<const char*, 6> kExprNames = {"NumberLit", "VariableRef", "OnOffLit",
                                                   "UnaryExpr", "BinaryExpr",  "SwitchRead"};
static_assert(kExprNames.size() == std::variant_size_v<decltype(ir::Expr::node)>,
              "kExprNames must name every ir::Expr alternative");

const char* StmtName(const ir::Stmt& stmt) { return kStmtNames[stmt.node.index()]; }

bool IsTopLevelOnly(const ir::Stmt& stmt) {
  return std::holds_alternative<ir::ProgramDecl>(stmt.node) ||
         std::holds_alternative<ir::UnitsDecl>(stmt.node) ||
         std::holds_alternative<ir::FixtureDecl>(stmt.node) ||
         std::holds_alternative<ir::LocalDecl>(stmt.node) ||
         std::holds_alternative<ir::PointDecl>(stmt.node) ||
         std::holds_alternative<ir::PalletDecl>(stmt.node) ||
         std::holds_alternative<ir::VacuumDecl>(stmt.node) ||
         std::holds_alternative<ir::Function>(stmt.node);
}
bool IsAllowedAtTopLevel(const ir::Stmt& stmt) {
  return IsTopLevelOnly(stmt) || std::holds_alternative<ir::Comment>(stmt.node) ||
         std::holds_alternative<ir::VarDecl>(stmt.node);
}

class Verifier {
 public:
  std::vector<VerifierIssue> issues;

  void Program(const ir::Program& program) {
    if (program.file == 0) issues.push_back({"Program", {}, "has no source file id"});
    for (const ir::StmtPtr& item : program.items) {
      if (item == nullptr) {
        issues.push_back({"Program", {}, "has a null top-level statement"});
        continue;
      }
      if (!IsAllowedAtTopLevel(*item)) {
        Issue(*item, "is a statement at top level; statements belong inside a Function");
      }
      Stmt(*item);
    }
  }

 private:
  void Issue(const char* node, SourceLoc loc, std::string problem) {
    issues.push_back({node, loc, std::move(problem)});
  }
  void Issue(const ir::Stmt& stmt, std::string problem) { Issue(StmtName(stmt), stmt.loc, std::move(problem)); }

  void Known(const char* node, SourceLoc loc, const char* what) {
    if (!loc.known()) Issue(node, loc, fmt::format("{} has no known source location", what));
  }
  void Name(const ir::Stmt& stmt, const std::string& name, const char* what) {
    if (name.empty()) Issue(stmt, fmt::format("{} is empty", what));
  }
  // A name the checks may underline: not empty, and its location known.
  void Name(const ir::Stmt& stmt, const std::string& name, SourceLoc loc, const char* what) {
    Name(stmt, name, what);
    Known(StmtName(stmt), loc, what);
  }
  void Required(const ir::Stmt& stmt, const ir::ExprPtr& expr, const char* what) {
    if (expr == nullptr) {
      Issue(stmt, fmt::format("{} is null", what));
    } else {
      Expr(*expr);
    }
  }
  void Optional(const ir::ExprPtr& expr) {
    if (expr != nullptr) Expr(*expr);
  }

  void Block(const ir::Stmt& owner, const ir::Block& block) {
    for (const ir::StmtPtr& stmt : block) {
      if (stmt == nullptr) {
        Issue(owner, "has a null statement in its block");
        continue;
      }
      if (IsTopLevelOnly(*stmt)) {
        Issue(*stmt, fmt::format("is inside the block of a {}; it may appear only at top level",
                                 StmtName(owner)));
      }
      Stmt(*stmt);
    }
  }
  void End(const ir::Stmt& owner, const ir::BlockEnd& end) {
    if (!end.loc.known()) Issue(owner, "has a block end with no known source location");
  }

  void Coords(const char* node, const ir::Coords& coords) {
    Known(node, coords.loc, "XY(...)");
    for (double value : coords.values) {
      if (!std::isfinite(value)) Issue(node, coords.loc, fmt::format("XY(...) holds a non-finite value {}", value));
    }
  }

  void Point(const ir::Stmt& stmt, const ir::PointExpr& point) {
    Known(StmtName(stmt), point.loc, "the point expression");
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      if (named->name.empty()) Issue(stmt, "names a point with an empty name");
      if (named->length == 0) Issue(stmt, "names a point with a caret length of 0");
    } else if (const auto* coords = std::get_if<ir::Coords>(&point.base)) {
      Coords(StmtName(stmt), *coords);
    } else {
      const auto& pallet = std::get<ir::PalletPoint>(point.base);
      Required(stmt, pallet.number, "the pallet number");
      Required(stmt, pallet.i, "the first pallet index");
      Optional(pallet.j);
    }
    for (const ir::PointOffset& offset : point.offsets) {
      Known(StmtName(stmt), offset.loc, "a point offset");
      Required(stmt, offset.amount, "a point offset's amount");
    }
  }

  void Expr(const ir::Expr& expr) {
    const char* node = kExprNames[expr.node.index()];
    Known(node, expr.loc, "the expression");
    if (expr.length == 0) Issue(node, expr.loc, "has a caret length of 0");
    auto operand = [&](const ir::ExprPtr& child, const char* what) {
      if (child == nullptr) {
        Issue(node, expr.loc, fmt::format("{} is null", what));
      } else {
        Expr(*child);
      }
    };
    if (const auto* number = std::get_if<ir::NumberLit>(&expr.node)) {
      if (!std::isfinite(number->value)) {
        Issue(node, expr.loc, fmt::format("holds a non-finite value {}", number->value));
      } else if (number->is_integer && std::trunc(number->value) != number->value) {
        Issue(node, expr.loc, fmt::format("is marked Integer but holds {}", number->value));
      }
    } else if (const auto* variable = std::get_if<ir::VariableRef>(&expr.node)) {
      if (variable->name.empty()) Issue(node, expr.loc, "names a variable with an empty name");
    } else if (const auto* unary = std::get_if<ir::UnaryExpr>(&expr.node)) {
      operand(unary->operand, "the operand");
    } else if (const auto* binary = std::get_if<ir::BinaryExpr>(&expr.node)) {
      operand(binary->lhs, "the left operand");
      operand(binary->rhs, "the right operand");
    } else if (const auto* sw = std::get_if<ir::SwitchRead>(&expr.node)) {
      operand(sw->bit, "the Sw() bit");
    }
  }

  void Stmt(const ir::Stmt& stmt) {
    Known(StmtName(stmt), stmt.loc, "the statement");
    if (stmt.length == 0) Issue(stmt, "has a caret length of 0");
    std::visit([&](const auto& node) { Node(stmt, node); }, stmt.node);
  }

  void Node(const ir::Stmt&, const ir::Comment&) {}
  void Node(const ir::Stmt& s, const ir::ProgramDecl& n) { Name(s, n.name, n.name_loc, "the program name"); }
  void Node(const ir::Stmt& s, const ir::UnitsDecl& n) { Name(s, n.unit, n.unit_loc, "the unit"); }
  void Node(const ir::Stmt& s, const ir::FixtureDecl& n) { Name(s, n.name, n.name_loc, "the fixture name"); }
  void Node(const ir::Stmt& s, const ir::LocalDecl& n) {
    Name(s, n.name, n.name_loc, "the Local frame name");
    Coords(StmtName(s), n.origin);
    if (!n.frame.empty()) Known(StmtName(s), n.frame_loc, "the frame name");
  }
  void Node(const ir::Stmt& s, const ir::PointDecl& n) {
    Name(s, n.name, n.name_loc, "the point name");
    Coords(StmtName(s), n.coords);
    if (!n.frame.empty()) Known(StmtName(s), n.frame_loc, "the frame name");
  }
  void Node(const ir::Stmt& s, const ir::PalletDecl& n) {
    Known(StmtName(s), n.number_loc, "the pallet number");
    for (std::size_t i = 0; i < n.corners.size(); ++i) Name(s, n.corners[i], n.corner_locs[i], "a pallet corner");
    Known(StmtName(s), n.columns_loc, "the number of columns");
    Known(StmtName(s), n.rows_loc, "the number of rows");
  }
  void Node(const ir::Stmt& s, const ir::VacuumDecl& n) { Known(StmtName(s), n.output_loc, "the vacuum output"); }
  void Node(const ir::Stmt& s, const ir::VarDecl& n) {
    if (n.names.empty()) Issue(s, "declares no names");
    if (n.names.size() != n.name_locs.size()) {
      Issue(s, fmt::format("has {} names but {} name locations", n.names.size(), n.name_locs.size()));
    }
    for (const std::string& name : n.names) Name(s, name, "a variable name");
    for (SourceLoc loc : n.name_locs) Known(StmtName(s), loc, "a variable name");
  }
  void Node(const ir::Stmt& s, const ir::Function& n) {
    Name(s, n.name, n.name_loc, "the function name");
    Block(s, n.body);
    End(s, n.end);
  }
  void Node(const ir::Stmt& s, const ir::Assign& n) {
    Name(s, n.name, "the assigned variable's name");
    Required(s, n.value, "the assigned value");
  }
  void Node(const ir::Stmt& s, const ir::Motion& n) {
    Point(s, n.target);
    Optional(n.limz);
    if (n.limz != nullptr) Known(StmtName(s), n.limz_loc, "the LimZ keyword");
  }
  void Node(const ir::Stmt& s, const ir::PickPlace& n) {
    Point(s, n.target);
    Optional(n.vacuum);
    Optional(n.limz);
  }
  void Node(const ir::Stmt& s, const ir::SetOutput& n) { Required(s, n.bit, "the output bit"); }
  void Node(const ir::Stmt& s, const ir::WaitTime& n) { Required(s, n.seconds, "the wait time"); }
  void Node(const ir::Stmt& s, const ir::WaitSwitch& n) { Required(s, n.bit, "the input bit"); }
  void Node(const ir::Stmt& s, const ir::For& n) {
    Name(s, n.var, n.var_loc, "the loop variable");
    Required(s, n.from, "the start value");
    Required(s, n.to, "the end value");
    Optional(n.step);
    Block(s, n.body);
    End(s, n.end);
    if (!n.next_var.empty()) Known(StmtName(s), n.next_var_loc, "the variable after Next");
  }
  void Node(const ir::Stmt& s, const ir::If& n) {
    if (n.branches.empty()) Issue(s, "has no branches");
    for (std::size_t i = 0; i < n.branches.size(); ++i) {
      const ir::IfBranch& branch = n.branches[i];
      Known(StmtName(s), branch.loc, "a branch");
      if (branch.condition == nullptr && (i == 0 || i + 1 != n.branches.size())) {
        Issue(s, fmt::format("branch {} has no condition; only a last Else may lack one", i + 1));
      }
      Optional(branch.condition);
      Block(s, branch.body);
    }
    End(s, n.end);
  }
  void Node(const ir::Stmt& s, const ir::Call& n) { Name(s, n.name, n.name_loc, "the called function's name"); }
  void Node(const ir::Stmt& s, const ir::Cycle& n) {
    Name(s, n.fixture, n.fixture_loc, "the cycled fixture's name");
    Block(s, n.body);
    End(s, n.end);
  }
  void Node(const ir::Stmt& s, const ir::Scan& n) { Name(s, n.fixture, n.fixture_loc, "the scanned fixture's name"); }
  void Node(const ir::Stmt&, const ir::ExitFunction&) {}
};

}  // namespace

std::vector<VerifierIssue> VerifyProgram(const ir::Program& program) {
  Verifier verifier;
  verifier.Program(program);
  return std::move(verifier.issues);
}

std::string FormatVerifierIssue(const VerifierIssue& issue, const SourceManager& sources,
                                std::uint32_t program_file) {
  std::string where;
  if (!issue.loc.known()) {
    where = "<unknown location>";
  } else if (issue.loc.file == program_file) {
    where = fmt::format("{}:{}:{}", sources.File(program_file).name, issue.loc.line, issue.loc.column);
  } else {
    where = fmt::format("<file #{}>:{}:{}", issue.loc.file, issue.loc.line, issue.loc.column);
  }
  return fmt::format("{}: {}: {}", where, issue.node, issue.problem);
}

}  // namespace smtcal
