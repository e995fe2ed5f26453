// The feeder set-up sheet (see setup_sheet.h).
#include "backend/reports/setup_sheet.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <tuple>
#include <unordered_map>

#include <fmt/format.h>

#include "backend/reports/svg_text.h"
#include "base/csv_field.h"
#include "base/field_text.h"
#include "calibration/error_table.h"
#include "calibration/tolerances.h"
#include "ir/symbols.h"

namespace smtcal {
namespace {

// ---------------------------------------------------------------- a program's sheet

// What a program's comments say a part is.
struct PartText {
  std::string value, package;
};

// The value and package a comment gives the part named `name`: the form
// `smtcal import` writes, "DESIGNATOR VALUE PACKAGE", whose first word is
// the part's designator (its point is named after it, "Pcb2_R1" on the
// second board of a panel); the value may hold spaces, the package not;
// the comment ends at a "; " (the passes append their notes after one).
std::optional<PartText> CommentPart(std::string_view comment, std::string_view name) {
  // What a pass added after "; " (a taught point's conversion) is not the part's.
  comment = comment.substr(0, comment.find("; "));
  std::vector<std::string> words;
  std::string word;
  for (char c : comment) {
    if (c == ' ' || c == '\t') {
      if (!word.empty()) words.push_back(std::move(word));
      word.clear();
    } else {
      word += c;
    }
  }
  if (!word.empty()) words.push_back(std::move(word));
  if (words.size() < 3) return std::nullopt;
  const std::string point = AsciiLowercase(name), designator = AsciiLowercase(MakeIdentifier(words.front()));
  const bool named = point == designator || (point.size() > designator.size() + 1 && point.ends_with("_" + designator));
  if (!named) return std::nullopt;
  PartText part;
  for (std::size_t i = 1; i + 1 < words.size(); ++i) part.value += (i == 1 ? "" : " ") + words[i];
  part.package = words.back();
  return part;
}

// What the comments of a program say of its parts: a Place's own comment,
// else its point's declaration's.
class PartComments {
 public:
  explicit PartComments(const ir::Program& program) {
    for (const ir::StmtPtr& item : program.items) {
      const auto* point = std::get_if<ir::PointDecl>(&item->node);
      if (point == nullptr) continue;
      if (std::optional<PartText> part = CommentPart(item->trailing_comment, point->name)) {
        by_point_.emplace(AsciiLowercase(point->name), *part);
      }
    }
  }
  PartText Of(const ir::Stmt& place) const {
    const auto* pick_place = std::get_if<ir::PickPlace>(&place.node);
    const auto* named = pick_place == nullptr ? nullptr : std::get_if<ir::NamedPoint>(&pick_place->target.base);
    if (named == nullptr) return {};
    if (std::optional<PartText> part = CommentPart(place.trailing_comment, named->name)) return *part;
    auto it = by_point_.find(AsciiLowercase(named->name));
    return it == by_point_.end() ? PartText{} : it->second;
  }

 private:
  std::unordered_map<std::string, PartText> by_point_;
};

// Builds the rows of a program's sheet: one per feeder slot its picks
// reach, in the feeder order, then one per Pick it cannot place at a slot.
class SheetBuilder {
 public:
  SheetBuilder(const CompileState& state, const cad::FeederTable& table, Diagnostics& diags)
      : state_(state), table_(table), feeders_(table.feeders()), diags_(diags) {}

  // The row of the pick target `t` (an index into state.targets), made on
  // first use; what it cannot find is reported once per statement.
  std::size_t RowOf(std::size_t t) {
    if (auto it = row_of_target_.find(t); it != row_of_target_.end()) return it->second;
    const Target& target = state_.targets[t];
    std::size_t row = target.known ? SlotRow(target) : UnknownRow(target);
    row_of_target_.emplace(t, row);
    return row;
  }

