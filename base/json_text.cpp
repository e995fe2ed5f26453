// JSON text (base/json_text.h).
#include "base/json_text.h"

#include <charconv>
#include <cstdlib>
#include <string_view>
#include <system_error>

namespace smtcal {
namespace {

using nlohmann::ordered_json;

// nlohmann's DOM builder, but a parse error (or an out-of-range number,
// which nlohmann reports through the same call) records where it happened
// instead of throwing. sax_parse calls the handler's methods directly, so
// this parse_error is the one it calls.
class DomParserWithPosition : public nlohmann::detail::json_sax_dom_parser<ordered_json> {
 public:
  explicit DomParserWithPosition(ordered_json& root) : json_sax_dom_parser(root, /*allow_exceptions=*/false) {}

  template <typename Exception>
  bool parse_error(std::size_t position, const std::string& /*last_token*/, const Exception& error) {
    offset = position == 0 ? 0 : position - 1;  // position counts the bytes read, the bad one included
    message = error.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 2: text": we give the place ourselves.
    if (std::size_t bracket = message.find("] "); message.starts_with("[json.exception.") && bracket != std::string::npos) {
      message.erase(0, bracket + 2);
    }
    if (std::size_t colon = message.find(": "); message.starts_with("parse error") && colon != std::string::npos) {
      message.erase(0, colon + 2);
    }
    return false;
  }

  std::size_t offset = 0;
  std::string message;
};

// A double as nlohmann writes it (".0" on integral values, plain from 1e-4
// to below 1e15, else d.ddde-05), but from the shortest digits that read
// back as it: nlohmann's Grisu2 sometimes gives more (0.059409 as
// 0.059408999999999997), and a number rounded to its meaning must print as
// its decimals.
std::string ShortestNumber(double value) {
  char buffer[64];
  // "d.ddde-05": the shortest round-trip digits in scientific form.
  const std::to_chars_result written =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::scientific);
  std::string text(buffer, written.ptr);
  std::string sign;
  if (text.front() == '-') {
    sign = "-";
    text.erase(0, 1);
  }
  const std::size_t e = text.find('e');
  std::string digits = text.substr(0, e);
  if (digits.size() > 1) digits.erase(1, 1);  // the '.'
  const int k = static_cast<int>(digits.size());
  const int n = std::atoi(text.c_str() + e + 1) + 1;  // where the decimal point goes
  constexpr int kMinExp = -4, kMaxExp = 15;           // nlohmann's to_chars
  if (k <= n && n <= kMaxExp) return sign + digits + std::string(static_cast<std::size_t>(n - k), '0') + ".0";
  if (0 < n && n <= kMaxExp) {
    const std::size_t point = static_cast<std::size_t>(n);
    return sign + digits.substr(0, point) + "." + digits.substr(point);
  }
  if (kMinExp < n && n <= 0) return sign + "0." + std::string(static_cast<std::size_t>(-n), '0') + digits;
  const int exponent = n - 1;
  std::string mantissa = k == 1 ? digits : digits.substr(0, 1) + "." + digits.substr(1);
  return sign + mantissa + "e" + (exponent < 0 ? "-" : "+") + (std::abs(exponent) < 10 ? "0" : "") +
         std::to_string(std::abs(exponent));
}

// nlohmann's text with every floating-point number (a token outside a string
// with '.' or an exponent) rewritten by ShortestNumber.
std::string WithShortestNumbers(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '"') {  // a string, escapes included
      std::size_t end = i + 1;
      while (end < text.size() && text[end] != '"') end += text[end] == '\\' ? 2 : 1;
      out.append(text, i, end + 1 - i);
      i = end + 1;
      continue;
    }
    if (c == '-' || (c >= '0' && c <= '9')) {
      std::size_t end = i + 1;
      while (end < text.size() && std::string_view("0123456789.eE+-").find(text[end]) != std::string_view::npos) ++end;
      const std::string_view token(text.data() + i, end - i);
      double value = 0;
      if (token.find_first_of(".eE") != std::string_view::npos &&
          std::from_chars(token.data(), token.data() + token.size(), value).ec == std::errc()) {
        out += ShortestNumber(value);
      } else {
        out += token;
      }
      i = end;
      continue;
    }
    out += c;
    ++i;
  }
  return out;
}

}  // namespace

std::string JsonText(const ordered_json& json) {
  return WithShortestNumbers(json.dump(2, ' ', false, ordered_json::error_handler_t::replace)) + "\n";
}

std::string JsonText(const nlohmann::json& json) {
  return WithShortestNumbers(json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)) + "\n";
}

JsonParse ParseJson(std::string_view text) {
  ordered_json root;
  DomParserWithPosition handler(root);
  JsonParse result;
  if (ordered_json::sax_parse(text, &handler) && handler.message.empty()) {
    result.value = std::move(root);
  } else {
    result.error_offset = handler.offset;
    result.error = handler.message.empty() ? "it is not JSON" : handler.message;
  }
  return result;
}

}  // namespace smtcal
