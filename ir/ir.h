// The IR: a .place program as a tree of plain structs. Every node carries the
// SourceLoc it came from; nodes a pass injects borrow the location of what
// caused them. Comments and blank lines are kept so `smtcal fmt` can print a
// program back without losing anything a person wrote.
//
// Units: the IR keeps numbers exactly as written (mm, degrees, seconds);
// conversion to radians happens where angles are used in math.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "base/source.h"

namespace smtcal {
struct CompileState;  // passes/correction/compile_state.h
}
namespace smtcal::sema {
class SymbolTable;  // ir/symbols.h
struct Symbol;
}

namespace smtcal::ir {

// ------------------------------------------------------------------ expressions

enum class UnaryOp { Negate, Plus, Not };
enum class BinaryOp { Add, Sub, Mul, Div, Mod, Eq, Ne, Lt, Gt, Le, Ge, And, Or, Xor };

struct Expr;
using ExprPtr = std::unique_ptr<Expr>;

struct NumberLit {
  double value = 0;
  bool is_integer = false;  // written without '.' or exponent
};
struct VariableRef {
  std::string name;
};
struct OnOffLit {
  bool on = false;
};
struct UnaryExpr {
  UnaryOp op;
  ExprPtr operand;
};
struct BinaryExpr {
  BinaryOp op;
  ExprPtr lhs, rhs;
};
struct SwitchRead {  // Sw(n)
  ExprPtr bit;
};

struct Expr {
  SourceLoc loc;
  std::uint32_t length = 1;  // bytes of source text, for caret underlines
  std::variant<NumberLit, VariableRef, OnOffLit, UnaryExpr, BinaryExpr, SwitchRead> node;
};

// ------------------------------------------------------------------ points

// XY(x, y, z, u): mm and degrees, as written.
struct Coords {
  std::array<double, 4> values{};  // x, y, z, u
  SourceLoc loc;
  friend bool operator==(const Coords& a, const Coords& b) { return a.values == b.values; }
};

enum class Axis { X, Y, Z, U };

struct PointOffset {  // + X(d), - U(d), ...
  SourceLoc loc;
  bool negative = false;
  Axis axis = Axis::X;
  ExprPtr amount;
};

struct NamedPoint {
  std::string name;
  std::uint32_t length = 1;
  // What the name was last found as, and by which symbol table (its
  // SymbolTable::id(); 0: never): sema::SymbolTable::Find(NamedPoint) fills
  // it, so that the passes after the first reach a placement's point
  // without a hash lookup. Not part of the program (a table trusts only its
  // own id); a pass that changes `name` sets symbol_table to 0.
  mutable const sema::Symbol* symbol = nullptr;
  mutable std::uint64_t symbol_table = 0;
};
struct PalletPoint {  // Pallet(n, i, j) or Pallet(n, k)
  ExprPtr number;
  ExprPtr i;
  ExprPtr j;  // null for the single-index form
};

struct PointExpr {
  SourceLoc loc;
  std::variant<NamedPoint, Coords, PalletPoint> base;
  std::vector<PointOffset> offsets;
};

// ------------------------------------------------------------------ statements
//
// Names and numbers that a diagnostic may underline keep the location of
// their first byte (`name_loc`, `frame_loc`, ...); the caret's length is the
// name's length, or the number of digits of a number. A name that is the
// statement's first token (an assignment's variable) uses Stmt::loc.

struct Stmt;
using StmtPtr = std::unique_ptr<Stmt>;
using Block = std::vector<StmtPtr>;

// A block's closing line (Fend, Next, EndIf, EndCycle): its location and the
// comment written on it.
struct BlockEnd {
  SourceLoc loc;
  std::string comment;
};

struct Comment {  // a line holding only a comment; text without the leading '
  std::string text;
};
struct ProgramDecl {
  std::string name;
  SourceLoc name_loc;
};
struct UnitsDecl {
  std::string unit;  // as written; only "mm" is valid
  SourceLoc unit_loc;
};
struct FixtureDecl {
  std::string name;
  SourceLoc name_loc;
};
struct LocalDecl {  // Local NAME = XY(...) [In FRAME]
  std::string name;
  SourceLoc name_loc;
  Coords origin;
  std::string frame;  // empty = robot base
  SourceLoc frame_loc;
};
struct PointDecl {  // [Taught] Point NAME = XY(...) [In FRAME | On FIXTURE]
  std::string name;
  SourceLoc name_loc;
  bool taught = false;
  Coords coords;
  std::string frame;  // empty = robot base; for taught points, the fixture
  SourceLoc frame_loc;
};
struct PalletDecl {  // Pallet n, P1, P2, P3, columns, rows
  int number = 0;
  SourceLoc number_loc;
  std::array<std::string, 3> corners;
  std::array<SourceLoc, 3> corner_locs;
  int columns = 0;
  SourceLoc columns_loc;
  int rows = 0;
  SourceLoc rows_loc;
};
struct VacuumDecl {  // Vacuum n: default vacuum output for Pick/Place
  int output = 0;
  SourceLoc output_loc;
};
enum class VarType { Integer, Real };
struct VarDecl {
  VarType type = VarType::Integer;
  std::vector<std::string> names;
  std::vector<SourceLoc> name_locs;
};
struct Function {
  std::string name;
  SourceLoc name_loc;
  Block body;
  BlockEnd end;  // the Fend line
};
struct Assign {
  std::string name;  // the statement's first token: at Stmt::loc
  ExprPtr value;
};
enum class MotionKind { Jump, Go, Move };
struct Motion {
  MotionKind kind = MotionKind::Jump;
  PointExpr target;
  ExprPtr limz;  // may be null
  SourceLoc limz_loc;  // the LimZ keyword: only Jump may have one
};
enum class PickPlaceKind { Pick, Place };
struct PickPlace {
  PickPlaceKind kind = PickPlaceKind::Pick;
  PointExpr target;
  ExprPtr vacuum;  // may be null: the program's Vacuum default
  ExprPtr limz;    // may be null
};
struct SetOutput {  // On n / Off n
  bool on = true;
  ExprPtr bit;
};
struct WaitTime {  // Wait t (seconds)
  ExprPtr seconds;
};
struct WaitSwitch {  // Wait Sw(n) = On|Off
  ExprPtr bit;
  bool on = true;
};
struct For {
  std::string var;
  SourceLoc var_loc;
  ExprPtr from, to, step;  // step may be null (= 1)
  Block body;
  BlockEnd end;
  std::string next_var;  // as written after Next (may be empty)
  SourceLoc next_var_loc;
};
struct IfBranch {
  SourceLoc loc;
  ExprPtr condition;  // null for Else
  Block body;
  // Comment on the ElseIf/Else line. The If line's own comment is the
  // Stmt's trailing_comment, so branches[0].comment stays empty.
  std::string comment;
};
struct If {
  std::vector<IfBranch> branches;  // If, ElseIf..., [Else with null condition]
  BlockEnd end;
};
struct Call {
  std::string name;
  SourceLoc name_loc;
};
struct Cycle {
  std::string fixture;
  SourceLoc fixture_loc;
  Block body;
  BlockEnd end;
};
struct Scan {
  std::string fixture;
  SourceLoc fixture_loc;
};
struct ExitFunction {};

struct Stmt {
  SourceLoc loc;
  std::uint32_t length = 1;      // bytes of the statement's first token
  bool blank_line_before = false;  // one blank line precedes it in the source
  std::string trailing_comment;  // comment at the end of its (first) line
  std::variant<Comment, ProgramDecl, UnitsDecl, FixtureDecl, LocalDecl, PointDecl, PalletDecl,
               VacuumDecl, VarDecl, Function, Assign, Motion, PickPlace, SetOutput, WaitTime,
               WaitSwitch, For, If, Call, Cycle, Scan, ExitFunction>
      node;
};

struct Program {
  std::uint32_t file = 0;  // SourceManager id of the main source
  Block items;             // top level, in source order
  // Set by the bind pass when the program is compiled for a cell; what the
  // correction passes found (passes/correction/compile_state.h). Null for `check`.
  std::shared_ptr<CompileState> compile;
  // The top-level symbol table every pass shares, made on first use by
  // sema::SymbolsOf (ir/symbols.h).
  mutable std::shared_ptr<const sema::SymbolTable> symbols;
};

}  // namespace smtcal::ir
