#include "backend/place/place_printer.h"

#include <string_view>
#include <type_traits>

#include <fmt/format.h>

#include "base/check.h"
#include "ir/ir_ops.h"
#include "ir/symbols.h"

namespace smtcal {

namespace {

class Printer {
 public:
  explicit Printer(TextOutput& out) : output_(out), out_(out.buffer()) {}
  void Print(const ir::Program& program) { PrintBlock(program.items, 0); }

 private:
  // One output line: indentation, text, and the comment written on it.
  void Line(int depth, std::string_view text, std::string_view comment) {
    out_.append(static_cast<std::size_t>(depth) * 2, ' ');
    out_ += text;
    out_ += comment;
    out_ += '\n';
    output_.Produced();
  }

  // "  'text" for a trailing comment; nothing when there is none. The IR
  // keeps a comment's text without its '; an empty string means no comment,
  // so a bare ' at the end of a line is not representable and not printed.
  static std::string CommentSuffix(std::string_view comment) {
    if (comment.empty()) return {};
    return "  '" + std::string(comment);
  }

  void PrintBlock(const ir::Block& block, int depth) {
    for (std::size_t i = 0; i < block.size(); ++i) {
      SMTCAL_CHECK(block[i] != nullptr, "null statement in a block");
      // At most one blank line (the IR holds a flag), and never as the first
      // line of the file or of a block, where it separates nothing.
      if (i > 0 && block[i]->blank_line_before) out_ += '\n';
      PrintStmt(*block[i], depth);
    }
  }

  void End(int depth, std::string_view keyword, const ir::BlockEnd& end) {
    Line(depth, keyword, CommentSuffix(end.comment));
  }

