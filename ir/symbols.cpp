#include "ir/symbols.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <utility>

namespace smtcal::sema {
namespace {

// ASCII only: names are ASCII, and they compare the same in every locale.
char LowerChar(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

}  // namespace

std::string DescribeKind(const Symbol& symbol) {
  switch (symbol.kind) {
    case SymbolKind::Fixture: return "a fixture";
    case SymbolKind::Local: return "a Local frame";
    case SymbolKind::Point: {
      const auto* point = symbol.decl ? std::get_if<ir::PointDecl>(&symbol.decl->node) : nullptr;
      return point != nullptr && point->taught ? "a taught point" : "a point";
    }
    case SymbolKind::Variable: {
      std::string type = symbol.var_type == ir::VarType::Integer ? "an Integer" : "a Real";
      return type + (symbol.global ? " variable" : " local variable");
    }
    case SymbolKind::Function: return "a function";
  }
  return "a name";
}

std::string Lowercase(std::string_view name) {
  std::string lower(name);
  for (char& c : lower) c = LowerChar(c);
  return lower;
}

bool SameName(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return LowerChar(x) == LowerChar(y); });
}

std::size_t NameHash::operator()(std::string_view name) const {
  std::size_t hash = 14695981039346656037ull;  // FNV-1a of the lowercased bytes
  for (char c : name) hash = (hash ^ static_cast<unsigned char>(LowerChar(c))) * 1099511628211ull;
  return hash;
}

// ------------------------------------------------------------------ NameIndex

std::size_t NameIndex::SlotOf(std::string_view name, std::size_t hash) const {
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t i = hash & mask;; i = (i + 1) & mask) {
    const Slot& slot = slots_[i];
    if (slot.symbol == nullptr || (slot.hash == hash && SameName(slot.symbol->name, name))) return i;
  }
}

const Symbol* NameIndex::Find(std::string_view name) const {
  if (slots_.empty()) return nullptr;
  return slots_[SlotOf(name, NameHash{}(name))].symbol;
}

const Symbol* NameIndex::Insert(const Symbol& symbol) {
  if ((count_ + 1) * 2 > slots_.size()) Reserve(count_ + 1);
  const std::size_t hash = NameHash{}(symbol.name);
  Slot& slot = slots_[SlotOf(symbol.name, hash)];
  if (slot.symbol != nullptr) return slot.symbol;
  slot = Slot{hash, &symbol};
  ++count_;
  return nullptr;
}

void NameIndex::Reserve(std::size_t names) {
  std::size_t size = 16;
  while (size < names * 2) size *= 2;
  if (size <= slots_.size()) return;
  std::vector<Slot> old = std::exchange(slots_, std::vector<Slot>(size));
  for (const Slot& slot : old) {
    if (slot.symbol != nullptr) slots_[SlotOf(slot.symbol->name, slot.hash)] = slot;
  }
}

SourceRange NameAt(SourceLoc loc, std::string_view name) {
  return SourceRange(loc, static_cast<std::uint32_t>(name.size()));
}

SourceRange StmtRange(const ir::Stmt& stmt) { return SourceRange(stmt.loc, stmt.length); }
SourceRange ExprRange(const ir::Expr& expr) { return SourceRange(expr.loc, expr.length); }

std::vector<Symbol> VariablesDeclaredBy(const ir::Stmt& stmt, bool global) {
  std::vector<Symbol> result;
  const auto* decl = std::get_if<ir::VarDecl>(&stmt.node);
  if (decl == nullptr) return result;
  for (std::size_t i = 0; i < decl->names.size(); ++i) {
    Symbol symbol;
    symbol.kind = SymbolKind::Variable;
    symbol.name = decl->names[i];
    SourceLoc loc = i < decl->name_locs.size() ? decl->name_locs[i] : stmt.loc;
    symbol.range = NameAt(loc, decl->names[i]);
    symbol.decl = &stmt;
    symbol.var_type = decl->type;
    symbol.global = global;
    result.push_back(std::move(symbol));
  }
  return result;
}

// ------------------------------------------------------------------ SymbolTable