  // A part placed from the row's slot: the place target as written, what
  // the program's comments say it is, and the nozzle's turn from `pick_u`.
  void AddPart(std::size_t row, const std::string& text, const PartText& part, std::optional<double> turn) {
    Row& r = rows_[row];
    auto [it, fresh] = r.part_index.emplace(text, r.parts.size());
    if (fresh) r.parts.emplace_back(text, 0);
    ++r.parts[it->second].second;
    for (auto [field, seen] : {std::pair{&part.value, &r.slot.values}, std::pair{&part.package, &r.slot.packages}}) {
      if (!field->empty() && std::find(seen->begin(), seen->end(), *field) == seen->end()) seen->push_back(*field);
    }
    if (turn) AddDistinct(r.slot.turns_deg, *turn);
  }

  void Pick(std::size_t row) { ++rows_[row].slot.count; }
  bool Picked(std::size_t row) const { return rows_[row].slot.count > 0 || !rows_[row].parts.empty(); }
  void Note(std::size_t row, std::string note) {
    if (rows_[row].slot.note.empty()) rows_[row].slot.note = std::move(note);
  }

  // The slots in feeder order, lanes and pockets ascending; then the picks
  // the sheet could not place, in the order they were met.
  std::vector<SetupSlot> Slots() {
    std::vector<std::size_t> order(rows_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      auto key = [&](const Row& r) {
        return std::make_tuple(r.feeder < 0 ? std::numeric_limits<int>::max() : r.feeder, r.feeder < 0 ? 0 : r.k);
      };
      return key(rows_[a]) < key(rows_[b]);
    });
    std::vector<SetupSlot> slots;
    for (std::size_t i : order) {
      Row& r = rows_[i];
      for (const auto& [text, n] : r.parts) r.slot.designators.push_back(n > 1 ? fmt::format("{} ×{}", text, n) : text);
      if (r.feeder >= 0) Describe(r);
      slots.push_back(std::move(r.slot));
    }
    return slots;
  }

 private:
  struct Row {
    int feeder = -1;  // index into feeders_; -1: no slot ("?")
    int k = 0;        // pick point, 1-based
    SetupSlot slot;
    std::vector<std::pair<std::string, std::size_t>> parts;  // place target text, times placed
    std::unordered_map<std::string, std::size_t> part_index;
  };

  // What a slot holds: the program's comments (filled as parts are added),
  // then the feeders file's [[lane]], then the feeder's own patterns (a bank
  // with one package per lane gives this lane's own).
  void Describe(Row& r) const {
    const cad::FeederSpec& feeder = feeders_[static_cast<std::size_t>(r.feeder)];
    SetupSlot& slot = r.slot;
    DescribeSlot(slot, table_, static_cast<std::size_t>(r.feeder), r.k);
    if (slot.packages.empty()) {
      slot.packages = feeder.lanes_by_package() ? std::vector<std::string>{feeder.packages[static_cast<std::size_t>(r.k - 1)]}
                                                : feeder.packages;
    }
    if (slot.values.empty() && !feeder.value.empty()) slot.values = {feeder.value};
    AddDistinct(slot.in_tape_deg, SignedDegrees(slot.pick[3] - feeder.rotation_offset_deg));
  }

