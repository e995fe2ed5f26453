// The .place lexer: a file's bytes to compact tokens, written by hand.
//
// It makes exactly the tokens of grammar/Place.g4's lexer rules (the types
// are the grammar's token types; COMMENT and NEWLINE included, WS skipped, a
// byte no rule takes is a BAD_CHAR), in 16 bytes a token instead of ANTLR's
// 112-byte CommonToken and without ANTLR's copy of the input as UTF-32. The
// generated lexer is kept as the reference: LexPlaceWithAntlr gives its
// tokens in the same form, and a differential test holds the two equal.
//
// Positions are bytes: a UTF-8 character of several bytes is several
// BAD_CHARs (outside comments a program is ASCII), columns count bytes, and a
// UTF-8 byte order mark at the start is skipped like white space.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace smtcal {

struct PlaceToken {
  std::uint32_t start = 0;   // offset of its first byte; the file's size for the end-of-file token
  std::uint32_t length = 0;  // bytes; 0 for the end-of-file token
  std::uint32_t line = 1;    // 1-based
  int type = 0;              // the grammar's token type; kPlaceEof at the end
  friend bool operator==(const PlaceToken&, const PlaceToken&) = default;
};

// The end-of-file token's type (ANTLR's Token::EOF).
inline constexpr int kPlaceEof = -1;

// A file's tokens, white space left out, the end-of-file token last, and
// where its lines start.
struct LexedPlace {
  std::vector<PlaceToken> tokens;
  std::vector<std::uint32_t> line_starts;  // [line]: offset of the line's first byte; [0] unused
  // 0-based, in bytes (ANTLR's charPositionInLine).
  std::uint32_t Column(const PlaceToken& token) const { return token.start - line_starts[token.line]; }
};

// The tokens of `text`. A file of 4 GiB or more is beyond 32-bit offsets:
// the caller refuses it.
LexedPlace LexPlace(std::string_view text);

// The same through the ANTLR-generated PlaceLexer: the reference for tests.
// Its line starts are where ANTLR's columns put them (a line whose tokens
// disagree about it gets UINT32_MAX).
LexedPlace LexPlaceWithAntlr(std::string_view text);

// The grammar's name of a token type ("PICK", "NUMBER", "EOF"), for tests.
std::string PlaceTokenName(int type);

}  // namespace smtcal