SymbolTable SymbolTable::Build(const ir::Program& program) {
  static std::atomic<std::uint64_t> last_id{0};
  SymbolTable table;
  table.id_ = ++last_id;
  table.by_name_.Reserve(program.items.size());
  auto named = [&](SymbolKind kind, const ir::Stmt& stmt, const std::string& name, SourceLoc name_loc) {
    Symbol symbol;
    symbol.kind = kind;
    symbol.name = name;
    symbol.range = NameAt(name_loc, name);
    symbol.decl = &stmt;
    table.Add(std::move(symbol));
  };
  for (const ir::StmtPtr& item : program.items) {
    if (item == nullptr) continue;
    const ir::Stmt& stmt = *item;
    if (const auto* fixture = std::get_if<ir::FixtureDecl>(&stmt.node)) {
      named(SymbolKind::Fixture, stmt, fixture->name, fixture->name_loc);
    } else if (const auto* local = std::get_if<ir::LocalDecl>(&stmt.node)) {
      named(SymbolKind::Local, stmt, local->name, local->name_loc);
    } else if (const auto* point = std::get_if<ir::PointDecl>(&stmt.node)) {
      named(SymbolKind::Point, stmt, point->name, point->name_loc);
    } else if (const auto* function = std::get_if<ir::Function>(&stmt.node)) {
      named(SymbolKind::Function, stmt, function->name, function->name_loc);
    } else if (std::holds_alternative<ir::VarDecl>(stmt.node)) {
      for (Symbol& variable : VariablesDeclaredBy(stmt, /*global=*/true)) table.Add(std::move(variable));
    } else if (const auto* pallet = std::get_if<ir::PalletDecl>(&stmt.node)) {
      PalletEntry entry{&stmt, pallet};
      auto [it, inserted] = table.pallets_.emplace(pallet->number, entry);
      if (!inserted) table.duplicate_pallets_.emplace_back(it->second, entry);
    }
  }
  // The fixtures of the frames and pallets, once: every target asks.
  for (const Symbol& symbol : table.symbols_) {
    if (symbol.kind == SymbolKind::Local) table.fixture_of_local_.emplace(&symbol, table.WalkToFixture(symbol));
  }
  for (const auto& [number, entry] : table.pallets_) table.fixture_of_pallet_.emplace(number, table.PalletFixture(number));
  return table;
}

void SymbolTable::Add(Symbol symbol) {
  if (const Symbol* first = by_name_.Find(symbol.name)) {
    duplicates_.push_back({*first, std::move(symbol)});
    return;
  }
  symbols_.push_back(std::move(symbol));
  by_name_.Insert(symbols_.back());
}

const Symbol* SymbolTable::Find(std::string_view name) const { return by_name_.Find(name); }

const Symbol* SymbolTable::Find(const ir::NamedPoint& point) const {
  if (point.symbol_table == id_) return point.symbol;
  point.symbol = by_name_.Find(point.name);
  point.symbol_table = id_;
  return point.symbol;
}

const SymbolTable& SymbolsOf(const ir::Program& program) {
  if (!program.symbols) program.symbols = std::make_shared<const SymbolTable>(SymbolTable::Build(program));
  return *program.symbols;
}

void ForgetSymbols(const ir::Program& program) { program.symbols.reset(); }

bool SameSymbols(const SymbolTable& a, const SymbolTable& b) {
  auto same = [](const Symbol& x, const Symbol& y) {
    return x.kind == y.kind && x.name == y.name && x.decl == y.decl && x.range.begin == y.range.begin;
  };
  auto same_pallet = [](const SymbolTable::PalletEntry& x, const SymbolTable::PalletEntry& y) {
    return x.stmt == y.stmt && x.pallet == y.pallet;
  };
  return std::equal(a.symbols().begin(), a.symbols().end(), b.symbols().begin(), b.symbols().end(), same) &&
         std::equal(a.duplicates().begin(), a.duplicates().end(), b.duplicates().begin(), b.duplicates().end(),
                    [&](const auto& x, const auto& y) { return same(x.first, y.first) && same(x.again, y.again); }) &&
         a.PalletNumbers() == b.PalletNumbers() &&
         std::equal(a.duplicate_pallets().begin(), a.duplicate_pallets().end(), b.duplicate_pallets().begin(),
                    b.duplicate_pallets().end(), [&](const auto& x, const auto& y) {
                      return same_pallet(x.first, y.first) && same_pallet(x.second, y.second);
                    });
}

