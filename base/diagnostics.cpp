#include "base/diagnostics.h"

#include <algorithm>
#include <cctype>
#include <tuple>

#include <nlohmann/json.hpp>

#include "base/field_text.h"

namespace smtcal {
namespace {

struct KindInfo {
  std::string_view name;
  Severity severity;
  std::string_view format;
};

constexpr KindInfo kKinds[] = {
#define DIAG(name, severity, format) {#name, Severity::severity, format},
#include "base/diagnostic_kinds.def"
#undef DIAG
};

const KindInfo& Info(DiagKind kind) { return kKinds[static_cast<std::size_t>(kind)]; }

std::string Location(const SourceManager& sources, const SourceRange& range) {
  if (range.begin.file == 0) return "smtcal";
  const std::string name = Printable(sources.File(range.begin.file).name);
  if (range.begin.line == 0) return name;
  return fmt::format("{}:{}:{}", name, range.begin.line, range.begin.column);
}

// A source line longer than this many bytes is quoted as a window around
// the caret, with "..." where it is cut: a 2 MB CSV header line must not
// make a message of 2 MB. Program lines of a few hundred bytes stay whole.
constexpr std::size_t kSnippetMaxBytes = 320;
constexpr std::size_t kSnippetBytesBeforeCaret = 120;
constexpr std::string_view kEllipsis = "...";

bool IsContinuationByte(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

// The quoted source line and a caret line under the range. The line is made
// safe for a terminal (Printable's kSourceLine: control characters and
// invalid UTF-8 bytes become '?'), and the caret line advances one column per
// character, not per byte, so the caret sits under the right character in
// UTF-8 text. Tabs are kept.
void AppendSnippet(std::string& out, const SourceManager& sources, const SourceRange& range) {
  if (!range.begin.known()) return;
  std::string_view line = sources.File(range.begin.file).Line(range.begin.line);
  std::size_t begin = range.begin.column == 0 ? 0 : range.begin.column - 1;
  std::size_t end = begin + std::max<std::uint32_t>(range.length, 1);
  // The part of the line shown: all of it, or a window that starts
  // kSnippetBytesBeforeCaret before the caret, at a character boundary.
  std::size_t from = 0, to = line.size();
  if (line.size() > kSnippetMaxBytes) {
    std::size_t caret = std::min(begin, line.size());
    from = caret > kSnippetBytesBeforeCaret ? caret - kSnippetBytesBeforeCaret : 0;
    while (from > 0 && IsContinuationByte(line[from])) --from;
    to = std::min(line.size(), from + kSnippetMaxBytes);
    while (to < line.size() && IsContinuationByte(line[to])) ++to;
  }
  std::string shown(from > 0 ? kEllipsis : "");
  shown += Printable(line.substr(from, to - from), TextQuoting::kSourceLine);
  std::string marks(from > 0 ? kEllipsis.size() : 0, ' ');
  bool caret_placed = false;
  for (std::size_t i = from; i < to;) {  // one mark per character Printable shows
    std::size_t step = std::max<std::size_t>(Utf8Length(line, i), 1);
    char mark = line[i] == '\t' ? '\t' : ' ';
    if (i + step > begin && i < end) mark = caret_placed ? '~' : '^';
    if (mark == '^') caret_placed = true;
    marks += mark;
    i += step;
  }
  if (to < line.size()) shown += kEllipsis;
  if (!caret_placed) marks += '^';  // the range starts at the end of the line
  while (!marks.empty() && (marks.back() == ' ' || marks.back() == '\t')) marks.pop_back();
  out += fmt::format("  {}\n  {}\n", shown, marks);
}

// Diagnostics in source order (file, line, column), whatever pass found them;
// equal locations keep the order they were reported in. Diagnostics about a
// whole file (no line) follow that file's located ones, and the
// too-many-errors and too-many-warnings markers stay last: both are summaries.
std::vector<const Diagnostic*> InSourceOrder(const std::vector<Diagnostic>& diagnostics) {
  std::vector<const Diagnostic*> sorted;
  for (const Diagnostic& diag : diagnostics) sorted.push_back(&diag);
  std::stable_sort(sorted.begin(), sorted.end(), [](const Diagnostic* a, const Diagnostic* b) {
    bool a_last = a->kind == DiagKind::TooManyErrors || a->kind == DiagKind::TooManyWarnings;
    bool b_last = b->kind == DiagKind::TooManyErrors || b->kind == DiagKind::TooManyWarnings;
    if (a_last != b_last) return b_last;
    const SourceLoc& x = a->range.begin;
    const SourceLoc& y = b->range.begin;
    bool x_whole_file = x.line == 0;
    bool y_whole_file = y.line == 0;
    return std::tie(x.file, x_whole_file, x.line, x.column) <
           std::tie(y.file, y_whole_file, y.line, y.column);
  });
  return sorted;
}

}  // namespace

// A message quotes fields of the input: whatever a reader forgot to quote
// becomes valid UTF-8 here (docs/files-and-exit-codes.md), and a 2 MB column
// name must not make a 2 MB message.
std::string Diagnostics::Printed(std::string_view message) {
  return CutForMessage(Printable(message, TextQuoting::kMessage));
}

void Diagnostics::AddNote(Diagnostic* diag, SourceRange range, std::string_view text) {
  if (diag != nullptr) diag->notes.emplace_back(range, Printed(text));
}

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

bool Diagnostics::Keeps(DiagKind kind) const {
  if (limit_reached_) return false;
  switch (DiagKindSeverity(kind)) {
    case Severity::Error: return error_count_ < error_limit_;
    case Severity::Warning: return warning_count_ < warning_limit_;
    case Severity::Note: return true;
  }
  return true;
}

// Every diagnostic is counted, kept or not: a reader that asks whether its
// part of the input had an error (error_count() before and after) gets the
// truth after the limit too. Constant time per diagnostic. Whether it is
// kept is Keeps' rule; the first error and the first warning past their
// limits leave a marker in its place.
Diagnostic* Diagnostics::Add(DiagKind kind, SourceRange range, std::string message) {
  const Severity severity = DiagKindSeverity(kind);
  const bool keep = Keeps(kind);
  if (severity == Severity::Error) {
    if (!keep && !limit_reached_) {
      limit_reached_ = true;
      diagnostics_.push_back({DiagKind::TooManyErrors, Severity::Error, range,
                              fmt::format("too many errors ({}); stopping here", error_count_), {}});
    }
    ++error_count_;
  } else if (severity == Severity::Warning) {
    // Counted (the summaries say how many), but past the limit no longer shown.
    if (++warning_count_ == warning_limit_ + 1 && !limit_reached_) {
      diagnostics_.push_back({DiagKind::TooManyWarnings, Severity::Warning, range,
                              fmt::format("more than {} warnings; the others are counted but not shown",
                                          warning_limit_),
                              {}});
    }
  }
  if (!keep) return nullptr;
  diagnostics_.push_back({kind, severity, range, Printed(message), {}});
  return &diagnostics_.back();
}

std::string Diagnostics::RenderText() const {
  std::string out;
  for (const Diagnostic* sorted : InSourceOrder(diagnostics_)) {
    const Diagnostic& diag = *sorted;
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
  for (const Diagnostic* sorted : InSourceOrder(diagnostics_)) {
    const Diagnostic& diag = *sorted;
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
  // replace: a message quoting invalid UTF-8 from the input must not throw.
  return list.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
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