  void PrintStmt(const ir::Stmt& stmt, int depth) {
    std::string comment = CommentSuffix(stmt.trailing_comment);
    std::visit(
        [&](const auto& node) {
          using Node = std::decay_t<decltype(node)>;
          if constexpr (std::is_same_v<Node, ir::Comment>) {
            Line(depth, "'" + node.text, "");
          } else if constexpr (std::is_same_v<Node, ir::ProgramDecl>) {
            Line(depth, "Program " + node.name, comment);
          } else if constexpr (std::is_same_v<Node, ir::UnitsDecl>) {
            Line(depth, "Units " + node.unit, comment);
          } else if constexpr (std::is_same_v<Node, ir::FixtureDecl>) {
            Line(depth, "Fixture " + node.name, comment);
          } else if constexpr (std::is_same_v<Node, ir::LocalDecl>) {
            std::string text = "Local " + node.name + " = " + PrintCoords(node.origin);
            if (!node.frame.empty()) text += " In " + node.frame;
            Line(depth, text, comment);
          } else if constexpr (std::is_same_v<Node, ir::PointDecl>) {
            // The IR does not say whether In or On was written: a programmed
            // point is given In a frame, a taught point was taught On a fixture.
            std::string text = std::string(node.taught ? "Taught Point " : "Point ") + node.name +
                               " = " + PrintCoords(node.coords);
            if (!node.frame.empty()) text += (node.taught ? " On " : " In ") + node.frame;
            Line(depth, text, comment);
          } else if constexpr (std::is_same_v<Node, ir::PalletDecl>) {
            Line(depth,
                 "Pallet " + std::to_string(node.number) + ", " + node.corners[0] + ", " +
                     node.corners[1] + ", " + node.corners[2] + ", " +
                     std::to_string(node.columns) + ", " + std::to_string(node.rows),
                 comment);
          } else if constexpr (std::is_same_v<Node, ir::VacuumDecl>) {
            Line(depth, "Vacuum " + std::to_string(node.output), comment);
          } else if constexpr (std::is_same_v<Node, ir::VarDecl>) {
            std::string text = node.type == ir::VarType::Integer ? "Integer " : "Real ";
            for (std::size_t i = 0; i < node.names.size(); ++i) {
              if (i > 0) text += ", ";
              text += node.names[i];
            }
            Line(depth, text, comment);
          } else if constexpr (std::is_same_v<Node, ir::Function>) {
            Line(depth, "Function " + node.name, comment);
            PrintBlock(node.body, depth + 1);
            End(depth, "Fend", node.end);
          } else if constexpr (std::is_same_v<Node, ir::Assign>) {
            Line(depth, node.name + " = " + PrintExpr(*node.value), comment);
          } else if constexpr (std::is_same_v<Node, ir::Motion>) {
            std::string text = std::string(ir::MotionSpelling(node.kind)) + " " + PrintPointExpr(node.target);
            if (node.limz) text += " LimZ " + PrintExpr(*node.limz);
            Line(depth, text, comment);
          } else if constexpr (std::is_same_v<Node, ir::PickPlace>) {
            std::string text = std::string(ir::PickPlaceSpelling(node.kind)) + " " + PrintPointExpr(node.target);
            if (node.vacuum) text += " Vacuum " + PrintExpr(*node.vacuum);
            if (node.limz) text += " LimZ " + PrintExpr(*node.limz);
            Line(depth, text, comment);
          } else if constexpr (std::is_same_v<Node, ir::SetOutput>) {
            Line(depth, (node.on ? "On " : "Off ") + PrintExpr(*node.bit), comment);
          } else if constexpr (std::is_same_v<Node, ir::WaitTime>) {
            // The parser reads any `Wait Sw(n) = On|Off`, parenthesized or
            // not, as WaitSwitch, so a WaitTime never has that shape.
            Line(depth, "Wait " + PrintExpr(*node.seconds), comment);
          } else if constexpr (std::is_same_v<Node, ir::WaitSwitch>) {
            Line(depth, "Wait Sw(" + PrintExpr(*node.bit) + ") = " + (node.on ? "On" : "Off"),
                 comment);
          } else if constexpr (std::is_same_v<Node, ir::For>) {
            std::string text = "For " + node.var + " = " + PrintExpr(*node.from) + " To " +
                               PrintExpr(*node.to);
            if (node.step) text += " Step " + PrintExpr(*node.step);
            Line(depth, text, comment);
            PrintBlock(node.body, depth + 1);
            // `Next` always names its loop variable, spelled as in the For
            // line; a Next naming some other variable is the user's mistake,
            // kept as written for the checker to report.
            bool names_other = !node.next_var.empty() && !sema::SameName(node.next_var, node.var);
            End(depth, "Next " + (names_other ? node.next_var : node.var), node.end);
          } else if constexpr (std::is_same_v<Node, ir::If>) {
            for (std::size_t i = 0; i < node.branches.size(); ++i) {
              const ir::IfBranch& branch = node.branches[i];
              if (i == 0) {
                SMTCAL_CHECK(branch.condition != nullptr, "If without a condition");
                Line(depth, "If " + PrintExpr(*branch.condition) + " Then", comment);
              } else if (branch.condition) {
                Line(depth, "ElseIf " + PrintExpr(*branch.condition) + " Then",
                     CommentSuffix(branch.comment));
              } else {
                Line(depth, "Else", CommentSuffix(branch.comment));
              }
              PrintBlock(branch.body, depth + 1);
            }
            End(depth, "EndIf", node.end);
          } else if constexpr (std::is_same_v<Node, ir::Call>) {
            Line(depth, "Call " + node.name, comment);
          } else if constexpr (std::is_same_v<Node, ir::Cycle>) {
            Line(depth, "Cycle " + node.fixture, comment);
            PrintBlock(node.body, depth + 1);
            End(depth, "EndCycle", node.end);
          } else if constexpr (std::is_same_v<Node, ir::Scan>) {
            Line(depth, "Scan " + node.fixture, comment);
          } else if constexpr (std::is_same_v<Node, ir::ExitFunction>) {
            Line(depth, "Exit Function", comment);
          } else {
            static_assert(sizeof(Node) == 0, "statement kind not printed");
          }
        },
        stmt.node);
  }

  TextOutput& output_;
  std::string& out_;  // output_'s buffer
};

}  // namespace

void PrintPlace(const ir::Program& program, TextOutput& out) { Printer(out).Print(program); }

std::string PrintPlace(const ir::Program& program) {
  TextOutput out;
  PrintPlace(program, out);
  return std::move(out.buffer());
}

Status WritePlace(const std::string& path, const ir::Program& program) {
  Result<std::unique_ptr<TextOutput>> out = TextOutput::Open(path);
  if (!out) return out.error();
  PrintPlace(program, *out.value());
  return out.value()->Commit();
}

namespace {

void ApplyCanonicalChanges(ir::Block& block) {
  for (std::size_t i = 0; i < block.size(); ++i) {
    if (i == 0) block[i]->blank_line_before = false;
    std::visit(
        [](auto& node) {
          using Node = std::decay_t<decltype(node)>;
          if constexpr (std::is_same_v<Node, ir::Function> || std::is_same_v<Node, ir::Cycle>) {
            ApplyCanonicalChanges(node.body);
          } else if constexpr (std::is_same_v<Node, ir::For>) {
            if (node.next_var.empty() || sema::SameName(node.next_var, node.var)) {
              node.next_var = node.var;
            }
            ApplyCanonicalChanges(node.body);
          } else if constexpr (std::is_same_v<Node, ir::If>) {
            for (ir::IfBranch& branch : node.branches) ApplyCanonicalChanges(branch.body);
          }
        },
        block[i]->node);
  }
}

}  // namespace

void ApplyCanonicalChanges(ir::Program& program) { ApplyCanonicalChanges(program.items); }

}  // namespace smtcal