std::vector<std::string> SymbolTable::NamesOf(std::initializer_list<SymbolKind> kinds) const {
  std::vector<std::string> names;
  for (const Symbol& symbol : symbols_) {
    if (std::find(kinds.begin(), kinds.end(), symbol.kind) != kinds.end()) names.push_back(symbol.name);
  }
  return names;
}

const SymbolTable::PalletEntry* SymbolTable::FindPallet(int number) const {
  auto it = pallets_.find(number);
  return it == pallets_.end() ? nullptr : &it->second;
}

std::vector<int> SymbolTable::PalletNumbers() const {
  std::vector<int> numbers;
  for (const auto& [number, entry] : pallets_) numbers.push_back(number);
  return numbers;
}

const Symbol* SymbolTable::WalkToFixture(const Symbol& frame) const {
  const Symbol* current = &frame;
  // A chain longer than the number of symbols must revisit one: a loop.
  for (std::size_t steps = 0; steps <= symbols_.size(); ++steps) {
    if (current->kind == SymbolKind::Fixture) return current;
    if (current->kind != SymbolKind::Local || current->decl == nullptr) return nullptr;
    const auto& local = std::get<ir::LocalDecl>(current->decl->node);
    if (local.frame.empty()) return nullptr;
    current = Find(local.frame);
    if (current == nullptr) return nullptr;
  }
  return nullptr;
}

const Symbol* SymbolTable::FixtureOfFrame(const Symbol& frame) const {
  if (frame.kind == SymbolKind::Fixture) return &frame;
  auto it = fixture_of_local_.find(&frame);
  return it != fixture_of_local_.end() ? it->second : WalkToFixture(frame);
}

const Symbol* SymbolTable::FixtureOfPoint(const Symbol& point) const {
  if (point.kind != SymbolKind::Point || point.decl == nullptr) return nullptr;
  const auto& decl = std::get<ir::PointDecl>(point.decl->node);
  if (decl.frame.empty()) return nullptr;
  const Symbol* frame = Find(decl.frame);
  return frame == nullptr ? nullptr : FixtureOfFrame(*frame);
}

PointFrame SymbolTable::FrameOfPoint(const Symbol& point) {
  const auto& decl = std::get<ir::PointDecl>(point.decl->node);
  return PointFrame{decl.taught, Lowercase(decl.frame)};
}

const Symbol* SymbolTable::FixtureOfPallet(int number) const {
  auto it = fixture_of_pallet_.find(number);
  return it != fixture_of_pallet_.end() ? it->second : nullptr;
}

const Symbol* SymbolTable::PalletFixture(int number) const {
  const PalletEntry* entry = FindPallet(number);
  if (entry == nullptr) return nullptr;
  const Symbol* first = nullptr;
  for (const std::string& corner : entry->pallet->corners) {
    const Symbol* point = Find(corner);
    if (point == nullptr || point->kind != SymbolKind::Point) return nullptr;
    if (first == nullptr) {
      first = point;
    } else if (!(FrameOfPoint(*point) == FrameOfPoint(*first))) {
      return nullptr;
    }
  }
  return first == nullptr ? nullptr : FixtureOfPoint(*first);
}

// ------------------------------------------------------------------ LocalScope

const Symbol* LocalScope::Declare(Symbol local) {
  if (const Symbol* earlier = by_name_.Find(local.name)) return earlier;
  const Symbol* global = globals_.Find(local.name);
  locals_.push_back(std::move(local));
  by_name_.Insert(locals_.back());
  return global;
}

const Symbol* LocalScope::Find(std::string_view name) const {
  if (const Symbol* local = by_name_.Find(name)) return local;
  return globals_.Find(name);
}

std::vector<std::string> LocalScope::VariableNames() const {
  std::vector<std::string> names;
  for (const Symbol& local : locals_) names.push_back(local.name);
  for (std::string& global : globals_.NamesOf({SymbolKind::Variable})) {
    if (!by_name_.Contains(global)) names.push_back(std::move(global));
  }
  return names;
}

}  // namespace smtcal::sema
