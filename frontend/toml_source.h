// Locations and type names in a TOML file for diagnostics, shared by the
// cell, feeders and truth loaders: toml++ counts columns in code points
// (after a byte order mark), SourceLoc counts bytes from the start of the line.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

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
  SourceLoc At(const toml::source_position& position) const {
    if (position.line == 0) return SourceLoc{file_, 0, 0};
    std::string_view line = sources_.File(file_).Line(position.line);
    std::size_t byte = position.line == 1 && line.starts_with("\xEF\xBB\xBF") ? 3 : 0;
    for (std::uint32_t code_point = 1; code_point < position.column && byte < line.size(); ++code_point) {
      ++byte;
      while (byte < line.size() && (static_cast<unsigned char>(line[byte]) & 0xc0) == 0x80) ++byte;
    }
    return SourceLoc{file_, position.line, static_cast<std::uint32_t>(byte + 1)};
  }
  // The region on its first line (a region over several lines: its start).
  SourceRange Range(const toml::source_region& region) const {
    SourceLoc begin = At(region.begin);
    if (region.end.line != region.begin.line || region.end.column <= region.begin.column) return SourceRange(begin);
    return SourceRange(begin, At(region.end).column - begin.column);
  }
  SourceRange Range(const toml::node& node) const { return Range(node.source()); }

 private:
  const SourceManager& sources_;
  std::uint32_t file_;
};

}  // namespace smtcal
