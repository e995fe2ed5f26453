// The reference for the hand-written lexer (frontend/place_lexer.h): the
// ANTLR-generated PlaceLexer, its tokens turned into PlaceTokens. Only the
// differential test uses it.
#include <memory>

#include "frontend/place_lexer.h"

// ANTLR's headers #undef the EOF macro of <cstdio>; they come last.
#include "PlaceLexer.h"

namespace smtcal {
namespace {

// Feeds ANTLR the file's bytes, one code point per byte, so ANTLR's columns
// are byte columns and invalid UTF-8 cannot throw. A UTF-8 byte order mark
// becomes three spaces, so it is skipped and columns stay byte columns.
class ByteStream : public antlr4::ANTLRInputStream {
 public:
  explicit ByteStream(std::string_view text) {
    _data.reserve(text.size());
    for (unsigned char c : text) _data.push_back(c);
    if (text.substr(0, 3) == "\xEF\xBB\xBF") _data[0] = _data[1] = _data[2] = U' ';
    p = 0;
  }
};

}  // namespace

LexedPlace LexPlaceWithAntlr(std::string_view text) {
  ByteStream stream(text);
  grammar::PlaceLexer lexer(&stream);
  lexer.removeErrorListeners();  // BAD_CHAR takes every byte: nothing to report
  LexedPlace lexed;
  constexpr std::uint32_t kUnset = UINT32_MAX - 1;
  lexed.line_starts = {0};
  for (;;) {
    std::unique_ptr<antlr4::Token> token = lexer.nextToken();
    const bool eof = token->getType() == antlr4::Token::EOF;
    PlaceToken out;
    out.start = static_cast<std::uint32_t>(token->getStartIndex());
    out.length = eof ? 0 : static_cast<std::uint32_t>(token->getStopIndex() - token->getStartIndex() + 1);
    out.line = static_cast<std::uint32_t>(token->getLine());
    out.type = eof ? kPlaceEof : static_cast<int>(token->getType());
    lexed.tokens.push_back(out);
    // Where ANTLR's column puts the line's start; UINT32_MAX when tokens of
    // one line disagree.
    if (lexed.line_starts.size() <= out.line) lexed.line_starts.resize(out.line + 1, kUnset);
    std::uint32_t start = out.start - static_cast<std::uint32_t>(token->getCharPositionInLine());
    std::uint32_t& line_start = lexed.line_starts[out.line];
    line_start = line_start == kUnset || line_start == start ? start : UINT32_MAX;
    if (eof) break;
  }
  // Lines that hold no token (none: every line ends in a NEWLINE or EOF).
  for (std::uint32_t& start : lexed.line_starts) start = start == kUnset ? UINT32_MAX : start;
  lexed.line_starts[0] = 0;
  return lexed;
}

std::string PlaceTokenName(int type) {
  if (type == kPlaceEof) return "EOF";
  static ByteStream empty("");
  static grammar::PlaceLexer lexer(&empty);
  return lexer.getVocabulary().getSymbolicName(static_cast<std::size_t>(type));
}

}  // namespace smtcal
