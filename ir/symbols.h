// The symbol table the semantic checks share. A .place program has one
// namespace for fixtures, Local frames, points, global variables and
// functions; like SPEL+, names are case-insensitive. Top-level declarations
// are order-independent. Pallets are named by number and kept apart.
//
// Building the table never reports anything: the first definition of a name
// wins and later ones are recorded as duplicates, and only check_names
// reports the duplicates. A compile builds it once: SymbolsOf(program) makes
// it on first use and keeps it with the program for every later pass.
#pragma once

#include <cstdint>
#include <deque>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "base/diagnostics.h"
#include "base/source.h"
#include "ir/ir.h"

namespace smtcal::sema {

enum class SymbolKind { Fixture, Local, Point, Variable, Function };

struct Symbol {
  SymbolKind kind = SymbolKind::Point;
  std::string name;              // as declared
  SourceRange range;             // the name in its declaration
  const ir::Stmt* decl = nullptr;  // the declaring statement
  ir::VarType var_type = ir::VarType::Integer;  // Variable only
  bool global = true;                           // Variable only: false for a function's local
};

// What a name is, with its article, for messages: "a point", "a taught point",
// "a fixture", "a Local frame", "an Integer variable", "a function".
std::string DescribeKind(const Symbol& symbol);
// Case-insensitive key of a name.
std::string Lowercase(std::string_view name);
bool SameName(std::string_view a, std::string_view b);
// Hash and equality of names as the language compares them (ASCII case
// ignored), for maps looked up by a string_view without making a key.
struct NameHash {
  using is_transparent = void;
  std::size_t operator()(std::string_view name) const;
};
struct NameEqual {
  using is_transparent = void;
  bool operator()(std::string_view a, std::string_view b) const { return SameName(a, b); }
};
template <typename Value>
using NameMap = std::unordered_map<std::string, Value, NameHash, NameEqual>;

// Symbols by name, as the language compares names: an open-addressing table
// of (hash, symbol) slots, at most half full. A compile looks a name up in
// every pass, and a CAD-sized program has a million names: a lookup here
// touches one slot and the symbol it finds, where a node-based map also
// chases a node and its bucket (cache misses that made the lookups a sixth
// of a 1 M-placement compile).
class NameIndex {
 public:
  const Symbol* Find(std::string_view name) const;
  // Adds `symbol` under its own name unless a symbol of that name is there;
  // returns that one, else null. `symbol` must outlive the index.
  const Symbol* Insert(const Symbol& symbol);
  bool Contains(std::string_view name) const { return Find(name) != nullptr; }
  void Reserve(std::size_t names);

 private:
  struct Slot {
    std::size_t hash = 0;
    const Symbol* symbol = nullptr;  // null: empty
  };
  std::size_t SlotOf(std::string_view name, std::size_t hash) const;
  std::vector<Slot> slots_;  // size: zero or a power of two
  std::size_t count_ = 0;
};

// The range of `name` written at `loc` (names are kept as written, so the
// caret underlines exactly the name).
SourceRange NameAt(SourceLoc loc, std::string_view name);
// The range of a statement's first token.
SourceRange StmtRange(const ir::Stmt& stmt);
SourceRange ExprRange(const ir::Expr& expr);

// Where a point's coordinates are given. Two points are in the same frame
// exactly when their frames compare equal.
struct PointFrame {
  bool taught = false;
  std::string frame;  // lowercase; empty = robot base
  friend bool operator==(const PointFrame&, const PointFrame&) = default;
};

class SymbolTable {
 public:
  struct Duplicate {
    Symbol first;
    Symbol again;
  };
  struct PalletEntry {
    const ir::Stmt* stmt = nullptr;
    const ir::PalletDecl* pallet = nullptr;
  };

  // Collects the top-level declarations of `program` (not function locals).
  static SymbolTable Build(const ir::Program& program);
  // Moved, never copied: the lookups point into the table's own symbols.
  SymbolTable() = default;
  SymbolTable(SymbolTable&&) = default;
  SymbolTable& operator=(SymbolTable&&) = default;
  SymbolTable(const SymbolTable&) = delete;
  SymbolTable& operator=(const SymbolTable&) = delete;

