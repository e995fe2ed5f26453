// The import report (see import_report.h).
#include "backend/reports/import_report.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "base/field_text.h"
#include "base/json_text.h"

namespace smtcal {

using nlohmann::ordered_json;

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

}  // namespace smtcal
