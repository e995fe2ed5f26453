// The hand-written .place lexer (frontend/place_lexer.h). Each branch below
// names the grammar/Place.g4 rule it implements; like ANTLR's lexer it takes
// the longest match, and among matches of one length the rule listed first
// (so "Point" is POINT, "Points" is ID).
#include "frontend/place_lexer.h"

#include <algorithm>
#include <array>
#include <string>
#include <utility>

#include "base/check.h"

// The token types, from the generated lexer (no ANTLR type leaves this file).
#include "PlaceLexer.h"

namespace smtcal {
namespace {

using L = grammar::PlaceLexer;

static_assert(kPlaceEof == static_cast<int>(antlr4::Token::EOF));

constexpr bool IsLetter(unsigned char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
constexpr bool IsDigit(unsigned char c) { return c >= '0' && c <= '9'; }
// The bytes an identifier continues with, [a-zA-Z_0-9], as a table: a
// program's bytes are mostly names.
constexpr std::array<bool, 256> kWordByte = [] {
  std::array<bool, 256> table{};
  for (int c = 0; c < 256; ++c) table[c] = IsLetter(static_cast<unsigned char>(c)) || IsDigit(static_cast<unsigned char>(c));
  return table;
}();

// The keywords, as the grammar spells their letters (case-insensitive).
struct Keyword {
  std::string_view lower;
  int type;
};
constexpr std::array<Keyword, 43> kKeywords = {{
    {"program", L::PROGRAM}, {"units", L::UNITS},     {"fixture", L::FIXTURE}, {"local", L::LOCAL},
    {"taught", L::TAUGHT},   {"point", L::POINT},     {"in", L::IN},           {"on", L::ON},
    {"off", L::OFF},         {"xy", L::XY},           {"pallet", L::PALLET},   {"vacuum", L::VACUUM},
    {"integer", L::INTEGER}, {"real", L::REAL},       {"function", L::FUNCTION}, {"fend", L::FEND},
    {"jump", L::JUMP},       {"go", L::GO},           {"move", L::MOVE},       {"limz", L::LIMZ},
    {"pick", L::PICK},       {"place", L::PLACE},     {"wait", L::WAIT},       {"sw", L::SW},
    {"for", L::FOR},         {"to", L::TO},           {"step", L::STEP},       {"next", L::NEXT},
    {"if", L::IF},           {"then", L::THEN},       {"elseif", L::ELSEIF},   {"else", L::ELSE},
    {"endif", L::ENDIF},     {"call", L::CALL},       {"cycle", L::CYCLE},     {"endcycle", L::ENDCYCLE},
    {"scan", L::SCAN},       {"exit", L::EXIT},       {"and", L::AND},         {"or", L::OR},
    {"xor", L::XOR},         {"not", L::NOT},         {"mod", L::MOD},
}};
constexpr std::size_t kLongestKeyword = 8;

// A word of up to 8 letters, lowercased, as one number (the first letter in
// the lowest byte); 0 when the word cannot be a keyword.
std::uint64_t KeywordKey(std::string_view word) {
  if (word.size() < 2 || word.size() > kLongestKeyword) return 0;
  std::uint64_t key = 0;
  for (std::size_t i = 0; i < word.size(); ++i) {
    char c = word[i];
    c = c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
    key |= static_cast<std::uint64_t>(static_cast<unsigned char>(c)) << (8 * i);
  }
  return key;
}

// ID : [a-zA-Z_] [a-zA-Z_0-9]* ; a word spelling a keyword is that keyword.
int WordType(std::string_view word) {
  using Entry = std::pair<std::uint64_t, int>;
  static const std::array<Entry, kKeywords.size()> table = [] {
    std::array<Entry, kKeywords.size()> entries;
    for (std::size_t i = 0; i < kKeywords.size(); ++i) entries[i] = {KeywordKey(kKeywords[i].lower), kKeywords[i].type};
    std::sort(entries.begin(), entries.end());
    return entries;
  }();
  const std::uint64_t key = KeywordKey(word);
  if (key == 0) return L::ID;
  auto it = std::lower_bound(table.begin(), table.end(), Entry{key, 0},
                             [](const Entry& a, const Entry& b) { return a.first < b.first; });
  return it != table.end() && it->first == key ? it->second : L::ID;
}

// NUMBER : DIGIT+ ('.' DIGIT*)? EXPONENT? | '.' DIGIT+ EXPONENT? ;
// EXPONENT : [eE] [+-]? DIGIT+ ;   Returns the end of the longest match at
// `at`, or `at` when there is none.
std::size_t NumberEnd(std::string_view text, std::size_t at) {
  auto digits = [&](std::size_t i) {
    while (i < text.size() && IsDigit(static_cast<unsigned char>(text[i]))) ++i;
    return i;
  };
  std::size_t i = at;
  if (IsDigit(static_cast<unsigned char>(text[i]))) {
    i = digits(i);
    if (i < text.size() && text[i] == '.') i = digits(i + 1);
  } else {  // '.' DIGIT+
    std::size_t end = digits(i + 1);
    if (end == i + 1) return at;
    i = end;
  }
  // The exponent only when digits follow it; else the number ends before 'e'.
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    std::size_t j = i + 1;
    if (j < text.size() && (text[j] == '+' || text[j] == '-')) ++j;
    std::size_t end = digits(j);
    if (end > j) i = end;
  }
  return i;
}

// The one-character and two-character operators and punctuation.
int PunctuationType(std::string_view text, std::size_t at, std::size_t& length) {
  char c = text[at];
  char next = at + 1 < text.size() ? text[at + 1] : '\0';
  length = 1;
  switch (c) {
    case '=': return L::EQ;
    case '<':
      if (next == '>') return length = 2, L::NE;
      if (next == '=') return length = 2, L::LE;
      return L::LT;
    case '>':
      if (next == '=') return length = 2, L::GE;
      return L::GT;
    case ',': return L::COMMA;
    case '(': return L::LPAREN;
    case ')': return L::RPAREN;
    case '+': return L::PLUS;
    case '-': return L::MINUS;
    case '*': return L::STAR;
    case '/': return L::SLASH;
    default: return L::BAD_CHAR;  // BAD_CHAR : . ;  (any other byte)
  }
}

}  // namespace

LexedPlace LexPlace(std::string_view text) {
  SMTCAL_CHECK(text.size() < UINT32_MAX, "the parser refuses files of 4 GiB and more before lexing");
  LexedPlace lexed;
  std::vector<PlaceToken>& tokens = lexed.tokens;
  // Programs have about a token per 3 bytes or fewer. Room reserved but not
  // used is address space, not memory (its pages are never touched), while
  // growing a vector of millions of tokens holds it twice for a moment.
  tokens.reserve(text.size() / 3 + 16);
  lexed.line_starts = {0, 0};  // line 1 starts at 0 (a byte order mark included: its bytes count as columns)
  std::uint32_t line = 1;
  std::size_t i = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // a byte order mark is white space
  auto add = [&](std::size_t start, std::size_t end, int type) {
    tokens.push_back(PlaceToken{static_cast<std::uint32_t>(start), static_cast<std::uint32_t>(end - start), line, type});
  };
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t start = i;
    if (c == ' ' || c == '\t') {  // WS : [ \t]+ -> skip ;
      while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    } else if (c == '\n' || (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n')) {
      i += c == '\r' ? 2 : 1;  // NEWLINE : '\r'? '\n' ;
      add(start, i, L::NEWLINE);
      ++line;
      lexed.line_starts.push_back(static_cast<std::uint32_t>(i));
    } else if (c == '\'') {  // COMMENT : '\'' ~[\r\n]* -> channel(HIDDEN) ;
      while (i < text.size() && text[i] != '\n' && text[i] != '\r') ++i;
      add(start, i, L::COMMENT);
    } else if (IsLetter(c)) {
      while (i < text.size() && kWordByte[static_cast<unsigned char>(text[i])]) ++i;
      add(start, i, WordType(text.substr(start, i - start)));
    } else if (IsDigit(c) || c == '.') {
      i = NumberEnd(text, start);
      if (i == start) {
        ++i;
        add(start, i, L::BAD_CHAR);  // a '.' without digits after it
      } else {
        add(start, i, L::NUMBER);
      }
    } else {
      std::size_t length = 1;
      int type = PunctuationType(text, start, length);
      i += length;
      add(start, i, type);
    }
  }
  add(text.size(), text.size(), kPlaceEof);
  return lexed;
}

}  // namespace smtcal
