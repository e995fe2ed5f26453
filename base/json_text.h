// JSON as smtcal writes it (reports, summaries, scans) and reads it (the
// previous scan of `smtcal fixture --previous`).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace smtcal {

// Two-space indented JSON with a final newline. Text that is not UTF-8 (a
// file name is any bytes on Linux) is written with U+FFFD in place of each
// invalid byte, as the diagnostics printer does, instead of throwing. Every
// floating-point number is written with the shortest digits that read back
// as it (nlohmann alone sometimes writes 0.059409 as 0.059408999999999997),
// so a number rounded with RoundedToDecimals shows exactly its decimals.
std::string JsonText(const nlohmann::ordered_json& json);
std::string JsonText(const nlohmann::json& json);

// A parsed JSON text, or where and why it is not JSON: a syntax error or a
// number beyond the range of a double (1e400).
struct JsonParse {
  std::optional<nlohmann::ordered_json> value;
  std::size_t error_offset = 0;  // the byte at which the parser stopped
  std::string error;             // "syntax error while parsing value - ...", without nlohmann's prefix
};
JsonParse ParseJson(std::string_view text);

}  // namespace smtcal