  std::size_t SlotRow(const Target& target) {
    const double x = target.required[0], y = target.required[1];
    int best_feeder = -1, best_k = 0;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t f = 0; f < feeders_.size(); ++f) {
      const cad::FeederSpec& feeder = feeders_[f];
      for (int k = 1; k <= feeder.pick_points(); ++k) {
        const std::array<double, 4> p =
            cell::PalletPickPoint(feeder.pick, feeder.pallet_last, feeder.pallet_back, feeder.columns, feeder.rows, k);
        const double d = std::hypot(p[0] - x, p[1] - y);
        if (d < best) {
          best = d;
          best_feeder = static_cast<int>(f);
          best_k = k;
        }
      }
    }
    if (best_feeder >= 0 && best <= kFeederPickMatchMm) return SlotRowAt(best_feeder, best_k);
    // At no pick point the sheet knows of: one row per statement.
    auto [it, fresh] = unplaced_.emplace(target.stmt, rows_.size());
    if (!fresh) return it->second;
    std::string nearest = "the cell and the feeders file hold no feeder";
    if (best_feeder >= 0) {
      const cad::FeederSpec& feeder = feeders_[static_cast<std::size_t>(best_feeder)];
      const std::array<double, 4> p = cell::PalletPickPoint(feeder.pick, feeder.pallet_last, feeder.pallet_back,
                                                            feeder.columns, feeder.rows, best_k);
      nearest = fmt::format("the nearest is {}'{}' at ({}, {}), {} mm away", SlotName(feeder, best_k),
                            Printable(feeder.name), FormatComputedMm(p[0]), FormatComputedMm(p[1]),
                            FormatComputedMm(best));
    }
    diags_.Report(DiagKind::SetupPickAtNoFeeder, sema::StmtRange(*target.stmt), target.text, FormatComputedMm(x),
                  FormatComputedMm(y), nearest);
    Row row;
    row.slot.feeder = "?";
    row.slot.pick = target.required;
    row.slot.note = fmt::format("Pick {} (line {}) at ({}, {}): at no feeder's pick point", target.text,
                                target.stmt->loc.line, FormatComputedMm(x), FormatComputedMm(y));
    rows_.push_back(std::move(row));
    return rows_.size() - 1;
  }

  std::size_t UnknownRow(const Target& target) {
    auto [it, fresh] = unplaced_.emplace(target.stmt, rows_.size());
    if (!fresh) return it->second;
    diags_.Report(DiagKind::SetupPickPositionUnknown, sema::StmtRange(*target.stmt), target.text,
                  target.unknown_because);
    Row row;
    row.slot.feeder = "?";
    row.slot.pick_known = false;
    row.slot.note = fmt::format("Pick {} (line {}): its position is known only at run time ({})", target.text,
                                target.stmt->loc.line, target.unknown_because);
    rows_.push_back(std::move(row));
    return rows_.size() - 1;
  }

  // "lane 3 of ", "pocket 12 of " or "" (a single pick point).
  static std::string SlotName(const cad::FeederSpec& feeder, int k) {
    if (!feeder.is_pallet()) return "";
    return fmt::format("{} {} of ", feeder.kind == cell::FeederKind::kTray ? "pocket" : "lane", k);
  }

  std::size_t SlotRowAt(int f, int k) {
    auto [it, fresh] = slot_rows_.emplace(std::make_pair(f, k), rows_.size());
    if (!fresh) return it->second;
    const cad::FeederSpec& feeder = feeders_[static_cast<std::size_t>(f)];
    Row row;
    row.feeder = f;
    row.k = k;
    SetupSlot& slot = row.slot;
    slot.feeder = feeder.name;
    slot.feeder_kind = cell::kFeederKindNames[static_cast<std::size_t>(feeder.kind)];
    if (feeder.is_pallet()) {
      slot.slot_kind = feeder.kind == cell::FeederKind::kTray ? "pocket" : "lane";
      slot.slot = k;
    }
    slot.pick = cell::PalletPickPoint(feeder.pick, feeder.pallet_last, feeder.pallet_back, feeder.columns,
                                      feeder.rows, k);
    for (double& coordinate : slot.pick) coordinate = RoundForProgramText(coordinate);
    rows_.push_back(std::move(row));
    return rows_.size() - 1;
  }

  const CompileState& state_;
  const cad::FeederTable& table_;
  const std::vector<cad::FeederSpec>& feeders_;
  Diagnostics& diags_;
  std::vector<Row> rows_;
  std::map<std::pair<int, int>, std::size_t> slot_rows_;   // (feeder, k) -> row
  std::map<const ir::Stmt*, std::size_t> unplaced_;        // a Pick the sheet cannot place -> its row
  std::unordered_map<std::size_t, std::size_t> row_of_target_;
};

bool IsPick(const Target& target, ir::PickPlaceKind kind) {
  const auto* pick = std::get_if<ir::PickPlace>(&target.stmt->node);
  return pick != nullptr && pick->kind == kind;
}

bool Before(const SourceLoc& a, const SourceLoc& b) {
  return std::tie(a.file, a.line, a.column) < std::tie(b.file, b.line, b.column);
}

