// The feeder set-up sheet (see setup_sheet.h).
#include "backend/reports/setup_sheet.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <unordered_map>

#include <fmt/format.h>

#include "base/csv_field.h"
#include "base/field_text.h"
#include "calibration/error_table.h"
#include "calibration/tolerances.h"
#include "ir/symbols.h"

namespace smtcal {
namespace {

// ---------------------------------------------------------------- a program's sheet

// Builds the rows of a program's sheet: one per feeder slot its picks
// reach, in the feeder order, then one per Pick it cannot place at a slot.
class SheetBuilder {
 public:
  SheetBuilder(const CompileState& state, const std::vector<cad::FeederSpec>& feeders, Diagnostics& diags)
      : state_(state), feeders_(feeders), diags_(diags) {}

  // The row of the pick target `t` (an index into state.targets), made on
  // first use; what it cannot find is reported once per statement.
  std::size_t RowOf(std::size_t t) {
    if (auto it = row_of_target_.find(t); it != row_of_target_.end()) return it->second;
    const Target& target = state_.targets[t];
    std::size_t row = target.known ? SlotRow(target) : UnknownRow(target);
    row_of_target_.emplace(t, row);
    return row;
  }

  // A part placed from the row's slot (a place target as written).
  void AddPart(std::size_t row, const std::string& text) {
    Row& r = rows_[row];
    auto [it, fresh] = r.part_index.emplace(text, r.parts.size());
    if (fresh) r.parts.emplace_back(text, 0);
    ++r.parts[it->second].second;
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
    // What the cell says it holds: a bank with one package per lane gives
    // this lane's own.
    if (feeder.lanes_by_package()) {
      slot.packages = {feeder.packages[static_cast<std::size_t>(k - 1)]};
    } else {
      slot.packages = feeder.packages;
    }
    if (!feeder.value.empty()) slot.values = {feeder.value};
    rows_.push_back(std::move(row));
    return rows_.size() - 1;
  }

  const CompileState& state_;
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
std::size_t Columns(const std::string& text) {
  std::size_t columns = 0;
  for (char c : text) columns += (static_cast<unsigned char>(c) & 0xc0) != 0x80;
  return columns;
}

std::string Padded(const std::string& text, std::size_t width) {
  return text + std::string(width > Columns(text) ? width - Columns(text) : 0, ' ');
}

}  // namespace

SetupSheet ProgramSetupSheet(const ir::Program& program, const CompileState& state,
                             const std::vector<cad::FeederSpec>& feeders, Diagnostics& diags) {
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
    std::size_t picked = kNone;
    for (const TraceEvent& event : *events) {
      if (event.kind != TraceEvent::Kind::kMotion) continue;
      const Target& target = state.targets[event.target];
      if (IsPick(target, ir::PickPlaceKind::Pick)) {
        traced[event.target] = true;
        picked = builder.RowOf(event.target);
        builder.Pick(picked);
      } else if (IsPick(target, ir::PickPlaceKind::Place) && picked != kNone) {
        builder.AddPart(picked, target.text);
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
        builder.AddPart(row, state.targets[next].text);
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

std::string SetupSheetText(const SetupSheet& sheet) {
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
  out += "\n";
  const std::vector<std::string> head = {"feeder", "kind", "slot", "count", "value", "package", "parts"};
  std::vector<std::vector<std::string>> rows;
  for (const SetupSlot& slot : sheet.slots) {
    std::string parts = Joined(slot.designators, ", ");
    if (!slot.note.empty()) parts += (parts.empty() ? "(" : " (") + slot.note + ")";
    rows.push_back({Printable(slot.feeder), slot.feeder_kind.empty() ? "-" : slot.feeder_kind, SlotText(slot),
                    std::to_string(slot.count), Printable(Joined(slot.values, " / ")),
                    Printable(Joined(slot.packages, " / ")), parts});
  }
  std::vector<std::size_t> width(head.size());
  for (std::size_t c = 0; c + 1 < head.size(); ++c) {
    width[c] = Columns(head[c]);
    for (const auto& row : rows) width[c] = std::max(width[c], Columns(row[c]));
  }
  auto line = [&](const std::vector<std::string>& cells) {
    std::string text;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      text += c + 1 < cells.size() ? Padded(cells[c], width[c] + 2) : cells[c];
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text + "\n";
  };
  out += line(head);
  for (const auto& row : rows) out += line(row);
  return out;
}

std::string SetupSheetCsv(const SetupSheet& sheet) {
  std::string out =
      "feeder,kind,slot_kind,slot,count,value,package,parts,pick_x_mm,pick_y_mm,pick_z_mm,pick_u_deg,note\n";
  for (const SetupSlot& slot : sheet.slots) {
    const std::string pick = slot.pick_known ? fmt::format("{},{},{},{}", slot.pick[0], slot.pick[1], slot.pick[2],
                                                            slot.pick[3])
                                             : std::string(",,,");
    out += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", CsvField(Printable(slot.feeder)), slot.feeder_kind,
                       slot.slot_kind, slot.slot, slot.count, CsvField(Printable(Joined(slot.values, " / "))),
                       CsvField(Printable(Joined(slot.packages, " / "))), CsvField(Joined(slot.designators, ", ")),
                       pick, CsvField(slot.note));
  }
  return out;
}

}  // namespace smtcal