  const Symbol* Find(std::string_view name) const;
  // The same for a point named in a statement; remembers the answer in
  // `point` (ir::NamedPoint::symbol), so the next pass asks no hash table.
  const Symbol* Find(const ir::NamedPoint& point) const;
  // Distinct for every table built in this process (never 0).
  std::uint64_t id() const { return id_; }
  // First definitions, in source order.
  const std::deque<Symbol>& symbols() const { return symbols_; }
  const std::vector<Duplicate>& duplicates() const { return duplicates_; }
  // Declared names of the given kinds, for "did you mean" suggestions.
  std::vector<std::string> NamesOf(std::initializer_list<SymbolKind> kinds) const;

  const PalletEntry* FindPallet(int number) const;
  // The second and later declarations of a pallet number, with the first.
  const std::vector<std::pair<PalletEntry, PalletEntry>>& duplicate_pallets() const {
    return duplicate_pallets_;
  }
  std::vector<int> PalletNumbers() const;

  // The fixture a frame (Fixture or Local) ultimately hangs in, following the
  // chain of Local frames `In` each other; null when the chain ends in the
  // robot base, at an undefined or wrong-kind name, or loops.
  const Symbol* FixtureOfFrame(const Symbol& frame) const;
  // The fixture a point belongs to: `In` a fixture-rooted frame, or `Taught
  // ... On FIXTURE`; null for robot-base points.
  const Symbol* FixtureOfPoint(const Symbol& point) const;
  // The frame a point's coordinates are given in.
  static PointFrame FrameOfPoint(const Symbol& point);
  // The fixture of a pallet: the fixture of its corners when all three are
  // defined points in one frame; null otherwise.
  const Symbol* FixtureOfPallet(int number) const;

 private:
  void Add(Symbol symbol);
  const Symbol* WalkToFixture(const Symbol& frame) const;
  const Symbol* PalletFixture(int number) const;

  std::uint64_t id_ = 0;
  std::deque<Symbol> symbols_;  // deque: Find's pointers stay valid
  NameIndex by_name_;
  std::vector<Duplicate> duplicates_;
  std::map<int, PalletEntry> pallets_;
  std::vector<std::pair<PalletEntry, PalletEntry>> duplicate_pallets_;
  // Made by Build, so the questions every target asks are one lookup.
  std::unordered_map<const Symbol*, const Symbol*> fixture_of_local_;
  std::map<int, const Symbol*> fixture_of_pallet_;
};

// The program's table, built on first use and then kept with the program
// (ir::Program::symbols), so the passes of a compile share one. It stays
// valid while the top-level declarations stay: a pass that adds, removes or
// renames one calls ForgetSymbols. (--verify-each checks that no pass forgot
// to: passes/pass.cpp.)
const SymbolTable& SymbolsOf(const ir::Program& program);
void ForgetSymbols(const ir::Program& program);
// Whether two tables hold the same symbols, duplicates and pallets (the same
// declarations, in the same order).
bool SameSymbols(const SymbolTable& a, const SymbolTable& b);

// A function's local variables, declared as a check walks the body in source
// order (SPEL+: a local is visible from its declaration to Fend, whatever
// block it is declared in). Lookups fall back to the global table.
class LocalScope {
 public:
  explicit LocalScope(const SymbolTable& globals) : globals_(globals) {}

  // Declares a local; returns the symbol it collides with, else null. A
  // local that collides with an earlier local is not declared again; one
  // that collides with a global is declared and hides it, so that the uses
  // after it (which mean the local) are not reported a second time.
  const Symbol* Declare(Symbol local);
  // Locals first, then globals.
  const Symbol* Find(std::string_view name) const;
  // Every variable visible here (locals and globals), for suggestions.
  std::vector<std::string> VariableNames() const;

 private:
  const SymbolTable& globals_;
  std::deque<Symbol> locals_;
  NameIndex by_name_;
};

// The symbols a VarDecl statement declares (one per name).
std::vector<Symbol> VariablesDeclaredBy(const ir::Stmt& stmt, bool global);

}  // namespace smtcal::sema
