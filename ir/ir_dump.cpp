#include "ir/ir_dump.h"

#include <cctype>
#include <string_view>

#include <fmt/format.h>

#include "base/field_text.h"
#include "ir/ir_ops.h"

namespace smtcal {
namespace {

// Names print bare when they look like identifiers, otherwise quoted, so a
// dump stays unambiguous whatever an importer put into a name.
bool IsBareName(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) return false;
  }
  return true;
}

std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    auto byte = static_cast<unsigned char>(c);
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (byte < 0x20 || byte == 0x7F) {
          out += fmt::format("\\x{:02x}", byte);
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string NameAtom(const std::string& name) { return IsBareName(name) ? name : Quoted(name); }

std::string Number(double value) { return fmt::format("{}", value); }

// Operators and axes print as the language spells them, in lower case like
// every head word of the dump: (+ a b), (mod a b), (and a b), (+x d).
// Unary operators get words of their own, so (neg a) never reads as a
// binary minus.
std::string_view UnaryName(ir::UnaryOp op) {
  switch (op) {
    case ir::UnaryOp::Negate: return "neg";
    case ir::UnaryOp::Plus: return "plus";
    case ir::UnaryOp::Not: return "not";
  }
  return "?";
}

class Dumper {
 public:
  explicit Dumper(bool with_locations) : locations_(with_locations) {}

  std::string Program(const ir::Program& program) {
    out_ = "(program";
    if (locations_) out_ += fmt::format(" @{}", program.file);
    Block(program.items, 1);
    out_ += ")\n";
    return std::move(out_);
  }

  std::string Expr(const ir::ExprPtr& expr) { return Expr(expr.get()); }
  std::string Expr(const ir::Expr* expr) {
    if (expr == nullptr) return "nil";
    std::string at = Loc(expr->loc, expr->length);
    return std::visit([&](const auto& node) { return ExprNode(node, at); }, expr->node);
  }

 private:
  // " @file:line:column[/length]" with locations, else "".
  std::string Loc(const SourceLoc& loc) const {
    return locations_ ? fmt::format(" @{}:{}:{}", loc.file, loc.line, loc.column) : std::string();
  }
  std::string Loc(const SourceLoc& loc, std::uint32_t length) const {
    return locations_ ? fmt::format("{}/{}", Loc(loc), length) : std::string();
  }

  // ---- expressions
  std::string ExprNode(const ir::NumberLit& n, const std::string& at) {
    return fmt::format("({}{} {})", n.is_integer ? "int" : "real", at, Number(n.value));
  }
  std::string ExprNode(const ir::VariableRef& v, const std::string& at) {
    return fmt::format("(var{} {})", at, NameAtom(v.name));
  }
  std::string ExprNode(const ir::OnOffLit& o, const std::string& at) {
    return fmt::format("({}{})", o.on ? "on" : "off", at);
  }
  std::string ExprNode(const ir::UnaryExpr& u, const std::string& at) {
    return fmt::format("({}{} {})", UnaryName(u.op), at, Expr(u.operand));
  }
  std::string ExprNode(const ir::BinaryExpr& b, const std::string& at) {
    return fmt::format("({}{} {} {})", AsciiLowercase(ir::BinaryOpSpelling(b.op)), at, Expr(b.lhs), Expr(b.rhs));
  }
  std::string ExprNode(const ir::SwitchRead& s, const std::string& at) {
    return fmt::format("(sw{} {})", at, Expr(s.bit));
  }

  // ---- points
  std::string Coords(const ir::Coords& c) {
    return fmt::format("(xy{} {} {} {} {})", Loc(c.loc), Number(c.values[0]), Number(c.values[1]),
                       Number(c.values[2]), Number(c.values[3]));
  }
  std::string Point(const ir::PointExpr& p) {
    std::string out = fmt::format("(point{} ", Loc(p.loc));
    if (const auto* named = std::get_if<ir::NamedPoint>(&p.base)) {
      std::string length = locations_ ? fmt::format(" /{}", named->length) : "";
      out += fmt::format("(name{} {})", length, NameAtom(named->name));
    } else if (const auto* coords = std::get_if<ir::Coords>(&p.base)) {
      out += Coords(*coords);
    } else if (const auto* pallet = std::get_if<ir::PalletPoint>(&p.base)) {
      out += fmt::format("(pallet {} {}", Expr(pallet->number), Expr(pallet->i));
      if (pallet->j) out += " " + Expr(pallet->j);
      out += ")";
    }
    for (const ir::PointOffset& offset : p.offsets) {
      out += fmt::format(" ({}{}{} {})", offset.negative ? '-' : '+', AsciiLowercase(ir::AxisSpelling(offset.axis)),
                         Loc(offset.loc), Expr(offset.amount));
    }
    return out + ")";
  }

  // ---- statements
  void Block(const ir::Block& block, int depth) {
    for (const ir::StmtPtr& stmt : block) {
      out_ += "\n" + std::string(2 * depth, ' ');
      if (!stmt) {
        out_ += "nil";
        continue;
      }
      Stmt(*stmt, depth);
    }
  }
  // The fields every statement has, after its own.
  std::string Common(const ir::Stmt& stmt) const {
    std::string out;
    if (stmt.blank_line_before) out += " :blank";
    if (!stmt.trailing_comment.empty()) out += " :comment " + Quoted(stmt.trailing_comment);
    return out;
  }
  std::string End(const ir::BlockEnd& end) const {
    std::string out = "(end" + Loc(end.loc);
    if (!end.comment.empty()) out += " :comment " + Quoted(end.comment);
    return out + ")";
  }
  std::string Frame(const std::string& frame, const SourceLoc& loc) const {
    if (frame.empty()) return "";
    return fmt::format(" :frame{} {}", Loc(loc), NameAtom(frame));
  }
  std::string Optional(const char* key, const ir::ExprPtr& expr) {
    return expr ? fmt::format(" :{} {}", key, Expr(expr)) : std::string();
  }

  void Stmt(const ir::Stmt& stmt, int depth) {
    std::string at = Loc(stmt.loc, stmt.length);
    std::visit([&](const auto& node) { StmtNode(node, stmt, at, depth); }, stmt.node);
  }
  void Simple(const std::string& head, const std::string& at, const std::string& fields,
              const ir::Stmt& stmt) {
    out_ += "(" + head + at + fields + Common(stmt) + ")";
  }

  void StmtNode(const ir::Comment& c, const ir::Stmt& s, const std::string& at, int) {
    Simple("comment", at, " " + Quoted(c.text), s);
  }
  void StmtNode(const ir::ProgramDecl& d, const ir::Stmt& s, const std::string& at, int) {
    Simple("program-decl", at, " " + NameAtom(d.name) + Loc(d.name_loc), s);
  }
  void StmtNode(const ir::UnitsDecl& d, const ir::Stmt& s, const std::string& at, int) {
    Simple("units", at, " " + NameAtom(d.unit) + Loc(d.unit_loc), s);
  }
  void StmtNode(const ir::FixtureDecl& d, const ir::Stmt& s, const std::string& at, int) {
    Simple("fixture", at, " " + NameAtom(d.name) + Loc(d.name_loc), s);
  }
  void StmtNode(const ir::LocalDecl& d, const ir::Stmt& s, const std::string& at, int) {
    Simple("local", at,
           " " + NameAtom(d.name) + Loc(d.name_loc) + " " + Coords(d.origin) + Frame(d.frame, d.frame_loc), s);
  }
  void StmtNode(const ir::PointDecl& d, const ir::Stmt& s, const std::string& at, int) {
    std::string fields = " " + NameAtom(d.name) + Loc(d.name_loc) + (d.taught ? " :taught " : " ") + Coords(d.coords);
    Simple("point-decl", at, fields + Frame(d.frame, d.frame_loc), s);
  }
  void StmtNode(const ir::PalletDecl& d, const ir::Stmt& s, const std::string& at, int) {
    std::string fields = fmt::format(" {}{}", d.number, Loc(d.number_loc));
    for (std::size_t i = 0; i < 3; ++i) fields += " " + NameAtom(d.corners[i]) + Loc(d.corner_locs[i]);
    fields += fmt::format(" {}{} {}{}", d.columns, Loc(d.columns_loc), d.rows, Loc(d.rows_loc));
    Simple("pallet-decl", at, fields, s);
  }
  void StmtNode(const ir::VacuumDecl& d, const ir::Stmt& s, const std::string& at, int) {
    Simple("vacuum-decl", at, fmt::format(" {}{}", d.output, Loc(d.output_loc)), s);
  }
  void StmtNode(const ir::VarDecl& d, const ir::Stmt& s, const std::string& at, int) {
    std::string fields;
    for (std::size_t i = 0; i < d.names.size(); ++i) {
      fields += " " + NameAtom(d.names[i]);
      if (i < d.name_locs.size()) fields += Loc(d.name_locs[i]);
    }
    Simple(d.type == ir::VarType::Real ? "real" : "integer", at, fields, s);
  }
  void StmtNode(const ir::Function& f, const ir::Stmt& s, const std::string& at, int depth) {
    out_ += "(function" + at + " " + NameAtom(f.name) + Loc(f.name_loc) + Common(s);
    Block(f.body, depth + 1);
    out_ += "\n" + std::string(2 * (depth + 1), ' ') + End(f.end) + ")";
  }
  void StmtNode(const ir::Assign& a, const ir::Stmt& s, const std::string& at, int) {
    Simple("assign", at, " " + NameAtom(a.name) + " " + Expr(a.value), s);
  }
  void StmtNode(const ir::Motion& m, const ir::Stmt& s, const std::string& at, int) {
    std::string head = AsciiLowercase(ir::MotionSpelling(m.kind));
    std::string limz = m.limz ? fmt::format(" :limz{} {}", Loc(m.limz_loc), Expr(m.limz)) : std::string();
    Simple(head, at, " " + Point(m.target) + limz, s);
  }
  void StmtNode(const ir::PickPlace& p, const ir::Stmt& s, const std::string& at, int) {
    Simple(AsciiLowercase(ir::PickPlaceSpelling(p.kind)), at,
           " " + Point(p.target) + Optional("vacuum", p.vacuum) + Optional("limz", p.limz), s);
  }
  void StmtNode(const ir::SetOutput& o, const ir::Stmt& s, const std::string& at, int) {
    Simple(o.on ? "on" : "off", at, " " + Expr(o.bit), s);
  }
  void StmtNode(const ir::WaitTime& w, const ir::Stmt& s, const std::string& at, int) {
    Simple("wait", at, " " + Expr(w.seconds), s);
  }
  void StmtNode(const ir::WaitSwitch& w, const ir::Stmt& s, const std::string& at, int) {
    Simple("wait-sw", at, " " + Expr(w.bit) + (w.on ? " on" : " off"), s);
  }
  void StmtNode(const ir::For& f, const ir::Stmt& s, const std::string& at, int depth) {
    out_ += "(for" + at + " " + NameAtom(f.var) + Loc(f.var_loc) + " " + Expr(f.from) + " " + Expr(f.to) +
            Optional("step", f.step);
    if (!f.next_var.empty()) out_ += " :next " + NameAtom(f.next_var) + Loc(f.next_var_loc);
    out_ += Common(s);
    Block(f.body, depth + 1);
    out_ += "\n" + std::string(2 * (depth + 1), ' ') + End(f.end) + ")";
  }
  void StmtNode(const ir::If& f, const ir::Stmt& s, const std::string& at, int depth) {
    out_ += "(if" + at + Common(s);
    std::string indent(2 * (depth + 1), ' ');
    for (const ir::IfBranch& branch : f.branches) {
      out_ += "\n" + indent + (branch.condition ? "(branch" : "(else") + Loc(branch.loc);
      if (branch.condition) out_ += " " + Expr(branch.condition);
      if (!branch.comment.empty()) out_ += " :comment " + Quoted(branch.comment);
      Block(branch.body, depth + 2);
      out_ += ")";
    }
    out_ += "\n" + indent + End(f.end) + ")";
  }
  void StmtNode(const ir::Call& c, const ir::Stmt& s, const std::string& at, int) {
    Simple("call", at, " " + NameAtom(c.name) + Loc(c.name_loc), s);
  }
  void StmtNode(const ir::Cycle& c, const ir::Stmt& s, const std::string& at, int depth) {
    out_ += "(cycle" + at + " " + NameAtom(c.fixture) + Loc(c.fixture_loc) + Common(s);
    Block(c.body, depth + 1);
    out_ += "\n" + std::string(2 * (depth + 1), ' ') + End(c.end) + ")";
  }
  void StmtNode(const ir::Scan& c, const ir::Stmt& s, const std::string& at, int) {
    Simple("scan", at, " " + NameAtom(c.fixture) + Loc(c.fixture_loc), s);
  }
  void StmtNode(const ir::ExitFunction&, const ir::Stmt& s, const std::string& at, int) {
    Simple("exit-function", at, "", s);
  }

  bool locations_;
  std::string out_;
};

}  // namespace

std::string DumpIr(const ir::Program& program, bool with_locations) {
  return Dumper(with_locations).Program(program);
}

std::string DumpExpr(const ir::Expr& expr, bool with_locations) {
  return Dumper(with_locations).Expr(&expr);
}

}  // namespace smtcal
