// Mistakes in the user's input. Each kind is declared once in
// diagnostic_kinds.def with its severity and message format; the code that
// finds the mistake reports it with typed arguments. Rendering (GCC/Clang text
// with the source line and a caret, or JSON) is separate from collecting.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "base/source.h"

namespace smtcal {

enum class DiagKind : std::uint16_t {
#define DIAG(name, severity, format) name,
#include "base/diagnostic_kinds.def"
#undef DIAG
};

enum class Severity { Note, Warning, Error };

std::string_view DiagKindName(DiagKind kind);
Severity DiagKindSeverity(DiagKind kind);
std::string_view DiagKindFormat(DiagKind kind);
std::string_view SeverityName(Severity severity);

// A location plus how many bytes the caret underline covers.
struct SourceRange {
  SourceLoc begin;
  std::uint32_t length = 1;
  SourceRange() = default;
  SourceRange(SourceLoc loc, std::uint32_t len = 1) : begin(loc), length(len == 0 ? 1 : len) {}
};

struct Diagnostic {
  DiagKind kind;
  Severity severity;
  SourceRange range;
  std::string message;
  std::vector<std::pair<SourceRange, std::string>> notes;  // "note:" lines after it
};

class Diagnostics {
 public:
  // After `error_limit` errors a TooManyErrors marker ends the list; after
  // `warning_limit` warnings a TooManyWarnings marker stands for the rest,
  // which are counted but not kept.
  explicit Diagnostics(const SourceManager& sources, std::size_t error_limit = 50, std::size_t warning_limit = 100)
      : sources_(sources), error_limit_(error_limit), warning_limit_(warning_limit) {}

  // A diagnostic past the limits is counted without being formatted, so a
  // loop that reports the same mistake a million times costs no more than
  // counting it.
  template <typename... Args>
  Diagnostic* Report(DiagKind kind, SourceRange range, const Args&... args) {
    if (!Keeps(kind)) return Add(kind, range, std::string());
    return Add(kind, range, fmt::vformat(DiagKindFormat(kind), fmt::make_format_args(args...)));
  }
  // Attaches a note to the diagnostic returned by Report (ignored if null:
  // Report returns null once the error or warning limit is reached).
  // Messages and notes are made valid UTF-8 and cut after kMaxMessageBytes
  // (base/field_text.h), whatever they quote.
  static void AddNote(Diagnostic* diag, SourceRange range, std::string_view text);

  std::size_t error_count() const { return error_count_; }
  std::size_t warning_count() const { return warning_count_; }
  bool has_errors() const { return error_count_ > 0; }
  bool limit_reached() const { return limit_reached_; }
  const std::vector<Diagnostic>& all() const { return diagnostics_; }
  const SourceManager& sources() const { return sources_; }

  // Both renderings list the diagnostics in source order (file, line,
  // column), not in the order the passes found them.
  // GCC/Clang style: "file:line:col: error: message", the source line, a caret.
  std::string RenderText() const;
  // The same as a JSON array of objects (kind, severity, file, line, column,
  // length, message, notes).
  std::string RenderJson() const;

 private:
  // Whether a diagnostic of `kind` reported now would be kept (shown).
  bool Keeps(DiagKind kind) const;
  Diagnostic* Add(DiagKind kind, SourceRange range, std::string message);
  static std::string Printed(std::string_view message);

  const SourceManager& sources_;
  std::size_t error_limit_;
  std::size_t warning_limit_;
  std::size_t error_count_ = 0;
  std::size_t warning_count_ = 0;
  bool limit_reached_ = false;
  std::vector<Diagnostic> diagnostics_;
};

// "did you mean 'X'?" helper: the closest candidate by edit distance
// (case-insensitive), or empty when nothing is close enough.
std::string ClosestName(std::string_view name, const std::vector<std::string>& candidates);

}  // namespace smtcal