// ---------------------------------------------------------------- printing

std::string Joined(const std::vector<std::string>& items, std::string_view separator) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : std::string(separator)) + item;
  return text;
}

// "lane 3", "pocket 12", or "-" for a feeder's single pick point.
std::string SlotText(const SetupSlot& slot) {
  return slot.slot_kind.empty() ? std::string("-") : fmt::format("{} {}", slot.slot_kind, slot.slot);
}

// Width of a text in columns: UTF-8 characters, not bytes (µ, Ω in values).
std::size_t Columns(const std::string& text) { return Utf8Columns(text); }

std::string Padded(const std::string& text, std::size_t width) {
  return text + std::string(width > Columns(text) ? width - Columns(text) : 0, ' ');
}

}  // namespace

SetupSheet ProgramSetupSheet(const ir::Program& program, const CompileState& state, const cad::FeederTable& feeders,
                             Diagnostics& diags) {
  SetupSheet sheet;
  sheet.program = "program";
  for (const ir::StmtPtr& item : program.items) {
    if (const auto* decl = std::get_if<ir::ProgramDecl>(&item->node)) sheet.program = decl->name;
  }
  // The cycles in program order (the trace keeps them by address).
  std::vector<std::pair<const ir::Stmt*, const std::vector<TraceEvent>*>> cycles;
  for (const auto& [stmt, events] : state.cycle_traces) cycles.emplace_back(stmt, &events);
  std::sort(cycles.begin(), cycles.end(), [](const auto& a, const auto& b) { return Before(a.first->loc, b.first->loc); });

  SheetBuilder builder(state, feeders, diags);
  const PartComments comments(program);
  auto turn = [&](std::size_t pick, const Target& place) -> std::optional<double> {
    const Target& from = state.targets[pick];
    if (!from.known || !place.known) return std::nullopt;
    return SignedDegrees(RoundForProgramText(place.required[3] - from.required[3]));
  };
  std::vector<bool> traced(state.targets.size(), false);
  std::vector<std::string> fixtures, lines;
  for (const auto& [stmt, events] : cycles) {
    const std::string& fixture = std::get<ir::Cycle>(stmt->node).fixture;
    if (std::find(fixtures.begin(), fixtures.end(), fixture) == fixtures.end()) fixtures.push_back(fixture);
    lines.push_back(std::to_string(stmt->loc.line));
    // Each Pick counts at its slot; the Place after it is the part it gives.
    // (kNone: no Pick since the last Place; a plain index rather than an
    // optional, which GCC 12 wrongly takes for uninitialized here.)
    constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
    std::size_t picked = kNone, pick_target = kNone;
    for (const TraceEvent& event : *events) {
      if (event.kind != TraceEvent::Kind::kMotion) continue;
      const Target& target = state.targets[event.target];
      if (IsPick(target, ir::PickPlaceKind::Pick)) {
        traced[event.target] = true;
        picked = builder.RowOf(event.target);
        pick_target = event.target;
        builder.Pick(picked);
      } else if (IsPick(target, ir::PickPlaceKind::Place) && picked != kNone) {
        builder.AddPart(picked, target.text, comments.Of(*target.stmt), turn(pick_target, target));
        picked = kNone;
      }
    }
  }
  // Picks the traced run does not reach (another branch of an If on an
  // input: a spare lane; a Pick outside every Cycle): their slots must be
  // loaded too. The part is the next Place the compile met after them.
  for (std::size_t t = 0; t < state.targets.size(); ++t) {
    const Target& target = state.targets[t];
    if (traced[t] || !IsPick(target, ir::PickPlaceKind::Pick)) continue;
    const std::size_t row = builder.RowOf(t);
    if (builder.Picked(row)) continue;
    builder.Note(row, fmt::format("not picked on the traced run: Pick {} (line {}) is on another branch of an If, "
                                  "or outside every Cycle",
                                  target.text, target.stmt->loc.line));
    for (std::size_t next = t + 1; next < state.targets.size(); ++next) {
      if (IsPick(state.targets[next], ir::PickPlaceKind::Place)) {
        builder.AddPart(row, state.targets[next].text, comments.Of(*state.targets[next].stmt),
                        turn(t, state.targets[next]));
        break;
      }
    }
  }
  sheet.fixture = Joined(fixtures, ", ");
  sheet.from = fmt::format("the first run of its Cycle{} (line{} {}), as the compile traces it",
                           lines.size() == 1 ? "" : "s", lines.size() == 1 ? "" : "s", Joined(lines, ", "));
  sheet.slots = builder.Slots();
  return sheet;
}

