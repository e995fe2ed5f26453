// Locations and type names in a TOML file for diagnostics, shared by the
// cell, feeders and truth loaders: toml++ counts columns in code points
// (after a byte order mark), SourceLoc counts bytes from the start of the line.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "base/diagnostics.h"
#include "base/source.h"

namespace smtcal {

// "a string", "an integer", ...: what a value is, for "expected X, found Y".
inline std::string_view TomlTypeName(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date or time";
  }
}

// The value of a number node (is_number()): an integer as the double nearest
// to it (toml++'s value<double>() gives none for an integer it cannot hold
// exactly), a float as it is.
inline double TomlNumber(const toml::node& node) {
  if (node.is_integer()) return static_cast<double>(*node.value<std::int64_t>());
  return *node.value<double>();
}
// ... and as a message quotes it: an integer as written (9223372036854775807,
// not 9.223372036854776e+18), a float in its shortest form (-0 as -0).
inline std::string TomlNumberText(const toml::node& node) {
  if (node.is_integer()) return std::to_string(*node.value<std::int64_t>());
  return fmt::format("{}", *node.value<double>());
}

class TomlLocator {
 public:
  TomlLocator(const SourceManager& sources, std::uint32_t file) : sources_(sources), file_(file) {}

  // An unknown position (line 0) gives a location in the file without a line.
  // Constant time per position: the byte offsets of a line's code points are
  // found once per line (a line may hold 100 000 numbers of one array).
  SourceLoc At(const toml::source_position& position) const {
    if (position.line == 0) return SourceLoc{file_, 0, 0};
    if (position.line != indexed_line_) IndexLine(position.line);
    const std::size_t code_point = position.column == 0 ? 0 : position.column - 1;
    const std::uint32_t byte = code_point < starts_.size() ? starts_[code_point] : starts_.back();
    return SourceLoc{file_, position.line, byte + 1};
  }
  // The region on its first line (a region over several lines: its start).
  SourceRange Range(const toml::source_region& region) const {
    SourceLoc begin = At(region.begin);
    if (region.end.line != region.begin.line || region.end.column <= region.begin.column) return SourceRange(begin);
    return SourceRange(begin, At(region.end).column - begin.column);
  }
  SourceRange Range(const toml::node& node) const { return Range(node.source()); }

 private:
  // starts_[i]: the byte of code point i + 1 of line `line` (after a byte
  // order mark on line 1); its last entry is the line's end.
  void IndexLine(std::uint32_t line_number) const {
    std::string_view line = sources_.File(file_).Line(line_number);
    std::size_t byte = line_number == 1 && line.starts_with("\xEF\xBB\xBF") ? 3 : 0;
    starts_.clear();
    while (byte < line.size()) {
      starts_.push_back(static_cast<std::uint32_t>(byte));
      ++byte;
      while (byte < line.size() && (static_cast<unsigned char>(line[byte]) & 0xc0) == 0x80) ++byte;
    }
    starts_.push_back(static_cast<std::uint32_t>(byte));
    indexed_line_ = line_number;
  }

  const SourceManager& sources_;
  std::uint32_t file_;
  mutable std::uint32_t indexed_line_ = 0;
  mutable std::vector<std::uint32_t> starts_;
};

}  // namespace smtcal
