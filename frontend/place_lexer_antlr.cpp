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

std::vector<PlaceToken> LexPlaceWithAntlr(std::string_view text) {
  ByteStream stream(text);
  grammar::PlaceLexer lexer(&stream);
  lexer.removeErrorListeners();  // BAD_CHAR takes every byte: nothing to report
  std::vector<PlaceToken> tokens;
  for (;;) {
    std::unique_ptr<antlr4::Token> token = lexer.nextToken();
    const bool eof = token->getType() == antlr4::Token::EOF;
    PlaceToken out;
    out.start = static_cast<std::uint32_t>(token->getStartIndex());
    out.length = eof ? 0 : static_cast<std::uint32_t>(token->getStopIndex() - token->getStartIndex() + 1);
    out.line = static_cast<std::uint32_t>(token->getLine());
    out.column = static_cast<std::uint32_t>(token->getCharPositionInLine());
    out.type = eof ? kPlaceEof : static_cast<int>(token->getType());
    tokens.push_back(out);
    if (eof) return tokens;
  }
}

std::string PlaceTokenName(int type) {
  if (type == kPlaceEof) return "EOF";
  static ByteStream empty("");
  static grammar::PlaceLexer lexer(&empty);
  return lexer.getVocabulary().getSymbolicName(static_cast<std::size_t>(type));
}

}  // namespace smtcal