namespace {

// ---------------------------------------------------------------- the cells of a row

// A number as a person reads it: up to 4 decimals, no trailing zeros.
std::string Short(double value) {
  std::string text = fmt::format("{:.4f}", value);
  while (text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  return text == "-0" ? "0" : text;
}

std::string Degrees(const std::vector<double>& angles) {
  std::vector<std::string> parts;
  for (double a : angles) parts.push_back(Short(a) + "°");
  return Joined(parts, " / ");
}

// "8 x 4 mm", "8 mm" or "" (what is declared of the tape).
std::string TapeText(const SetupSlot& slot) {
  if (slot.tape_width_mm && slot.tape_pitch_mm) {
    return fmt::format("{} x {} mm", Short(*slot.tape_width_mm), Short(*slot.tape_pitch_mm));
  }
  if (slot.tape_width_mm) return fmt::format("{} mm wide", Short(*slot.tape_width_mm));
  if (slot.tape_pitch_mm) return fmt::format("pitch {} mm", Short(*slot.tape_pitch_mm));
  return "";
}

std::size_t LotQuantity(const SetupSheet& sheet, const SetupSlot& slot) { return slot.count * sheet.LotCycles(); }

std::size_t Spares(const SetupSheet& sheet, const SetupSlot& slot) {
  return static_cast<std::size_t>(std::ceil(static_cast<double>(LotQuantity(sheet, slot)) * sheet.spares_percent / 100 - 1e-9));
}

std::string PickText(const SetupSlot& slot) {
  if (!slot.pick_known) return "at run time";
  return fmt::format("({}, {}, {}, {}°)", Short(slot.pick[0]), Short(slot.pick[1]), Short(slot.pick[2]),
                     Short(slot.pick[3]));
}

std::string PartsText(const SetupSlot& slot) {
  std::string parts = Joined(slot.designators, ", ");
  if (!slot.note.empty()) parts += (parts.empty() ? "(" : " (") + slot.note + ")";
  return parts;
}

// The sheet's opening lines.
std::string Heading(const SetupSheet& sheet) {
  std::size_t picks = 0;
  std::vector<std::string> feeders;
  for (const SetupSlot& slot : sheet.slots) {
    picks += slot.count;
    if (slot.feeder != "?" && std::find(feeders.begin(), feeders.end(), slot.feeder) == feeders.end()) {
      feeders.push_back(slot.feeder);
    }
  }
  std::string out = fmt::format("Feeder set-up for program {} (fixture {}{}): {} pick{} per cycle from {} feeder{}\n",
                                sheet.program, sheet.fixture,
                                sheet.boards > 1 ? fmt::format(", {} boards", sheet.boards) : std::string(), picks,
                                picks == 1 ? "" : "s", feeders.size(), feeders.size() == 1 ? "" : "s");
  if (!sheet.from.empty()) out += fmt::format("counted on {}\n", sheet.from);
  if (sheet.lot_boards > 0) {
    out += fmt::format("a lot of {} board{}: {} cycle{} of {} board{}; spares {}% of each lane's parts, rounded up\n",
                       sheet.lot_boards, sheet.lot_boards == 1 ? "" : "s", sheet.LotCycles(),
                       sheet.LotCycles() == 1 ? "" : "s", sheet.boards, sheet.boards == 1 ? "" : "s",
                       Short(sheet.spares_percent));
  }
  return out;
}

struct Column {
  std::string head;
  std::vector<std::string> cells;
};

// The sheet as columns (text and picture share them; the printed page
// leaves out the kind, which the slot says, and the turns, which loading
// does not need).
std::vector<Column> SheetColumns(const SetupSheet& sheet, bool page = false) {
  std::vector<Column> columns = {{"feeder", {}},   {"kind", {}},     {"slot", {}},    {"location", {}},
                                 {"count", {}},    {"lot", {}},      {"value", {}},   {"package", {}},
                                 {"part number", {}}, {"tape", {}},  {"in tape", {}}, {"turns", {}},
                                 {"pick (x, y, z, u)", {}}, {"parts", {}}};
  for (const SetupSlot& slot : sheet.slots) {
    const std::vector<std::string> cells = {
        Printable(slot.feeder),
        slot.feeder_kind.empty() ? "-" : slot.feeder_kind,
        SlotText(slot),
        slot.location.empty() ? "-" : Printable(slot.location),
        std::to_string(slot.count),
        fmt::format("{} + {}", LotQuantity(sheet, slot), Spares(sheet, slot)),
        slot.values.empty() ? "-" : Printable(Joined(slot.values, " / ")),
        slot.packages.empty() ? "-" : Printable(Joined(slot.packages, " / ")),
        slot.part_numbers.empty() ? "-" : Printable(Joined(slot.part_numbers, " / ")),
        TapeText(slot).empty() ? "-" : TapeText(slot),
        slot.in_tape_deg.empty() ? "-" : Degrees(slot.in_tape_deg),
        slot.turns_deg.empty() ? "-" : Degrees(slot.turns_deg),
        PickText(slot),
        PartsText(slot)};
    for (std::size_t c = 0; c < cells.size(); ++c) columns[c].cells.push_back(cells[c]);
  }
  std::vector<Column> kept;
  for (Column& column : columns) {
    if (column.head == "lot" && sheet.lot_boards == 0) continue;  // no lot: no lot column
    if (page && (column.head == "kind" || column.head == "turns")) continue;
    kept.push_back(std::move(column));
  }
  return kept;
}

}  // namespace

std::string SetupSheetText(const SetupSheet& sheet) {
  std::string out = Heading(sheet) + "\n";
  const std::vector<Column> columns = SheetColumns(sheet);
  std::vector<std::size_t> width(columns.size());
  for (std::size_t c = 0; c + 1 < columns.size(); ++c) {
    width[c] = Columns(columns[c].head);
    for (const std::string& cell : columns[c].cells) width[c] = std::max(width[c], Columns(cell));
  }
  auto line = [&](auto&& cell_of) {
    std::string text;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::string cell = cell_of(columns[c]);
      text += c + 1 < columns.size() ? Padded(cell, width[c] + 2) : cell;
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text + "\n";
  };
  out += line([](const Column& column) { return column.head; });
  for (std::size_t r = 0; r < sheet.slots.size(); ++r) out += line([&](const Column& column) { return column.cells[r]; });
  out += "\n(in tape: where the part's 0° (as its CAD footprint draws it) points in the tape or pocket, robot base "
         "frame; turns: how far the nozzle turns it from pick to place";
  out += sheet.lot_boards > 0 ? "; lot: parts for the lot + spares)\n" : ")\n";
  return out;
}

std::string SetupSheetCsv(const SetupSheet& sheet) {
  std::string out =
      "feeder,kind,slot_kind,slot,location,count,lot_quantity,spares,value,package,part_number,tape_width_mm,"
      "tape_pitch_mm,in_tape_deg,turns_deg,parts,pick_x_mm,pick_y_mm,pick_z_mm,pick_u_deg,note\n";
  auto numbers = [](const std::vector<double>& values) {
    std::vector<std::string> parts;
    for (double v : values) parts.push_back(Short(v));
    return Joined(parts, " ");
  };
  for (const SetupSlot& slot : sheet.slots) {
    const std::string pick = slot.pick_known ? fmt::format("{},{},{},{}", slot.pick[0], slot.pick[1], slot.pick[2],
                                                            slot.pick[3])
                                             : std::string(",,,");
    const bool lot = sheet.lot_boards > 0;
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", CsvField(Printable(slot.feeder)),
                       slot.feeder_kind, slot.slot_kind, slot.slot, CsvField(Printable(slot.location)), slot.count,
                       lot ? std::to_string(LotQuantity(sheet, slot)) : std::string(),
                       lot ? std::to_string(Spares(sheet, slot)) : std::string(),
                       CsvField(Printable(Joined(slot.values, " / "))), CsvField(Printable(Joined(slot.packages, " / "))),
                       CsvField(Printable(Joined(slot.part_numbers, " / "))),
                       slot.tape_width_mm ? Short(*slot.tape_width_mm) : std::string(),
                       slot.tape_pitch_mm ? Short(*slot.tape_pitch_mm) : std::string(), numbers(slot.in_tape_deg),
                       numbers(slot.turns_deg), CsvField(Joined(slot.designators, ", ")), pick, CsvField(slot.note));
  }
  return out;
}

