#include "frontend/diagnostics.h"

#include <algorithm>
#include <cctype>

#include <nlohmann/json.hpp>

namespace smtcal {
namespace {

struct KindInfo {
  std::string_view name;
  Severity severity;
  std::string_view format;
};

constexpr KindInfo kKinds[] = {
#define DIAG(name, severity, format) {#name, Severity::severity, format},
#include "frontend/diagnostic_kinds.def"
#undef DIAG
};

const KindInfo& Info(DiagKind kind) { return kKinds[static_cast<std::size_t>(kind)]; }

std::string Location(const SourceManager& sources, const SourceRange& range) {
  if (range.begin.file == 0) return "smtcal";
  const SourceFile& file = sources.File(range.begin.file);
  if (range.begin.line == 0) return file.name;
  return fmt::format("{}:{}:{}", file.name, range.begin.line, range.begin.column);
}

// The quoted source line and a caret line under the range. Tabs are kept in
// the caret line so the caret lines up in a terminal.
void AppendSnippet(std::string& out, const SourceManager& sources, const SourceRange& range) {
  if (!range.begin.known()) return;
  std::string_view line = sources.File(range.begin.file).Line(range.begin.line);
  out += fmt::format("  {}\n  ", line);
  std::uint32_t column = std::max<std::uint32_t>(range.begin.column, 1);
  for (std::uint32_t i = 1; i < column && i - 1 < line.size(); ++i) out += line[i - 1] == '\t' ? '\t' : ' ';
  out += '^';
  std::uint32_t available =
      column - 1 < line.size() ? static_cast<std::uint32_t>(line.size()) - (column - 1) : 1;
  std::uint32_t length = std::min(range.length, std::max<std::uint32_t>(available, 1));
  for (std::uint32_t i = 1; i < length; ++i) out += '~';
  out += '\n';
}

}  // namespace

std::string_view DiagKindName(DiagKind kind) { return Info(kind).name; }
Severity DiagKindSeverity(DiagKind kind) { return Info(kind).severity; }
std::string_view DiagKindFormat(DiagKind kind) { return Info(kind).format; }

std::string_view SeverityName(Severity severity) {
  switch (severity) {
    case Severity::Note: return "note";
    case Severity::Warning: return "warning";
    case Severity::Error: return "error";
  }
  return "error";
}

Diagnostic* Diagnostics::Add(DiagKind kind, SourceRange range, std::string message) {
  if (limit_reached_) return nullptr;
  Severity severity = DiagKindSeverity(kind);
  if (severity == Severity::Error && error_count_ >= error_limit_) {
    limit_reached_ = true;
    diagnostics_.push_back({DiagKind::TooManyErrors, Severity::Error, range,
                            fmt::format("too many errors ({}); stopping here", error_count_), {}});
    ++error_count_;
    return nullptr;
  }
  if (severity == Severity::Error) ++error_count_;
  if (severity == Severity::Warning) ++warning_count_;
  diagnostics_.push_back({kind, severity, range, std::move(message), {}});
  return &diagnostics_.back();
}

std::string Diagnostics::RenderText() const {
  std::string out;
  for (const Diagnostic& diag : diagnostics_) {
    out += fmt::format("{}: {}: {}\n", Location(sources_, diag.range), SeverityName(diag.severity),
                       diag.message);
    AppendSnippet(out, sources_, diag.range);
    for (const auto& [range, text] : diag.notes) {
      out += fmt::format("{}: note: {}\n", Location(sources_, range), text);
      AppendSnippet(out, sources_, range);
    }
  }
  return out;
}

std::string Diagnostics::RenderJson() const {
  auto located = [&](const SourceRange& range) {
    nlohmann::ordered_json j;
    j["file"] = range.begin.file == 0 ? "" : sources_.File(range.begin.file).name;
    j["line"] = range.begin.line;
    j["column"] = range.begin.column;
    j["length"] = range.length;
    return j;
  };
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const Diagnostic& diag : diagnostics_) {
    nlohmann::ordered_json j;
    j["kind"] = DiagKindName(diag.kind);
    j["severity"] = SeverityName(diag.severity);
    j.update(located(diag.range));
    j["message"] = diag.message;
    nlohmann::ordered_json notes = nlohmann::ordered_json::array();
    for (const auto& [range, text] : diag.notes) {
      nlohmann::ordered_json note = located(range);
      note["message"] = text;
      notes.push_back(std::move(note));
    }
    j["notes"] = std::move(notes);
    list.push_back(std::move(j));
  }
  return list.dump(2) + "\n";
}

std::string ClosestName(std::string_view name, const std::vector<std::string>& candidates) {
  auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  auto distance = [&](std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        std::size_t above = row[j];
        std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + cost});
        diagonal = above;
      }
    }
    return row[b.size()];
  };
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(1, name.size() / 3) + 1;
  for (const std::string& candidate : candidates) {
    std::size_t d = distance(name, candidate);
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

}  // namespace smtcal
