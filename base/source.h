// Source files and locations. Every IR node and every diagnostic carries a
// SourceLoc; the SourceManager owns the text so diagnostics can quote lines.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "base/result.h"

namespace smtcal {

struct SourceLoc {
  std::uint32_t file = 0;    // index into SourceManager; 0 = no file
  std::uint32_t line = 0;    // 1-based; 0 = unknown
  std::uint32_t column = 0;  // 1-based, in bytes

  bool known() const { return file != 0 && line != 0; }
  friend bool operator==(const SourceLoc&, const SourceLoc&) = default;
};

struct SourceFile {
  std::string name;  // as the user gave it (or "<stdin>")
  std::string text;
  std::vector<std::size_t> line_starts;  // byte offset of each line

  std::string_view Line(std::uint32_t line) const;  // without the newline
};

class SourceManager {
 public:
  // Registers text under a name; returns its id (never 0).
  std::uint32_t Add(std::string name, std::string text);
  // Reads a file ("-" is stdin) and registers it.
  Result<std::uint32_t> Load(const std::string& path);

  const SourceFile& File(std::uint32_t id) const;

 private:
  std::vector<std::unique_ptr<SourceFile>> files_;
};

// Writes `contents` to `path` atomically: a temporary file beside it, then a
// rename, so a failure never leaves a half-written output. "-" is stdout.
Status WriteFileAtomically(const std::string& path, std::string_view contents);

}  // namespace smtcal