std::string SetupSheetSvg(const SetupSheet& sheet) {
  // A page for the printer: A4 landscape at 96 px per inch, as tall as the
  // rows need; the table in a fixed-width face so its columns line up.
  constexpr double kWidth = 1123, kMargin = 28, kRow = 22, kChar = 6.6;  // 11 px monospace
  const std::vector<Column> columns = SheetColumns(sheet, true);
  // Column widths in characters, the parts column taking what is left.
  std::vector<std::size_t> chars(columns.size());
  std::size_t used = 0;
  for (std::size_t c = 0; c + 1 < columns.size(); ++c) {
    chars[c] = Columns(columns[c].head);
    for (const std::string& cell : columns[c].cells) chars[c] = std::max(chars[c], Columns(cell));
    used += chars[c] + 2;
  }
  const double tick = 28;  // the operator's tick box, last
  // The text's room: the table less the tick box's column and a gap of two
  // characters before it (the parts column's text runs up to its end).
  const double table_width = kWidth - 2 * kMargin - tick - 2 * kChar;
  chars.back() = static_cast<std::size_t>(std::max(30.0, table_width / kChar - static_cast<double>(used) - 2));
  const double scale = std::min(1.0, table_width / (kChar * static_cast<double>(used + chars.back())));
  std::string heading = Heading(sheet);
  std::vector<std::string> head_lines;
  for (std::size_t start = 0, end; (end = heading.find('\n', start)) != std::string::npos; start = end + 1) {
    head_lines.push_back(heading.substr(start, end - start));
  }
  const double top = kMargin + 20 + 18 * static_cast<double>(head_lines.size()) + 12;
  const double height = top + kRow * static_cast<double>(sheet.slots.size() + 1) + 70;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n"
      "  <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      SvgNum(kWidth), SvgNum(height));
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"17\" font-weight=\"bold\">Feeder set-up sheet: {}</text>\n",
                     SvgNum(kMargin), SvgNum(kMargin + 6), SvgEscape(sheet.program));
  for (std::size_t i = 0; i < head_lines.size(); ++i) {
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" fill=\"#333\">{}</text>\n", SvgNum(kMargin),
                       SvgNum(kMargin + 28 + 18 * static_cast<double>(i)), SvgEscape(head_lines[i]));
  }
  // The table: a shaded head, rows striped, a tick box per row.
  svg += fmt::format("  <g font-family=\"DejaVu Sans Mono, Menlo, Consolas, monospace\" font-size=\"{}\">\n",
                     SvgNum(11 * scale));
  auto row_y = [&](std::size_t r) { return top + kRow * static_cast<double>(r); };
  svg += fmt::format("    <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#dbe8f5\"/>\n", SvgNum(kMargin),
                     SvgNum(row_y(0)), SvgNum(kWidth - 2 * kMargin), SvgNum(kRow));
  for (std::size_t r = 0; r < sheet.slots.size(); ++r) {
    if (r % 2 == 1) {
      svg += fmt::format("    <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#f3f3f3\"/>\n", SvgNum(kMargin),
                         SvgNum(row_y(r + 1)), SvgNum(kWidth - 2 * kMargin), SvgNum(kRow));
    }
  }
  double x = kMargin + 4, in_tape_x = -1;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c].head == "in tape") in_tape_x = x;
    svg += fmt::format("    <text x=\"{}\" y=\"{}\" font-weight=\"bold\">{}</text>\n", SvgNum(x),
                       SvgNum(row_y(0) + 15), SvgEscape(columns[c].head));
    for (std::size_t r = 0; r < sheet.slots.size(); ++r) {
      std::string cell = columns[c].cells[r];
      if (Columns(cell) > chars[c]) {  // only the parts column is ever cut: the CSV has them all
        std::size_t keep = 0, seen = 0;
        for (; keep < cell.size() && seen + 1 < chars[c]; ++keep) seen += (static_cast<unsigned char>(cell[keep]) & 0xc0) != 0x80;
        while (keep < cell.size() && (static_cast<unsigned char>(cell[keep]) & 0xc0) == 0x80) ++keep;
        cell = cell.substr(0, keep) + "…";
      }
      svg += fmt::format("    <text x=\"{}\" y=\"{}\">{}</text>\n", SvgNum(x), SvgNum(row_y(r + 1) + 15), SvgEscape(cell));
    }
    x += kChar * scale * static_cast<double>(chars[c] + 2);
  }
  svg += "  </g>\n";
  // The direction of each part's 0° in its tape, drawn beside its angle.
  for (std::size_t r = 0; r < sheet.slots.size(); ++r) {
    const SetupSlot& slot = sheet.slots[r];
    if (slot.in_tape_deg.size() != 1 || in_tape_x < 0) continue;
    const double cx = in_tape_x + kChar * scale * (static_cast<double>(Columns(Degrees(slot.in_tape_deg))) + 2.5),
                 cy = row_y(r + 1) + kRow / 2;
    const double a = slot.in_tape_deg.front() * std::numbers::pi / 180, len = 7;
    const double ex = cx + len * std::cos(a), ey = cy - len * std::sin(a);
    svg += fmt::format("  <g class=\"in-tape\" data-deg=\"{}\"><line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#1b1b1b\" "
                       "stroke-width=\"1.4\"/><circle cx=\"{}\" cy=\"{}\" r=\"2\" fill=\"#1b1b1b\"/></g>\n",
                       Short(slot.in_tape_deg.front()), SvgNum(cx - len * std::cos(a)), SvgNum(cy + len * std::sin(a)),
                       SvgNum(ex), SvgNum(ey), SvgNum(ex), SvgNum(ey));
  }
  for (std::size_t r = 0; r < sheet.slots.size(); ++r) {
    svg += fmt::format("  <rect x=\"{}\" y=\"{}\" width=\"14\" height=\"14\" fill=\"none\" stroke=\"#444\"/>\n",
                       SvgNum(kWidth - kMargin - tick + 7), SvgNum(row_y(r + 1) + 4));
  }
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"10\" text-anchor=\"end\">loaded</text>\n",
                     SvgNum(kWidth - kMargin - 2), SvgNum(row_y(0) + 15));
  const double foot = row_y(sheet.slots.size() + 1) + 24;
  svg += fmt::format(
      "  <text x=\"{}\" y=\"{}\" font-size=\"11\" fill=\"#333\">in tape: where the part's 0° (as its CAD footprint "
      "draws it; the arrow's dot is its head) points in the tape or pocket, robot base frame, x to the right, y "
      "up{}.</text>\n",
      SvgNum(kMargin), SvgNum(foot), sheet.lot_boards > 0 ? "; lot: the lot's parts + spares" : "");
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"11\" fill=\"#333\">The CSV (--csv) and the text sheet "
                     "have every part of every slot and the nozzle's turns; this page cuts a long list of parts short "
                     "(…).</text>\n",
                     SvgNum(kMargin), SvgNum(foot + 18));
  svg += "</svg>\n";
  return svg;
}

}  // namespace smtcal
