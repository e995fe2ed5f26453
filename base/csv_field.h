// One field of a CSV file smtcal writes (RFC 4180): quoted when it holds a
// comma, a quote or a line end, a quote inside doubled. The one
// implementation for every CSV output (set-up sheets, monitor --csv).
#pragma once

#include <string>
#include <string_view>

namespace smtcal {

inline std::string CsvField(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace smtcal
