// JSON text (base/json_text.h).
#include "base/json_text.h"

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

}  // namespace

std::string JsonText(const ordered_json& json) {
  return json.dump(2, ' ', false, ordered_json::error_handler_t::replace) + "\n";
}

std::string JsonText(const nlohmann::json& json) {
  return json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
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
