// The import report and the feeder set-up sheet (see import_report.h).
#include "backend/reports/import_report.h"

#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "base/field_text.h"
#include "base/json_text.h"

namespace smtcal {
namespace {

using nlohmann::ordered_json;

std::string Joined(const std::vector<std::string>& items, std::string_view separator) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : std::string(separator)) + item;
  return text;
}

// "lane 3", "pocket 12", or "-" for a feeder's single pick point.
std::string SlotText(const SetupSlot& slot) {
  return slot.slot_kind.empty() ? std::string("-") : fmt::format("{} {}", slot.slot_kind, slot.slot);
}

// One CSV field (RFC 4180): quoted when it holds a comma, a quote or a line end.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
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

std::string ImportReportJson(const ImportSummary& summary, const std::vector<RowFate>& fates,
                             const std::string& list_name) {
  ordered_json out;
  out["list"] = list_name;
  out["format"] = summary.format;
  out["rows_read"] = summary.rows_read;
  out["placed"] = summary.parts_placed;
  out["boards"] = summary.boards;
  out["side"] = cad::SideName(summary.placed_side);
  std::size_t skipped = 0;
  for (std::size_t n : summary.skipped) skipped += n;
  out["skipped"] = skipped;
  out["board"] = {{"outline", summary.outline},
                  {"origin_mm", {summary.origin_x_mm, summary.origin_y_mm}},
                  {"origin_from", summary.origin_how}};
  out["skip_groups"] = ordered_json::array();
  for (const SkipGroup& group : summary.skip_groups) {
    out["skip_groups"].push_back({{"reason", SkipReasonName(group.reason)},
                                  {"rule", group.why},
                                  {"count", group.names.size()},
                                  {"designators", group.names}});
  }
  out["rows"] = ordered_json::array();
  for (const RowFate& fate : fates) {
    ordered_json row = {{"line", fate.row.line}};
    if (fate.reason == SkipReason::kNoDesignator) {
      row["fate"] = "skipped";
      row["reason"] = SkipReasonName(fate.reason);
      row["rule"] = fate.why;
      out["rows"].push_back(std::move(row));
      continue;
    }
    row["designator"] = Printable(fate.row.designator);
    row["value"] = Printable(fate.row.value);
    row["package"] = Printable(fate.row.package);
    row["side"] = cad::SideName(fate.row.side);
    row["x_mm"] = fate.row.x_mm;
    row["y_mm"] = fate.row.y_mm;
    row["rotation_deg"] = fate.row.rotation_deg;
    row["fate"] = fate.placed ? "placed" : "skipped";
    if (fate.placed) {
      row["feeder"] = Printable(fate.feeder);
      if (!fate.slot_kind.empty()) row[fate.slot_kind] = fate.slot;
      row["point"] = fate.point;
      row["board_xyu"] = fate.board_xyu;
    } else {
      row["reason"] = SkipReasonName(fate.reason);
      row["rule"] = fate.why;
    }
    out["rows"].push_back(std::move(row));
  }
  return JsonText(out);
}

std::string SetupSheetText(const SetupSheet& sheet) {
  std::size_t parts = 0;
  std::vector<std::string> feeders;
  for (const SetupSlot& slot : sheet.slots) {
    parts += slot.count;
    if (std::find(feeders.begin(), feeders.end(), slot.feeder) == feeders.end()) feeders.push_back(slot.feeder);
  }
  std::string out = fmt::format("Feeder set-up for program {} (fixture {}{}): {} placement{} per cycle from {} "
                                "feeder{}\n\n",
                                sheet.program, sheet.fixture,
                                sheet.boards > 1 ? fmt::format(", {} boards", sheet.boards) : std::string(), parts,
                                parts == 1 ? "" : "s", feeders.size(), feeders.size() == 1 ? "" : "s");
  const std::vector<std::string> head = {"feeder", "kind", "slot", "count", "value", "package", "parts"};
  std::vector<std::vector<std::string>> rows;
  for (const SetupSlot& slot : sheet.slots) {
    rows.push_back({Printable(slot.feeder), slot.feeder_kind, SlotText(slot), std::to_string(slot.count),
                    Printable(Joined(slot.values, " / ")), Printable(Joined(slot.packages, " / ")),
                    Joined(slot.designators, " ")});
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
  std::string out = "feeder,kind,slot_kind,slot,count,value,package,designators,pick_x_mm,pick_y_mm,pick_z_mm,pick_u_deg\n";
  for (const SetupSlot& slot : sheet.slots) {
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", CsvField(Printable(slot.feeder)), slot.feeder_kind,
                       slot.slot_kind, slot.slot, slot.count, CsvField(Printable(Joined(slot.values, " / "))),
                       CsvField(Printable(Joined(slot.packages, " / "))), CsvField(Joined(slot.designators, " ")),
                       slot.pick[0], slot.pick[1], slot.pick[2], slot.pick[3]);
  }
  return out;
}

}  // namespace smtcal
