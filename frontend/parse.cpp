// The .place parser: source text -> ir::Program, mistakes -> Diagnostics.
//
// Three steps, each working on the output of the one before:
//  1. Lex the whole file into compact tokens (frontend/place_lexer.h, by
//     hand; the generated lexer is only the differential test's reference).
//  2. Check the line structure (PreScan). .place has one statement per line,
//     and blocks open and close with the first word of a line, so block
//     mistakes ("Next" without "For", a missing "EndIf", a Point declared
//     inside a Function) are found here, with messages that name the block.
//     The pre-scan repairs what it reports -- it drops stray lines, closes
//     the blocks left open and cuts over-long expressions -- so the blocks
//     are well nested, every error of ANTLR's stays inside one line, and its
//     recursion depth stays bounded.
//  3. Parse with ANTLR one line at a time: the line's tokens go through one
//     TokenSource (LineTokens) and one token stream to the one parser, the
//     grammar's rule for the line's kind (known from its first word) parses
//     them, the line's IR is built from the rule's labelled elements
//     (IrBuilder), and the line's tokens and parse tree are freed before the
//     next line. Blocks are put together from the pre-scan's nesting
//     (BlockBuilder). Errors are recovered at the end of their line
//     (LineErrorStrategy) and rewritten into plain words from the rule and
//     the expected tokens (SyntaxErrorListener). A statement whose line has
//     a syntax error is dropped, and so is a block whose first line has one.
// All syntax errors are collected, sorted by position and capped, so a file
// of garbage gives a few clear errors. No ANTLR type leaves this file; of
// ANTLR's exceptions only its recognition errors are caught (running out of
// memory is not a syntax error and leaves as std::bad_alloc).
#include "frontend/parse.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "base/field_text.h"
#include "frontend/input_kind.h"
#include "frontend/place_lexer.h"

// ANTLR's headers #undef the EOF macro of <cstdio>; they come after every
// standard header that might include it.
#include "PlaceParser.h"

namespace smtcal {
namespace {

using antlr4::Token;
using grammar::PlaceParser;
using P = grammar::PlaceParser;

// At most this many syntax errors per file; then one "too many" line.
constexpr std::size_t kMaxSyntaxErrors = 10;
// Operators and parentheses allowed in one line. Each one can add a level of
// recursion to ANTLR's expression parser and to every pass that walks the
// expression tree, so a limit keeps 10000 '(' from overflowing the stack.
constexpr int kMaxExpressionSize = 200;
// Blocks (Function, For, If, Cycle) nested deeper than this stop the parse,
// for the same reason.
constexpr std::size_t kMaxBlockDepth = 100;

// ------------------------------------------------------------------ tokens

bool IsKeyword(std::size_t type) { return type >= P::PROGRAM && type <= P::MOD; }

bool IsBinaryOperator(std::size_t type) {
  switch (type) {
    case P::PLUS: case P::MINUS: case P::STAR: case P::SLASH: case P::MOD:
    case P::EQ: case P::NE: case P::LT: case P::GT: case P::LE: case P::GE:
    case P::AND: case P::OR: case P::XOR:
      return true;
    default:
      return false;
  }
}

// How a token type is written in messages: keywords in their canonical
// spelling, punctuation as itself.
std::string_view Spelling(std::size_t type) {
  switch (type) {
    case P::PROGRAM: return "Program";   case P::UNITS: return "Units";
    case P::FIXTURE: return "Fixture";   case P::LOCAL: return "Local";
    case P::TAUGHT: return "Taught";     case P::POINT: return "Point";
    case P::IN: return "In";             case P::ON: return "On";
    case P::OFF: return "Off";           case P::XY: return "XY";
    case P::PALLET: return "Pallet";     case P::VACUUM: return "Vacuum";
    case P::INTEGER: return "Integer";   case P::REAL: return "Real";
    case P::FUNCTION: return "Function"; case P::FEND: return "Fend";
    case P::JUMP: return "Jump";         case P::GO: return "Go";
    case P::MOVE: return "Move";         case P::LIMZ: return "LimZ";
    case P::PICK: return "Pick";         case P::PLACE: return "Place";
    case P::WAIT: return "Wait";         case P::SW: return "Sw";
    case P::FOR: return "For";           case P::TO: return "To";
    case P::STEP: return "Step";         case P::NEXT: return "Next";
    case P::IF: return "If";             case P::THEN: return "Then";
    case P::ELSEIF: return "ElseIf";     case P::ELSE: return "Else";
    case P::ENDIF: return "EndIf";       case P::CALL: return "Call";
    case P::CYCLE: return "Cycle";       case P::ENDCYCLE: return "EndCycle";
    case P::SCAN: return "Scan";         case P::EXIT: return "Exit";
    case P::AND: return "And";           case P::OR: return "Or";
    case P::XOR: return "Xor";           case P::NOT: return "Not";
    case P::MOD: return "Mod";           case P::EQ: return "=";
    case P::NE: return "<>";             case P::LE: return "<=";
    case P::GE: return ">=";             case P::LT: return "<";
    case P::GT: return ">";              case P::COMMA: return ",";
    case P::LPAREN: return "(";          case P::RPAREN: return ")";
    case P::PLUS: return "+";            case P::MINUS: return "-";
    case P::STAR: return "*";            case P::SLASH: return "/";
    default: return "";
  }
}

// An entry of an "expected ..." list.
std::string ExpectedItem(std::size_t type) {
  if (type == Token::EOF) return "end of file";
  if (type == P::NEWLINE) return "end of line";
  if (type == P::ID) return "a name";
  if (type == P::NUMBER) return "a number";
  std::string_view spelling = Spelling(type);
  if (spelling.empty()) return "something else";
  return fmt::format("'{}'", spelling);
}

std::string JoinAlternatives(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += i + 1 == items.size() ? " or " : ", ";
    out += items[i];
  }
  return out;
}

// The keywords that can start a line, for "did you mean" suggestions.
const std::vector<std::string>& StatementKeywords() {
  static const std::vector<std::string> words = {
      "Jump", "Go",   "Move", "Pick", "Place", "On",    "Off",    "Wait",   "For",  "Next", "If",
      "ElseIf", "Else", "EndIf", "Call", "Cycle", "EndCycle", "Scan", "Exit", "Integer", "Real", "Fend"};
  return words;
}
const std::vector<std::string>& DeclarationKeywords() {
  static const std::vector<std::string> words = {"Program", "Units",  "Fixture", "Local",
                                                 "Taught",  "Point",  "Pallet",  "Vacuum",
                                                 "Integer", "Real",   "Function"};
  return words;
}

// A PlaceToken's type as ANTLR numbers it (the end of file is Token::EOF).
std::size_t TypeOf(const PlaceToken& token) {
  return token.type == kPlaceEof ? Token::EOF : static_cast<std::size_t>(token.type);
}

// ------------------------------------------------------------------ the session

struct PendingError {
  SourceLoc loc;
  std::function<Diagnostic*(Diagnostics&)> emit;
  std::vector<std::pair<SourceRange, std::string>> notes;
};

// One source line as the lexer saw it. Its tokens are contiguous in the
// session's token list: the code, then the comment, then the NEWLINE.
struct Line {
  std::uint32_t first = 0;   // the code the parser gets: tokens [first, end)
  std::uint32_t end = 0;
  std::int32_t comment = -1;  // the ' comment's token, if any
  std::int32_t newline = -1;  // the NEWLINE's token; -1 on a last line without one
  bool had_code = false;      // the line held a statement (even if dropped)
  bool error = false;         // a syntax error was reported on this line
  // The blocks the pre-scan closes before this line: closers_[closers_first ..+ closers_count).
  std::uint32_t closers_first = 0;
  std::uint32_t closers_count = 0;
  std::size_t size() const { return end - first; }
  bool empty() const { return end == first; }
};

// A closer (Fend, Next, EndIf, EndCycle) the pre-scan adds where a block
// was left open; it takes the position of the token `at`.
struct Closer {
  std::size_t type;
  std::uint32_t at;  // token index
};

// A block the pre-scan has seen open.
struct OpenBlock {
  std::size_t type;  // FUNCTION, FOR, IF or CYCLE
  std::uint32_t opener;  // token index
  std::string name;  // the function's name
  bool seen_else = false;
};

std::size_t CloserOf(std::size_t opener) {
  switch (opener) {
    case P::FUNCTION: return P::FEND;
    case P::FOR: return P::NEXT;
    case P::IF: return P::ENDIF;
    default: return P::ENDCYCLE;
  }
}

// "Function Main", "the For": how messages name an open block.
std::string Describe(const OpenBlock& open) {
  if (open.type != P::FUNCTION) return fmt::format("the {}", Spelling(open.type));
  return open.name.empty() ? "the Function" : "Function " + open.name;
}

class Session {
 public:
  Session(std::uint32_t file, LexedPlace lexed, Diagnostics& diags)
      : file_(file),
        diags_(diags),
        text_(diags.sources().File(file).text),
        tokens_(std::move(lexed.tokens)),
        line_starts_(std::move(lexed.line_starts)) {}

  ir::Program Run();

  // --- tokens and locations: the lexer's tokens
  const PlaceToken& At(std::uint32_t index) const { return tokens_[index]; }
  std::string_view Text(const PlaceToken& token) const {
    return std::string_view(text_).substr(token.start, token.length);
  }
  std::uint32_t Column(const PlaceToken& token) const { return token.start - line_starts_[token.line]; }
  SourceLoc Loc(const PlaceToken& token) const { return SourceLoc{file_, token.line, Column(token) + 1}; }
  std::uint32_t Length(const PlaceToken& token) const { return std::max<std::uint32_t>(1, token.length); }
  SourceRange Range(const PlaceToken& token) const { return SourceRange(Loc(token), Length(token)); }
  // "'Jump'", "end of line" or "end of file": how a found token is named.
  std::string Display(const PlaceToken& token) const {
    if (token.type == kPlaceEof) return "end of file";
    if (TypeOf(token) == P::NEWLINE) return "end of line";
    return fmt::format("'{}'", Text(token));
  }
  std::span<const PlaceToken> Code(const Line& line) const {
    return std::span<const PlaceToken>(tokens_.data() + line.first, line.size());
  }

  // --- the same for the tokens ANTLR holds (LineTokens made them)
  std::string_view Text(const Token* token) const {
    std::size_t start = token->getStartIndex();
    std::size_t stop = token->getStopIndex();
    if (token->getType() == Token::EOF || stop < start || stop >= text_.size()) return {};
    return std::string_view(text_).substr(start, stop - start + 1);
  }
  SourceLoc Loc(const Token* token) const {
    return SourceLoc{file_, static_cast<std::uint32_t>(token->getLine()),
                     static_cast<std::uint32_t>(token->getCharPositionInLine() + 1)};
  }
  std::uint32_t Length(const Token* token) const {
    return std::max<std::uint32_t>(1, static_cast<std::uint32_t>(Text(token).size()));
  }
  SourceRange Range(const Token* token) const { return SourceRange(Loc(token), Length(token)); }
  std::string Display(const Token* token) const {
    if (token->getType() == Token::EOF) return "end of file";
    if (token->getType() == P::NEWLINE) return "end of line";
    return fmt::format("'{}'", Text(token));
  }

  // --- errors
  // Records an error for Flush(); the line it points at counts as broken
  // (one error per line, and the builder drops that line's statement).
  template <typename... Args>
  PendingError& Error(DiagKind kind, SourceRange range, Args... args) {
    if (range.begin.line < lines_.size()) lines_[range.begin.line].error = true;
    return ErrorElsewhere(kind, range, args...);
  }
  // The same for an error that points at a line that is not broken itself
  // (the opener of a block that is never closed).
  template <typename... Args>
  PendingError& ErrorElsewhere(DiagKind kind, SourceRange range, Args... args) {
    errors_.push_back({range.begin, [=](Diagnostics& d) { return d.Report(kind, range, args...); }, {}});
    return errors_.back();
  }
  void FlagLine(const Token* token) {
    if (token != nullptr && token->getLine() < lines_.size()) lines_[token->getLine()].error = true;
  }
  bool LineHasError(std::size_t line) const { return line < lines_.size() && lines_[line].error; }
  const Line* LineAt(std::size_t line) const { return line < lines_.size() ? &lines_[line] : nullptr; }
  const PlaceToken* CommentToken(std::size_t line) const {
    const Line* info = LineAt(line);
    return info != nullptr && info->comment >= 0 ? &tokens_[static_cast<std::size_t>(info->comment)] : nullptr;
  }
  std::uint32_t file() const { return file_; }
  std::uint32_t last_line() const { return static_cast<std::uint32_t>(lines_.size() - 1); }
  const std::vector<Line>& lines() const { return lines_; }
  std::span<const Closer> ClosersBefore(const Line& line) const {
    return std::span<const Closer>(closers_.data() + line.closers_first, line.closers_count);
  }
  std::span<const Closer> ClosersAtEnd() const { return closers_at_end_; }
  const PlaceToken& EndOfFile() const { return tokens_.back(); }

  // Reports an ANTLR parse error in plain words (SyntaxErrorListener).
  void ReportParseError(antlr4::Parser* parser, antlr4::ParserRuleContext* ctx, Token* found,
                        const antlr4::misc::IntervalSet& expected, bool deep);

 private:
  void SplitLines();
  void PreScan();
  void CheckCharacters(Line& line);
  void CheckExpressionSize(Line& line);
  void CheckStructure(Line& line, std::vector<OpenBlock>& stack, bool& misplaced_run);
  bool IfHasBlock(std::size_t if_line) const;
  void CloseBlocksAbove(std::size_t keep, std::vector<OpenBlock>& stack, std::uint32_t at, bool quiet);
  // Error(), unless the line already has one: one error per line.
  template <typename... Args>
  void LineError(const Line& line, DiagKind kind, SourceRange range, Args... args) {
    if (!line.error) Error(kind, range, args...);
  }
  void Drop(Line& line) {
    line.end = line.first;
    line.error = true;
  }
  void CloseAtEndOfFile(std::vector<OpenBlock>& stack, bool report);
  void Flush();

  std::uint32_t file_;
  Diagnostics& diags_;
  const std::string& text_;
  std::vector<PlaceToken> tokens_;  // every token the lexer made, EOF last
  std::vector<std::uint32_t> line_starts_;  // [line]: where it starts
  std::vector<Line> lines_;         // by line number; [0] unused
  std::vector<Closer> closers_;     // the closers before lines, in line order
  std::vector<Closer> closers_at_end_;  // closers added at the end of the file
  std::vector<PendingError> errors_;
};

// ------------------------------------------------------------------ step 1: lex

// The tokens by line. Code tokens come first on a line, then a comment, then
// the NEWLINE, so a line's code is the range before its comment or NEWLINE.
void Session::SplitLines() {
  std::size_t lines = std::max<std::size_t>(tokens_.back().line, 1) + 1;
  lines_.resize(lines);
  for (std::uint32_t i = 0; i + 1 < tokens_.size(); ++i) {  // all but EOF
    const PlaceToken& token = tokens_[i];
    Line& line = lines_[std::min<std::size_t>(token.line, lines - 1)];
    switch (TypeOf(token)) {
      case P::NEWLINE: line.newline = static_cast<std::int32_t>(i); break;
      case P::COMMENT: line.comment = static_cast<std::int32_t>(i); break;
      default:
        if (!line.had_code) line.first = i;
        line.end = i + 1;
        line.had_code = true;
    }
  }
}

// ------------------------------------------------------------------ step 2: pre-scan

void Session::PreScan() {
  std::vector<OpenBlock> stack;
  bool misplaced_run = false;  // inside a run of statements outside any Function
  for (std::size_t n = 1; n < lines_.size(); ++n) {
    Line& line = lines_[n];
    line.closers_first = static_cast<std::uint32_t>(closers_.size());
    CheckCharacters(line);
    if (line.empty()) continue;
    CheckStructure(line, stack, misplaced_run);
    line.closers_count = static_cast<std::uint32_t>(closers_.size()) - line.closers_first;
    CheckExpressionSize(line);
    if (stack.size() > kMaxBlockDepth) {
      // Stop here: drop this line and the rest, close what is open silently.
      Error(DiagKind::BlocksTooDeep, Range(At(stack.back().opener)), kMaxBlockDepth);
      for (std::size_t rest = n + 1; rest < lines_.size(); ++rest) lines_[rest].end = lines_[rest].first;
      stack.pop_back();
      Drop(line);
      return CloseAtEndOfFile(stack, false);
    }
  }
  CloseAtEndOfFile(stack, true);
}

// Closes the blocks still open at the end of the file, innermost first.
void Session::CloseAtEndOfFile(std::vector<OpenBlock>& stack, bool report) {
  const auto eof = static_cast<std::uint32_t>(tokens_.size() - 1);
  while (!stack.empty()) {
    const OpenBlock& open = stack.back();
    std::size_t closer = CloserOf(open.type);
    if (report) {
      ErrorElsewhere(DiagKind::MissingBlockEndAtEof, Range(At(open.opener)), std::string(Spelling(closer)),
                     Describe(open), static_cast<std::size_t>(At(open.opener).line));
    }
    closers_at_end_.push_back({closer, eof});
    stack.pop_back();
  }
}

// BAD_CHAR tokens: one error for the first per line (a UTF-8 sequence is one
// character); all of them leave the line so ANTLR never sees them.
void Session::CheckCharacters(Line& line) {
  bool reported = false;
  std::uint32_t kept = line.first;
  for (std::uint32_t i = line.first; i < line.end; ++i) {
    const PlaceToken token = tokens_[i];
    if (TypeOf(token) != P::BAD_CHAR) {
      tokens_[kept++] = token;
      continue;
    }
    if (reported) continue;
    reported = true;
    std::size_t at = token.start;
    auto byte = static_cast<unsigned char>(text_[at]);
    std::size_t length = byte >= 0xF0 ? 4 : byte >= 0xE0 ? 3 : byte >= 0xC0 ? 2 : 1;
    bool valid_utf8 = byte >= 0xC2 && byte <= 0xF4 && at + length <= text_.size();
    for (std::size_t i = 1; valid_utf8 && i < length; ++i) {
      valid_utf8 = (static_cast<unsigned char>(text_[at + i]) & 0xC0) == 0x80;
    }
    std::string what;
    std::string hint;
    std::uint32_t bytes = 1;
    if (byte >= 0x21 && byte < 0x7F) {
      what = fmt::format("'{}'", static_cast<char>(byte));
      if (byte == '"') hint = "; .place has no strings (comments start with ')";
      if (byte == ':') hint = "; write one statement per line";
    } else if (byte == '\r') {
      what = "'\\r' (a carriage return without a newline)";
    } else if (valid_utf8 && byte >= 0x80) {
      bytes = static_cast<std::uint32_t>(length);
      what = fmt::format("'{}'", text_.substr(at, length));
      hint = "; outside comments a program uses only plain ASCII letters, digits and signs";
    } else {
      what = fmt::format("with byte value 0x{:02X}", byte);
      hint = byte >= 0x80 ? "; the file is not UTF-8 text" : "";
    }
    Error(DiagKind::UnexpectedCharacter, SourceRange(Loc(token), bytes), what, hint);
  }
  line.end = kept;
}

// Counts operators and '(' on the line; cuts the line where the count
// passes the limit, so ANTLR's recursion stays bounded.
void Session::CheckExpressionSize(Line& line) {
  int count = 0;
  for (std::uint32_t i = line.first; i < line.end; ++i) {
    std::size_t type = TypeOf(tokens_[i]);
    if (type == P::LPAREN || type == P::NOT || IsBinaryOperator(type)) ++count;
    if (count > kMaxExpressionSize) {
      LineError(line, DiagKind::ExpressionTooBig, Range(tokens_[i]), kMaxExpressionSize);
      line.end = i;
      return;
    }
  }
}

void Session::CloseBlocksAbove(std::size_t keep, std::vector<OpenBlock>& stack, std::uint32_t at, bool quiet) {
  while (stack.size() > keep) {
    const OpenBlock& open = stack.back();
    std::size_t closer = CloserOf(open.type);
    std::string what = Describe(open);
    if (!quiet) {
      PendingError& error = Error(DiagKind::MissingBlockEnd, Range(At(at)), std::string(Spelling(closer)), what,
                                  static_cast<std::size_t>(At(open.opener).line));
      error.notes.emplace_back(Range(At(open.opener)), fmt::format("{} starts here", what));
    }
    closers_.push_back({closer, at});
    stack.pop_back();
  }
}

// The block structure, from the first token of each line.
void Session::CheckStructure(Line& line, std::vector<OpenBlock>& stack, bool& misplaced_run) {
  const std::uint32_t first_index = line.first;
  const PlaceToken& first = tokens_[first_index];
  std::size_t type = TypeOf(first);
  bool quiet = line.error;  // a bad character was reported on this line
  std::size_t second = line.size() > 1 ? TypeOf(tokens_[line.first + 1]) : std::size_t{P::NEWLINE};
  auto innermost = [&](std::size_t block_type) -> std::ptrdiff_t {
    for (std::size_t i = stack.size(); i-- > 0;) {
      if (stack[i].type == block_type) return static_cast<std::ptrdiff_t>(i);
    }
    return -1;
  };
  auto misplaced = [&](std::string what) {
    if (!misplaced_run) LineError(line, DiagKind::StatementOutsideFunction, Range(first), std::move(what));
    misplaced_run = true;
    Drop(line);
  };
  // "If c Then Jump P": THEN before the end of the line (its token index).
  auto then_not_last = [&]() -> std::optional<std::uint32_t> {
    for (std::uint32_t i = line.first; i + 1 < line.end; ++i) {
      if (TypeOf(tokens_[i]) == P::THEN) return i;
    }
    return std::nullopt;
  };
  auto cut_after = [&](std::uint32_t index) { line.end = index + 1; };

  // A name followed by '(' is a misspelt function (Palet(1, 2, 1)): the
  // language's only calls with parentheses are its built-in functions and
  // the offsets X( ) .. U( ) (and the empty () of Function F() / Call F()).
  for (std::uint32_t i = line.first; i + 1 < line.end; ++i) {
    if (TypeOf(tokens_[i]) != P::ID || TypeOf(tokens_[i + 1]) != P::LPAREN) continue;
    if (i > line.first && (TypeOf(tokens_[i - 1]) == P::FUNCTION || TypeOf(tokens_[i - 1]) == P::CALL)) continue;
    // After + or -: an offset, whose axis has a message of its own.
    if (i > line.first && (TypeOf(tokens_[i - 1]) == P::PLUS || TypeOf(tokens_[i - 1]) == P::MINUS)) continue;
    const std::string name = AsciiLowercase(Text(tokens_[i]));
    if (name == "x" || name == "y" || name == "z" || name == "u") continue;
    static const std::vector<std::string> kFunctions = {"Pallet", "XY", "Sw"};
    const std::string suggestion = ClosestName(Text(tokens_[i]), kFunctions);
    LineError(line, DiagKind::UnknownFunction, Range(tokens_[i]), std::string(Text(tokens_[i])),
              suggestion.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", suggestion));
    return Drop(line);
  }

  switch (type) {
    case P::FUNCTION: {
      CloseBlocksAbove(0, stack, first_index, quiet);
      misplaced_run = false;
      std::string name = second == P::ID ? std::string(Text(tokens_[line.first + 1])) : std::string();
      stack.push_back({type, first_index, std::move(name), false});
      return;
    }
    case P::FOR:
    case P::IF:
    case P::CYCLE:
      if (stack.empty()) return misplaced(fmt::format("'{}'", Spelling(type)));
      if (std::optional<std::uint32_t> then = type == P::IF ? then_not_last() : std::nullopt) {
        LineError(line, DiagKind::SingleLineIf, Range(tokens_[*then]), "Then");
        // A block If with something after Then keeps its header; a SPEL
        // single-line If (no EndIf follows) opens no block.
        if (!IfHasBlock(tokens_[*then].line)) return Drop(line);
        cut_after(*then);
      }
      stack.push_back({type, first_index, {}, false});
      return;
    case P::ELSEIF:
    case P::ELSE: {
      if (stack.empty() && misplaced_run) return Drop(line);
      std::ptrdiff_t at = innermost(P::IF);
      if (at < 0) {
        LineError(line, DiagKind::UnexpectedBlockEnd, Range(first), std::string(Spelling(type)), "If");
        return Drop(line);
      }
      CloseBlocksAbove(static_cast<std::size_t>(at) + 1, stack, first_index, quiet);
      if (stack.back().seen_else) {
        LineError(line, DiagKind::ElseAfterElse, Range(first), std::string(Spelling(type)),
                  static_cast<std::size_t>(At(stack.back().opener).line));
        return Drop(line);
      }
      if (type == P::ELSE) stack.back().seen_else = true;
      if (std::optional<std::uint32_t> then = type == P::ELSEIF ? then_not_last() : std::nullopt) {
        LineError(line, DiagKind::SingleLineIf, Range(tokens_[*then]), "Then");
        cut_after(*then);
      }
      return;
    }
    case P::NEXT:
    case P::ENDIF:
    case P::ENDCYCLE:
    case P::FEND: {
      if (stack.empty() && misplaced_run) return Drop(line);
      std::size_t opener = type == P::NEXT    ? P::FOR
                           : type == P::ENDIF ? P::IF
                           : type == P::ENDCYCLE ? P::CYCLE
                                                 : P::FUNCTION;
      std::ptrdiff_t at = innermost(opener);
      if (at < 0) {
        LineError(line, DiagKind::UnexpectedBlockEnd, Range(first), std::string(Spelling(type)),
                  std::string(Spelling(opener)));
        return Drop(line);
      }
      CloseBlocksAbove(static_cast<std::size_t>(at) + 1, stack, first_index, quiet);
      stack.pop_back();
      return;
    }
    case P::PROGRAM:
    case P::UNITS:
    case P::FIXTURE:
    case P::LOCAL:
    case P::TAUGHT:
    case P::POINT:
    case P::PALLET:
    case P::VACUUM:
      if (!stack.empty()) {
        std::string_view kind = type == P::TAUGHT ? "Taught Point" : Spelling(type);
        LineError(line, DiagKind::DeclarationInsideFunction, Range(first), std::string(kind),
                  Describe(stack.front()));
        return Drop(line);
      }
      misplaced_run = false;
      return;
    case P::INTEGER:
    case P::REAL:
      if (stack.empty()) misplaced_run = false;
      return;
    case P::ID:
      if (second != P::EQ) {
        const auto& words = stack.empty() ? DeclarationKeywords() : StatementKeywords();
        std::string suggestion = ClosestName(Text(first), words);
        if (stack.empty()) {
          LineError(line, DiagKind::ExpectedDeclaration, Range(first), Display(first),
                    suggestion.empty() ? std::string() : fmt::format("; did you mean '{}'?", suggestion));
          return Drop(line);
        }
        if (!suggestion.empty()) {
          LineError(line, DiagKind::ExpectedStatement, Range(first), Display(first),
                    fmt::format("; did you mean '{}'?", suggestion));
          return Drop(line);
        }
        return;  // ANTLR says what is wrong with it
      }
      if (stack.empty()) return misplaced("an assignment");
      return;
    case P::JUMP: case P::GO: case P::MOVE: case P::PICK: case P::PLACE: case P::ON: case P::OFF:
    case P::WAIT: case P::CALL: case P::SCAN: case P::EXIT:
      if (stack.empty()) return misplaced(fmt::format("'{}'", Spelling(type)));
      return;
    default:
      if (stack.empty()) {
        LineError(line, DiagKind::ExpectedDeclaration, Range(first), Display(first), std::string());
      } else {
        LineError(line, DiagKind::ExpectedStatement, Range(first), Display(first), std::string());
      }
      return Drop(line);
  }
}

// Whether the If on if_line is a block: an ElseIf, Else or EndIf of its own
// follows before the block around it closes. Past the error limit nothing
// more is shown, so the answer no longer matters and the scan is skipped
// (which keeps a file of single-line Ifs from costing quadratic time).
bool Session::IfHasBlock(std::size_t if_line) const {
  if (errors_.size() > kMaxSyntaxErrors) return false;
  int depth = 0;
  for (std::size_t n = if_line + 1; n < lines_.size(); ++n) {
    const Line& line = lines_[n];
    if (line.empty()) continue;
    switch (TypeOf(tokens_[line.first])) {
      case P::FOR: case P::CYCLE: ++depth; break;
      case P::IF:
        if (TypeOf(tokens_[line.end - 1]) == P::THEN) ++depth;
        break;
      case P::ELSEIF: case P::ELSE:
        if (depth == 0) return true;
        break;
      case P::ENDIF:
        if (depth == 0) return true;
        --depth;
        break;
      case P::NEXT: case P::ENDCYCLE:
        if (depth == 0) return false;
        --depth;
        break;
      case P::FEND: case P::FUNCTION:
        return false;
      default:
        break;
    }
  }
  return false;
}

// ------------------------------------------------------------------ step 3: ANTLR, one line at a time

// One line's tokens for the parser: the line's code as the pre-scan left it,
// its NEWLINE (one at the end-of-file position for a last line without one)
// and EOF. The parser reads them through this token stream, which is also
// their TokenSource (ANTLR's error recovery asks a token for its source's
// factory when it makes up a missing token). The tokens are ANTLR
// CommonTokens that point into the source text by byte offsets; their
// objects are made once and reused for every line, so a line costs no
// allocation per token (CommonTokenStream over a TokenSource would make and
// free one 112-byte object per token, the largest cost of a parse).
class LineTokens final : public antlr4::TokenStream, public antlr4::TokenSource {
 public:
  explicit LineTokens(const Session& session) : session_(session) {}

  void Start(const Line& line) {
    std::span<const PlaceToken> code = session_.Code(line);
    const PlaceToken& newline =
        line.newline >= 0 ? session_.At(static_cast<std::uint32_t>(line.newline)) : session_.EndOfFile();
    size_ = 0;
    for (const PlaceToken& token : code) Set(token, TypeOf(token));
    Set(newline, P::NEWLINE);
    Set(session_.EndOfFile(), Token::EOF);
    p_ = 0;
  }

  // --- TokenStream
  Token* LT(ssize_t k) override {
    if (k == 0) return nullptr;
    if (k < 0) return -k <= static_cast<ssize_t>(p_) ? tokens_[p_ + static_cast<std::size_t>(k)].get() : nullptr;
    return tokens_[std::min(p_ + static_cast<std::size_t>(k) - 1, size_ - 1)].get();
  }
  Token* get(std::size_t index) const override { return tokens_[std::min(index, size_ - 1)].get(); }
  antlr4::TokenSource* getTokenSource() const override { return const_cast<LineTokens*>(this); }
  // The texts only feed ANTLR's own messages, which SyntaxErrorListener drops.
  std::string getText(const antlr4::misc::Interval&) override { return {}; }
  std::string getText() override { return {}; }
  std::string getText(antlr4::RuleContext*) override { return {}; }
  std::string getText(Token*, Token*) override { return {}; }
  void consume() override {
    if (LA(1) == Token::EOF) throw antlr4::IllegalStateException("cannot consume EOF");
    ++p_;
  }
  // The parser asks LA(1) before every decision: answered from types_,
  // without a virtual call to the token.
  std::size_t LA(ssize_t i) override {
    if (i > 0) return types_[std::min(p_ + static_cast<std::size_t>(i) - 1, size_ - 1)];
    Token* token = LT(i);
    return token != nullptr ? token->getType() : Token::INVALID_TYPE;
  }
  ssize_t mark() override { return 0; }
  void release(ssize_t) override {}
  std::size_t index() override { return p_; }
  void seek(std::size_t index) override { p_ = std::min(index, size_ - 1); }
  std::size_t size() override { return size_; }

  // --- TokenSource (the parser never pulls tokens from it)
  std::unique_ptr<Token> nextToken() override { return nullptr; }
  std::size_t getLine() const override { return p_ < size_ ? tokens_[p_]->getLine() : 0; }
  std::size_t getCharPositionInLine() override { return p_ < size_ ? tokens_[p_]->getCharPositionInLine() : 0; }
  antlr4::CharStream* getInputStream() override { return nullptr; }
  std::string getSourceName() const override { return "line"; }
  std::string getSourceName() override { return "line"; }
  antlr4::TokenFactory<antlr4::CommonToken>* getTokenFactory() override {
    return antlr4::CommonTokenFactory::DEFAULT.get();
  }

 private:
  // A CommonToken filled in place for each line (its setters are virtual
  // calls, one per field).
  class Reused : public antlr4::CommonToken {
   public:
    explicit Reused(antlr4::TokenSource* source)
        : antlr4::CommonToken(std::pair<antlr4::TokenSource*, antlr4::CharStream*>(source, nullptr),
                              Token::INVALID_TYPE, Token::DEFAULT_CHANNEL, 0, 0) {}
    void Fill(const PlaceToken& from, std::uint32_t column, std::size_t type, std::size_t index) {
      _type = type;
      _line = from.line;
      _charPositionInLine = column;
      // A token of no length (the end of file, a NEWLINE made up there)
      // stops where it starts, beyond the text: its text is empty.
      _start = from.start;
      _stop = from.length == 0 ? from.start : from.start + from.length - 1;
      _index = index;
    }
  };

  void Set(const PlaceToken& from, std::size_t type) {
    if (size_ == tokens_.size()) {
      tokens_.push_back(std::make_unique<Reused>(this));
      types_.push_back(Token::INVALID_TYPE);
    }
    tokens_[size_]->Fill(from, session_.Column(from), type, size_);
    types_[size_] = type;
    ++size_;
  }

  const Session& session_;
  std::vector<std::unique_ptr<Reused>> tokens_;  // [0, size_) are this line's
  std::vector<std::size_t> types_;               // their types
  std::size_t size_ = 0;
  std::size_t p_ = 0;
};

// Recovery by line: after an error, skip to the end of the line and let the
// enclosing rules finish there. Never deletes a NEWLINE; and as the parser
// sees one line at a time, not even the failsafe below (which consumes a
// token when two errors meet at one place) can pull the next line into this
// statement.
class LineErrorStrategy : public antlr4::DefaultErrorStrategy {
 public:
  explicit LineErrorStrategy(Session& session) : session_(session) {}

  // Every line starts afresh (the parser is reset before each): the states
  // of an earlier line's errors say nothing about this one.
  void reset(antlr4::Parser* parser) override {
    lastErrorStates.clear();
    antlr4::DefaultErrorStrategy::reset(parser);
  }
  void recover(antlr4::Parser* parser, std::exception_ptr) override {
    antlr4::TokenStream* input = parser->getTokenStream();
    auto index = static_cast<int>(input->index());
    if (lastErrorIndex == index && lastErrorStates.contains(parser->getState()) &&
        input->LA(1) != Token::EOF) {
      parser->consume();  // failsafe against a loop that never consumes
    }
    lastErrorIndex = static_cast<int>(input->index());
    lastErrorStates.add(parser->getState());
    while (input->LA(1) != P::NEWLINE && input->LA(1) != Token::EOF) parser->consume();
  }
  // No resynchronising before loops: errors show up at the token that is
  // wrong, and recovery stays within the line.
  void sync(antlr4::Parser*) override {}

  void reportError(antlr4::Parser* parser, const antlr4::RecognitionException& e) override {
    if (inErrorRecoveryMode(parser)) session_.FlagLine(e.getOffendingToken());
    antlr4::DefaultErrorStrategy::reportError(parser, e);
  }

 protected:
  Token* singleTokenDeletion(antlr4::Parser* parser) override {
    if (parser->getTokenStream()->LA(1) == P::NEWLINE) return nullptr;
    return antlr4::DefaultErrorStrategy::singleTokenDeletion(parser);
  }
  void reportUnwantedToken(antlr4::Parser* parser) override {
    if (inErrorRecoveryMode(parser)) session_.FlagLine(parser->getCurrentToken());
    antlr4::DefaultErrorStrategy::reportUnwantedToken(parser);
  }
  void reportMissingToken(antlr4::Parser* parser) override {
    if (inErrorRecoveryMode(parser)) session_.FlagLine(parser->getCurrentToken());
    antlr4::DefaultErrorStrategy::reportMissingToken(parser);
  }

 private:
  Session& session_;
};

// Replaces ANTLR's console listener: ANTLR's own wording is dropped, the
// error is rewritten from the parser's state.
class SyntaxErrorListener : public antlr4::BaseErrorListener {
 public:
  explicit SyntaxErrorListener(Session& session) : session_(session) {}

  void syntaxError(antlr4::Recognizer* recognizer, Token* offending, std::size_t line, std::size_t column,
                   const std::string&, std::exception_ptr e) override {
    auto* parser = dynamic_cast<antlr4::Parser*>(recognizer);
    if (parser == nullptr || offending == nullptr) {
      session_.Error(DiagKind::SyntaxError,
                     SourceLoc{session_.file(), static_cast<std::uint32_t>(line),
                               static_cast<std::uint32_t>(column + 1)},
                     std::string("cannot read this text"));
      return;
    }
    if (session_.LineHasError(offending->getLine())) return;  // one error per line
    antlr4::ParserRuleContext* ctx = parser->getContext();
    antlr4::misc::IntervalSet expected;
    bool deep = false;  // the parser failed after looking past the first token
    try {
      if (e) {
        try {
          std::rethrow_exception(e);
        } catch (const antlr4::NoViableAltException& ex) {
          deep = ex.getStartToken() != offending;
          expected = ex.getExpectedTokens();
          if (auto* c = dynamic_cast<antlr4::ParserRuleContext*>(ex.getCtx())) ctx = c;
        } catch (const antlr4::FailedPredicateException&) {
          deep = true;
        } catch (const antlr4::RecognitionException& ex) {
          expected = ex.getExpectedTokens();
          if (auto* c = dynamic_cast<antlr4::ParserRuleContext*>(ex.getCtx())) ctx = c;
        }
      } else {
        expected = parser->getExpectedTokens();
      }
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception&) {
      deep = true;  // no expected set; fall back to a plain message
    }
    session_.ReportParseError(parser, ctx, offending, expected, deep);
  }

 private:
  Session& session_;
};

// The nearest enclosing context of type C within the line.
template <typename C>
C* Find(antlr4::RuleContext* ctx) {
  for (antlr4::RuleContext* c = ctx; c != nullptr; c = dynamic_cast<antlr4::RuleContext*>(c->parent)) {
    if (auto* found = dynamic_cast<C*>(c)) return found;
  }
  return nullptr;
}

// What a name is for, from the rule that wanted it.
std::string NameRole(antlr4::RuleContext* ctx, const Token* previous) {
  std::size_t prev = previous != nullptr ? previous->getType() : 0;
  if (prev == P::IN) return "a frame name";
  if (prev == P::ON) return "a fixture name";
  if (Find<P::ProgramDeclContext>(ctx)) return "a program name";
  if (Find<P::UnitsDeclContext>(ctx)) return "a unit (mm)";
  if (Find<P::FixtureDeclContext>(ctx) || Find<P::CycleHeadContext>(ctx) || Find<P::ScanStmtContext>(ctx)) {
    return "a fixture name";
  }
  if (Find<P::LocalDeclContext>(ctx)) return "a frame name";
  if (Find<P::PointDeclContext>(ctx) || Find<P::PalletDeclContext>(ctx)) return "a point name";
  if (Find<P::FunctionHeadContext>(ctx) || Find<P::CallStmtContext>(ctx)) return "a function name";
  if (Find<P::VarDeclContext>(ctx) || Find<P::ForHeadContext>(ctx) || Find<P::NextLineContext>(ctx)) {
    return "a variable name";
  }
  return "a name";
}

// The form of the statement being parsed, appended to "expected" messages.
std::string FormHint(antlr4::RuleContext* ctx) {
  for (antlr4::RuleContext* c = ctx; c != nullptr; c = dynamic_cast<antlr4::RuleContext*>(c->parent)) {
    if (dynamic_cast<P::ForHeadContext*>(c)) return "; write: For var = start To end [Step step]";
    if (dynamic_cast<P::IfHeadContext*>(c)) return "; write: If condition Then";
    if (dynamic_cast<P::ElseIfHeadContext*>(c)) return "; write: ElseIf condition Then";
    if (dynamic_cast<P::LocalDeclContext*>(c)) return "; write: Local NAME = XY(x, y, z, u) [In FRAME]";
    if (dynamic_cast<P::PointDeclContext*>(c)) {
      return "; write: [Taught] Point NAME = XY(x, y, z, u) [In FRAME | On FIXTURE]";
    }
    if (dynamic_cast<P::PalletDeclContext*>(c)) return "; write: Pallet n, P1, P2, P3, columns, rows";
    if (dynamic_cast<P::PalletPointContext*>(c)) return "; write: Pallet(n, i, j) or Pallet(n, k)";
    if (dynamic_cast<P::VarDeclContext*>(c)) return "; write: Integer a, b or Real d";
    if (dynamic_cast<P::SwitchExprContext*>(c)) return "; write: Sw(n)";
    if (dynamic_cast<P::OffsetContext*>(c)) return "; write: + X(d)";
    if (dynamic_cast<P::ExitStmtContext*>(c)) return "; write: Exit Function";
    if (dynamic_cast<P::AssignmentContext*>(c)) return "; write: name = value";
  }
  return "";
}

void Session::ReportParseError(antlr4::Parser* parser, antlr4::ParserRuleContext* ctx, Token* found,
                               const antlr4::misc::IntervalSet& expected, bool deep) {
  SourceRange at = Range(found);
  if (found->getType() == P::NEWLINE || found->getType() == Token::EOF) at.length = 1;
  // The token before the offending one, on the same line.
  const Token* previous = nullptr;
  if (found->getTokenIndex() != INVALID_INDEX && found->getTokenIndex() > 0) {
    Token* before = parser->getTokenStream()->get(found->getTokenIndex() - 1);
    if (before->getType() != P::NEWLINE && before->getLine() == found->getLine()) previous = before;
  }
  std::string after = previous != nullptr ? fmt::format(" after '{}'", Text(previous)) : std::string();
  std::string found_text = Display(found);
  std::size_t type = found->getType();
  auto has = [&](std::size_t t) { return expected.contains(t); };

  if (deep || expected.isEmpty()) {
    Error(DiagKind::SyntaxError, at, fmt::format("unexpected {}{}", found_text, after));
    return;
  }
  bool at_end = type == P::NEWLINE || type == Token::EOF;

  if (auto* coords = Find<P::CoordsContext>(ctx)) {
    std::size_t numbers = 0;
    for (const Token* number : {coords->x, coords->y, coords->z, coords->u}) numbers += number != nullptr ? 1 : 0;
    if (has(P::NUMBER) && type != P::RPAREN && !at_end) {
      Error(DiagKind::CoordsNotNumber, at, found_text);
      return;
    }
    if ((has(P::NUMBER) || has(P::COMMA)) && (type == P::RPAREN || at_end)) {
      Error(DiagKind::CoordsCount, at, std::to_string(numbers));
      return;
    }
    if (has(P::RPAREN) && type == P::COMMA) {
      Error(DiagKind::CoordsCount, at, std::string("more than 4"));
      return;
    }
  }
  if (has(P::XY) && has(P::PALLET) && has(P::ID)) {
    Error(DiagKind::ExpectedPoint, at, after, found_text);
    return;
  }
  if (Find<P::OffsetContext>(ctx) != nullptr && has(P::ID) && !has(P::LPAREN)) {
    Error(DiagKind::ExpectedOffset, at, after, found_text);
    return;
  }
  bool expects_expression = has(P::NUMBER) && has(P::LPAREN) && has(P::NOT);
  if (has(P::RPAREN) && !expects_expression && at_end) {
    // The '(' still open on this line, innermost first.
    int depth = 0;
    for (auto i = static_cast<std::ptrdiff_t>(found->getTokenIndex()) - 1; i >= 0; --i) {
      Token* t = parser->getTokenStream()->get(static_cast<std::size_t>(i));
      if (t->getType() == P::NEWLINE) break;
      if (t->getType() == P::RPAREN) ++depth;
      if (t->getType() == P::LPAREN && depth-- == 0) {
        Error(DiagKind::MissingCloseParen, at, t->getCharPositionInLine() + 1, found_text);
        return;
      }
    }
  }
  if (expects_expression) {
    Error(DiagKind::ExpectedExpression, at, after, found_text);
    return;
  }
  bool expects_end = has(P::NEWLINE) || has(Token::EOF);
  if (has(P::ID) && !expects_end) {
    std::string role = NameRole(ctx, previous);
    if (IsKeyword(type)) {
      Error(DiagKind::KeywordAsName, at, std::string(Text(found)), role);
    } else {
      Error(DiagKind::ExpectedName, at, role, after, found_text);
    }
    return;
  }
  // The expected tokens in words; operators only when nothing else fits.
  std::vector<std::string> names;
  // An expression could go on when '*' fits; then the operators are one item.
  // Otherwise each expected token is listed, '=' included.
  bool operators = false;
  bool expression_continues = has(P::STAR);
  for (auto t : expected.toList()) {
    if (expression_continues && IsBinaryOperator(static_cast<std::size_t>(t))) {
      operators = true;
    } else {
      names.push_back(ExpectedItem(static_cast<std::size_t>(t)));
    }
  }
  if (operators && (names.empty() || expects_end)) names.insert(names.begin(), "an operator");
  std::string list = JoinAlternatives(names);
  if (expects_end) {
    Error(DiagKind::UnexpectedToken, at, found_text, after, list);
    return;
  }
  Error(DiagKind::ExpectedToken, at, list, after, found_text, FormHint(ctx));
}

// ------------------------------------------------------------------ step 3: the IR of a line

// Builds the IR of one parsed line from its rule's labelled elements. Each
// piece is empty (null, nullopt) when the tree is incomplete after an error.
class IrBuilder {
 public:
  explicit IrBuilder(Session& session) : s_(session) {}

  // The text of the comment on `line`, without its ' and without spaces or
  // tabs at its end: they are invisible, and printing them back would end a
  // canonical line in whitespace. Spaces after the ' are kept as written.
  std::string CommentOn(std::size_t line) const {
    const PlaceToken* comment = s_.CommentToken(line);
    if (comment == nullptr) return {};
    std::string_view text = s_.Text(*comment).substr(1);
    std::size_t end = text.find_last_not_of(" \t");
    return std::string(text.substr(0, end == std::string_view::npos ? 0 : end + 1));
  }
  // A line that holds only a comment.
  ir::StmtPtr CommentLine(std::size_t line) const {
    const PlaceToken& comment = *s_.CommentToken(line);
    auto stmt = std::make_unique<ir::Stmt>();
    stmt->loc = s_.Loc(comment);
    stmt->length = s_.Length(comment);
    stmt->node = ir::Comment{CommentOn(line)};
    return stmt;
  }
  // A block's closing line (Fend, Next, EndIf, EndCycle) ...
  ir::BlockEnd End(const Token* closer) const {
    return ir::BlockEnd{s_.Loc(closer), CommentOn(closer->getLine())};
  }
  // ... or a closer the pre-scan added at the position of the token `at`.
  ir::BlockEnd End(const PlaceToken& at) const { return ir::BlockEnd{s_.Loc(at), CommentOn(at.line)}; }

  // declarationLine : (programDecl | unitsDecl | fixtureDecl | localDecl | pointDecl
  //                    | palletDecl | vacuumDecl | varDecl) NEWLINE ;
  ir::StmtPtr Declaration(P::DeclarationLineContext* ctx) {
    if (ctx->pointAlt != nullptr) return PointDecl(ctx->pointAlt);
    if (ctx->programAlt != nullptr) return ProgramDecl(ctx->programAlt);
    if (ctx->unitsAlt != nullptr) return UnitsDecl(ctx->unitsAlt);
    if (ctx->fixtureAlt != nullptr) return FixtureDecl(ctx->fixtureAlt);
    if (ctx->localAlt != nullptr) return LocalDecl(ctx->localAlt);
    if (ctx->palletAlt != nullptr) return PalletDecl(ctx->palletAlt);
    if (ctx->vacuumAlt != nullptr) return VacuumDecl(ctx->vacuumAlt);
    if (ctx->varDeclAlt != nullptr) return VarDecl(ctx->varDeclAlt);
    return nullptr;
  }
  // statementLine : (varDecl | assignment | motion | pickPlace | onOff | waitStmt
  //                  | callStmt | scanStmt | exitStmt) NEWLINE ;
  ir::StmtPtr Statement(P::StatementLineContext* ctx) {
    if (ctx->pickPlaceAlt != nullptr) return PickPlace(ctx->pickPlaceAlt);
    if (ctx->motionAlt != nullptr) return Motion(ctx->motionAlt);
    if (ctx->assignmentAlt != nullptr) return Assignment(ctx->assignmentAlt);
    if (ctx->varDeclAlt != nullptr) return VarDecl(ctx->varDeclAlt);
    if (ctx->onOffAlt != nullptr) return OnOff(ctx->onOffAlt);
    if (ctx->waitAlt != nullptr) return Wait(ctx->waitAlt);
    if (ctx->callAlt != nullptr) return MakeStmt(ctx->callAlt, ir::Call{Name(ctx->callAlt->name), Loc(ctx->callAlt->name)});
    if (ctx->scanAlt != nullptr) return MakeStmt(ctx->scanAlt, ir::Scan{Name(ctx->scanAlt->fixture), Loc(ctx->scanAlt->fixture)});
    if (ctx->exitAlt != nullptr) return MakeStmt(ctx->exitAlt, ir::ExitFunction{});
    return nullptr;
  }

  // ---- the first lines of blocks: the statement without its body
  // functionHead : FUNCTION name=ID ('(' ')')? NEWLINE ;
  ir::StmtPtr FunctionHead(P::FunctionHeadContext* ctx) {
    return MakeStmt(ctx, ir::Function{Name(ctx->name), Loc(ctx->name), {}, {}});
  }
  // forHead : FOR var=ID '=' from=expr TO to=expr (STEP step=expr)? NEWLINE ;
  ir::StmtPtr ForHead(P::ForHeadContext* ctx) {
    if (ctx->from == nullptr || ctx->to == nullptr) return nullptr;
    ir::For loop;
    loop.var = Name(ctx->var);
    loop.var_loc = Loc(ctx->var);
    loop.from = Expr(ctx->from);
    loop.to = Expr(ctx->to);
    loop.step = Expr(ctx->step);
    if (!loop.from || !loop.to) return nullptr;
    return MakeStmt(ctx, std::move(loop));
  }
  // ifHead : IF condition=expr THEN NEWLINE ;   (the If with its first branch)
  ir::StmtPtr IfHead(P::IfHeadContext* ctx) {
    ir::IfBranch first;
    first.loc = s_.Loc(ctx->getStart());
    first.condition = Expr(ctx->condition);
    if (!first.condition) return nullptr;
    ir::If stmt;
    stmt.branches.push_back(std::move(first));
    return MakeStmt(ctx, std::move(stmt));
  }
  // elseIfHead : ELSEIF condition=expr THEN NEWLINE ;
  std::optional<ir::IfBranch> ElseIfHead(P::ElseIfHeadContext* ctx) {
    ir::IfBranch branch;
    branch.loc = s_.Loc(ctx->getStart());
    branch.condition = Expr(ctx->condition);
    if (!branch.condition) return std::nullopt;
    branch.comment = CommentOn(ctx->getStart()->getLine());
    return branch;
  }
  // elseHead : ELSE NEWLINE ;
  ir::IfBranch ElseHead(P::ElseHeadContext* ctx) {
    ir::IfBranch branch;
    branch.loc = s_.Loc(ctx->getStart());
    branch.comment = CommentOn(ctx->getStart()->getLine());
    return branch;
  }
  // cycleHead : CYCLE fixture=ID NEWLINE ;
  ir::StmtPtr CycleHead(P::CycleHeadContext* ctx) {
    return MakeStmt(ctx, ir::Cycle{Name(ctx->fixture), Loc(ctx->fixture), {}, {}});
  }

  std::string Name(const Token* token) const { return token == nullptr ? std::string() : std::string(s_.Text(token)); }
  SourceLoc Loc(const Token* token) const { return token == nullptr ? SourceLoc{} : s_.Loc(token); }

 private:
  // A new statement located at the first token of `ctx`.
  template <typename Node>
  ir::StmtPtr MakeStmt(antlr4::ParserRuleContext* ctx, Node node) {
    auto stmt = std::make_unique<ir::Stmt>();
    stmt->loc = s_.Loc(ctx->getStart());
    stmt->length = s_.Length(ctx->getStart());
    stmt->node = std::move(node);
    return stmt;
  }

  // A NUMBER token: value and whether it was written as a whole number.
  ir::NumberLit Number(const Token* token) {
    ir::NumberLit lit;
    if (token == nullptr) return lit;
    std::string_view text = s_.Text(token);
    lit.is_integer = text.find_first_of(".eE") == std::string_view::npos;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), lit.value);
    (void)end;
    if (ec == std::errc::result_out_of_range) {
      s_.Error(DiagKind::NumberOutOfRange, s_.Range(token), std::string(text));
      lit.value = 0;
    }
    return lit;
  }
  // A NUMBER that must be a whole number (pallet sizes, output numbers).
  int WholeNumber(const Token* token, const char* what) {
    if (token == nullptr) return 0;
    ir::NumberLit lit = Number(token);
    std::string text(s_.Text(token));
    if (!lit.is_integer) {
      s_.Error(DiagKind::WholeNumberRequired, s_.Range(token), std::string(what), text);
      return 0;
    }
    if (lit.value > std::numeric_limits<int>::max()) {
      s_.Error(DiagKind::WholeNumberTooLarge, s_.Range(token), std::string(what), std::numeric_limits<int>::max(),
               text);
      return 0;
    }
    return static_cast<int>(lit.value);
  }
  // coords : XY '(' xSign=('-' | '+')? x=NUMBER ',' ... uSign=('-' | '+')? u=NUMBER ')' ;
  std::optional<ir::Coords> Coords(P::CoordsContext* ctx) {
    if (ctx == nullptr) return std::nullopt;
    const std::array<Token*, 4> numbers = {ctx->x, ctx->y, ctx->z, ctx->u};
    const std::array<Token*, 4> signs = {ctx->xSign, ctx->ySign, ctx->zSign, ctx->uSign};
    for (const Token* number : numbers) {
      if (number == nullptr) return std::nullopt;
    }
    ir::Coords coords;
    coords.loc = s_.Loc(ctx->getStart());
    for (std::size_t i = 0; i < 4; ++i) {
      double value = Number(numbers[i]).value;
      coords.values[i] = signs[i] != nullptr && signs[i]->getType() == P::MINUS ? -value : value;
    }
    return coords;
  }

  // ---- declarations
  // programDecl : PROGRAM name=ID ;
  ir::StmtPtr ProgramDecl(P::ProgramDeclContext* ctx) {
    return MakeStmt(ctx, ir::ProgramDecl{Name(ctx->name), Loc(ctx->name)});
  }
  // unitsDecl : UNITS unit=ID ;
  ir::StmtPtr UnitsDecl(P::UnitsDeclContext* ctx) {
    return MakeStmt(ctx, ir::UnitsDecl{Name(ctx->unit), Loc(ctx->unit)});
  }
  // fixtureDecl : FIXTURE name=ID ;
  ir::StmtPtr FixtureDecl(P::FixtureDeclContext* ctx) {
    return MakeStmt(ctx, ir::FixtureDecl{Name(ctx->name), Loc(ctx->name)});
  }
  // localDecl : LOCAL name=ID '=' origin=coords (IN frame=ID)? ;
  ir::StmtPtr LocalDecl(P::LocalDeclContext* ctx) {
    std::optional<ir::Coords> coords = Coords(ctx->origin);
    if (!coords) return nullptr;
    ir::LocalDecl decl;
    decl.name = Name(ctx->name);
    decl.name_loc = Loc(ctx->name);
    decl.origin = *coords;
    decl.frame = Name(ctx->frame);
    decl.frame_loc = Loc(ctx->frame);
    return MakeStmt(ctx, std::move(decl));
  }
  // pointDecl : taught=TAUGHT? POINT name=ID '=' position=coords (frameKeyword=(IN | ON) frame=ID)? ;
  ir::StmtPtr PointDecl(P::PointDeclContext* ctx) {
    std::optional<ir::Coords> coords = Coords(ctx->position);
    if (!coords) return nullptr;
    ir::PointDecl decl;
    decl.name = Name(ctx->name);
    decl.name_loc = Loc(ctx->name);
    decl.taught = ctx->taught != nullptr;
    decl.coords = *coords;
    decl.frame = Name(ctx->frame);
    decl.frame_loc = Loc(ctx->frame);
    // The IR keeps one frame for both forms, so the keyword must fit the point.
    std::size_t keyword = ctx->frameKeyword != nullptr ? ctx->frameKeyword->getType() : 0;
    if (decl.taught && keyword == P::IN) {
      s_.Error(DiagKind::TaughtPointIn, s_.Range(ctx->frameKeyword), decl.frame);
    }
    if (!decl.taught && keyword == P::ON) {
      s_.Error(DiagKind::ProgrammedPointOn, s_.Range(ctx->frameKeyword), decl.frame, decl.frame);
    }
    return MakeStmt(ctx, std::move(decl));
  }
  // palletDecl : PALLET number=NUMBER ',' corner1=ID ',' corner2=ID ',' corner3=ID
  //              ',' columns=NUMBER ',' rows=NUMBER ;
  ir::StmtPtr PalletDecl(P::PalletDeclContext* ctx) {
    const std::array<Token*, 3> corners = {ctx->corner1, ctx->corner2, ctx->corner3};
    if (ctx->number == nullptr || ctx->columns == nullptr || ctx->rows == nullptr) return nullptr;
    for (const Token* corner : corners) {
      if (corner == nullptr) return nullptr;
    }
    ir::PalletDecl decl;
    decl.number = WholeNumber(ctx->number, "the pallet number");
    decl.number_loc = Loc(ctx->number);
    for (std::size_t i = 0; i < 3; ++i) {
      decl.corners[i] = Name(corners[i]);
      decl.corner_locs[i] = Loc(corners[i]);
    }
    decl.columns = WholeNumber(ctx->columns, "the number of pallet columns");
    decl.columns_loc = Loc(ctx->columns);
    decl.rows = WholeNumber(ctx->rows, "the number of pallet rows");
    decl.rows_loc = Loc(ctx->rows);
    return MakeStmt(ctx, std::move(decl));
  }
  // vacuumDecl : VACUUM output=NUMBER ;
  ir::StmtPtr VacuumDecl(P::VacuumDeclContext* ctx) {
    return MakeStmt(ctx, ir::VacuumDecl{WholeNumber(ctx->output, "the vacuum output"), Loc(ctx->output)});
  }
  // varDecl : type=(INTEGER | REAL) names+=ID (',' names+=ID)* ;
  ir::StmtPtr VarDecl(P::VarDeclContext* ctx) {
    ir::VarDecl decl;
    decl.type = ctx->type != nullptr && ctx->type->getType() == P::REAL ? ir::VarType::Real : ir::VarType::Integer;
    for (const Token* name : ctx->names) {
      decl.names.push_back(Name(name));
      decl.name_locs.push_back(Loc(name));
    }
    return MakeStmt(ctx, std::move(decl));
  }

  // ---- statements
  // assignment : name=ID '=' value=expr ;
  ir::StmtPtr Assignment(P::AssignmentContext* ctx) {
    ir::ExprPtr value = Expr(ctx->value);
    if (!value) return nullptr;
    return MakeStmt(ctx, ir::Assign{Name(ctx->name), std::move(value)});
  }
  // motion : kind=(JUMP | GO | MOVE) target=pointExpr (limzKeyword=LIMZ limz=expr)? ;
  ir::StmtPtr Motion(P::MotionContext* ctx) {
    std::optional<ir::PointExpr> target = Point(ctx->target);
    if (!target) return nullptr;
    ir::Motion motion;
    std::size_t kind = ctx->kind != nullptr ? ctx->kind->getType() : std::size_t{P::JUMP};
    motion.kind = kind == P::GO ? ir::MotionKind::Go : kind == P::MOVE ? ir::MotionKind::Move : ir::MotionKind::Jump;
    motion.target = std::move(*target);
    motion.limz = Expr(ctx->limz);
    motion.limz_loc = Loc(ctx->limzKeyword);
    return MakeStmt(ctx, std::move(motion));
  }
  // pickPlace : kind=(PICK | PLACE) target=pointExpr (VACUUM vacuum=expr)? (LIMZ limz=expr)? ;
  ir::StmtPtr PickPlace(P::PickPlaceContext* ctx) {
    std::optional<ir::PointExpr> target = Point(ctx->target);
    if (!target) return nullptr;
    ir::PickPlace pick;
    pick.kind = ctx->kind != nullptr && ctx->kind->getType() == P::PLACE ? ir::PickPlaceKind::Place
                                                                          : ir::PickPlaceKind::Pick;
    pick.target = std::move(*target);
    pick.vacuum = Expr(ctx->vacuum);
    pick.limz = Expr(ctx->limz);
    return MakeStmt(ctx, std::move(pick));
  }
  // onOff : state=(ON | OFF) bit=expr ;
  ir::StmtPtr OnOff(P::OnOffContext* ctx) {
    ir::ExprPtr bit = Expr(ctx->bit);
    if (!bit) return nullptr;
    bool on = ctx->state != nullptr && ctx->state->getType() == P::ON;
    return MakeStmt(ctx, ir::SetOutput{on, std::move(bit)});
  }
  // waitStmt : WAIT value=expr ;   Sw(n) = On|Off waits for an input, else seconds.
  ir::StmtPtr Wait(P::WaitStmtContext* ctx) {
    ir::ExprPtr expr = Expr(ctx->value);
    if (!expr) return nullptr;
    if (auto* eq = std::get_if<ir::BinaryExpr>(&expr->node); eq != nullptr && eq->op == ir::BinaryOp::Eq) {
      auto* sw = std::get_if<ir::SwitchRead>(&eq->lhs->node);
      auto* state = std::get_if<ir::OnOffLit>(&eq->rhs->node);
      if (sw != nullptr && state != nullptr) return MakeStmt(ctx, ir::WaitSwitch{std::move(sw->bit), state->on});
    }
    return MakeStmt(ctx, ir::WaitTime{std::move(expr)});
  }

  // ---- points
  // pointExpr   : (name=ID | position=coords | pallet=palletPoint) (signs+=('+' | '-') offsets+=offset)* ;
  // palletPoint : PALLET '(' number=expr ',' i=expr (',' j=expr)? ')' ;
  // offset      : axis=ID '(' amount=expr ')' ;
  std::optional<ir::PointExpr> Point(P::PointExprContext* ctx) {
    if (ctx == nullptr) return std::nullopt;
    ir::PointExpr point;
    point.loc = s_.Loc(ctx->getStart());
    if (ctx->name != nullptr) {
      point.base = ir::NamedPoint{Name(ctx->name), s_.Length(ctx->name)};
    } else if (ctx->position != nullptr) {
      std::optional<ir::Coords> coords = Coords(ctx->position);
      if (!coords) return std::nullopt;
      point.base = *coords;
    } else if (P::PalletPointContext* pallet = ctx->pallet) {
      ir::PalletPoint base;
      base.number = Expr(pallet->number);
      base.i = Expr(pallet->i);
      base.j = Expr(pallet->j);
      if (!base.number || !base.i) return std::nullopt;
      point.base = std::move(base);
    } else {
      return std::nullopt;
    }
    // Each offset follows its sign token.
    for (std::size_t k = 0; k < ctx->offsets.size(); ++k) {
      P::OffsetContext* offset = ctx->offsets[k];
      const Token* sign = k < ctx->signs.size() ? ctx->signs[k] : nullptr;
      if (offset == nullptr || offset->axis == nullptr || sign == nullptr) return std::nullopt;
      ir::PointOffset out;
      out.loc = s_.Loc(sign);
      out.negative = sign->getType() == P::MINUS;
      std::string axis = Name(offset->axis);
      if (axis == "x" || axis == "X") {
        out.axis = ir::Axis::X;
      } else if (axis == "y" || axis == "Y") {
        out.axis = ir::Axis::Y;
      } else if (axis == "z" || axis == "Z") {
        out.axis = ir::Axis::Z;
      } else if (axis == "u" || axis == "U") {
        out.axis = ir::Axis::U;
      } else {
        s_.Error(DiagKind::UnknownOffsetAxis, s_.Range(offset->axis), axis);
      }
      out.amount = Expr(offset->amount);
      if (!out.amount) return std::nullopt;
      point.offsets.push_back(std::move(out));
    }
    return point;
  }

  // ---- expressions
  ir::ExprPtr NewExpr(antlr4::ParserRuleContext* ctx) {
    auto expr = std::make_unique<ir::Expr>();
    const Token* start = ctx->getStart();
    const Token* stop = ctx->getStop();
    expr->loc = s_.Loc(start);
    std::size_t begin = start->getStartIndex();
    std::size_t end = stop != nullptr ? stop->getStopIndex() : begin;
    expr->length = end >= begin ? static_cast<std::uint32_t>(end - begin + 1) : s_.Length(start);
    return expr;
  }
  template <typename Node>
  ir::ExprPtr MakeExpr(antlr4::ParserRuleContext* ctx, Node node) {
    ir::ExprPtr expr = NewExpr(ctx);
    expr->node = std::move(node);
    return expr;
  }

  // expr : ... (one labelled alternative per kind of context).
  ir::ExprPtr Expr(P::ExprContext* ctx) {
    if (ctx == nullptr) return nullptr;
    // An expression of one token can only be a number, a name or On/Off:
    // no search for its kind of context (most expressions are one number).
    if (ctx->getStart() == ctx->getStop()) {
      Token* token = ctx->getStart();
      switch (token->getType()) {
        case P::NUMBER: return MakeExpr(ctx, Number(token));               //  | NUMBER
        case P::ID: return MakeExpr(ctx, ir::VariableRef{Name(token)});   //  | ID
        case P::ON: return MakeExpr(ctx, ir::OnOffLit{true});              //  | (ON | OFF)
        case P::OFF: return MakeExpr(ctx, ir::OnOffLit{false});
        default: return nullptr;
      }
    }
    //      | lhs=expr op=(...) rhs=expr
    if (auto* binary = dynamic_cast<P::BinaryExprContext*>(ctx)) return Binary(binary);
    //      | op=('-' | '+' | NOT) operand=expr
    if (auto* unary = dynamic_cast<P::UnaryExprContext*>(ctx)) {
      ir::ExprPtr operand = Expr(unary->operand);
      if (!operand || unary->op == nullptr) return nullptr;
      std::size_t op = unary->op->getType();
      return MakeExpr(unary, ir::UnaryExpr{op == P::MINUS  ? ir::UnaryOp::Negate
                                           : op == P::PLUS ? ir::UnaryOp::Plus
                                                           : ir::UnaryOp::Not,
                                           std::move(operand)});
    }
    // expr : '(' inner=expr ')'  (the parentheses leave no node)
    if (auto* paren = dynamic_cast<P::ParenExprContext*>(ctx)) return Expr(paren->inner);
    //      | SW '(' bit=expr ')'
    if (auto* sw = dynamic_cast<P::SwitchExprContext*>(ctx)) {
      ir::ExprPtr bit = Expr(sw->bit);
      if (!bit) return nullptr;
      return MakeExpr(sw, ir::SwitchRead{std::move(bit)});
    }
    return nullptr;
  }

  ir::ExprPtr Binary(P::BinaryExprContext* ctx) {
    if (ctx->lhs == nullptr || ctx->rhs == nullptr || ctx->op == nullptr) return nullptr;
    ir::ExprPtr lhs = Expr(ctx->lhs);
    ir::ExprPtr rhs = Expr(ctx->rhs);
    if (!lhs || !rhs) return nullptr;
    ir::BinaryOp op;
    switch (ctx->op->getType()) {
      case P::PLUS: op = ir::BinaryOp::Add; break;
      case P::MINUS: op = ir::BinaryOp::Sub; break;
      case P::STAR: op = ir::BinaryOp::Mul; break;
      case P::SLASH: op = ir::BinaryOp::Div; break;
      case P::MOD: op = ir::BinaryOp::Mod; break;
      case P::EQ: op = ir::BinaryOp::Eq; break;
      case P::NE: op = ir::BinaryOp::Ne; break;
      case P::LT: op = ir::BinaryOp::Lt; break;
      case P::GT: op = ir::BinaryOp::Gt; break;
      case P::LE: op = ir::BinaryOp::Le; break;
      case P::GE: op = ir::BinaryOp::Ge; break;
      case P::AND: op = ir::BinaryOp::And; break;
      case P::OR: op = ir::BinaryOp::Or; break;
      case P::XOR: op = ir::BinaryOp::Xor; break;
      default: return nullptr;
    }
    return MakeExpr(ctx, ir::BinaryExpr{op, std::move(lhs), std::move(rhs)});
  }

  Session& s_;
};

// ------------------------------------------------------------------ step 3: the blocks

// A block's statements plus its comment lines and blank-line marks, built
// line by line: Begin() and End() each statement in order, then Finish() at
// the line that closes the block (past the end of the file for the top level).
class BlockWalker {
 public:
  BlockWalker(const Session& session, const IrBuilder& ir, std::uint32_t first)
      : s_(&session), ir_(&ir), line_(first) {}

  // Whether a statement starting on `start` joins the block (not when the
  // block already holds a statement ending on that line: a block the
  // pre-scan closed there). Adds the comment and blank lines before it.
  bool Begin(std::uint32_t start) {
    if (start < line_) return false;
    Until(start);
    return true;
  }
  // The statement that began on `start` and ends on `stop` (null: dropped).
  void End(std::uint32_t start, std::uint32_t stop, ir::StmtPtr stmt) {
    if (stmt) {
      stmt->blank_line_before = blank_;
      stmt->trailing_comment = ir_->CommentOn(start);
      block_.push_back(std::move(stmt));
    }
    blank_ = false;
    line_ = std::max(start, stop) + 1;
  }
  ir::Block Finish(std::uint32_t end) {
    Until(end);
    return std::move(block_);
  }

 private:
  // The comment lines and blank lines before `end`.
  void Until(std::uint32_t end) {
    for (; line_ < end; ++line_) {
      const Line* info = s_->LineAt(line_);
      if (info != nullptr && !info->had_code && info->comment >= 0) {
        ir::StmtPtr stmt = ir_->CommentLine(line_);
        stmt->blank_line_before = blank_;
        block_.push_back(std::move(stmt));
        blank_ = false;
      } else {
        blank_ = info != nullptr && !info->had_code && info->comment < 0;
      }
    }
  }

  const Session* s_;
  const IrBuilder* ir_;
  std::uint32_t line_;
  bool blank_ = false;
  ir::Block block_;
};

// The open blocks, innermost last, each with its statement so far: the IR
// of its first line (and of an If's ElseIf and Else lines); the bodies come
// when the block closes. A block whose first line has an error is dropped,
// as is an If with an ElseIf line that has one; their lines are still
// parsed (for their errors) but not built.
class BlockBuilder {
 public:
  BlockBuilder(const Session& session, const IrBuilder& ir) : s_(session), ir_(ir) {
    frames_.push_back(Frame{0, BlockWalker(session, ir, 1), false, true, 0, nullptr});
  }

  // A line that is one statement (or declaration); build(ctx) makes its IR.
  template <typename Build>
  void Statement(std::uint32_t line, Build&& build) {
    Frame& frame = frames_.back();
    if (!frame.keep || !frame.body.Begin(line)) return;
    frame.body.End(line, line, s_.LineHasError(line) ? nullptr : build());
  }

  // The first line of a block; head() makes its statement without the body
  // (null drops the block).
  template <typename Head>
  void Open(std::size_t type, std::uint32_t line, Head&& head) {
    Frame& outer = frames_.back();
    Frame frame{type, BlockWalker(s_, ir_, line + 1), false, false, line, nullptr};
    frame.joined = outer.keep && outer.body.Begin(line);
    if (frame.joined && !s_.LineHasError(line)) frame.stmt = head();
    frame.keep = frame.stmt != nullptr;
    frames_.push_back(std::move(frame));
  }

  // An ElseIf line of the innermost If; branch() makes its branch (nullopt
  // drops the If).
  template <typename Branch>
  void ElseIf(std::uint32_t line, Branch&& branch) {
    Frame& frame = Innermost(P::IF);
    if (!frame.keep) return;
    ir::If& stmt = std::get<ir::If>(frame.stmt->node);
    stmt.branches.back().body = frame.body.Finish(line);
    std::optional<ir::IfBranch> next;
    if (!s_.LineHasError(line)) next = branch();
    if (!next) return Drop(frame);
    stmt.branches.push_back(std::move(*next));
    frame.body = BlockWalker(s_, ir_, line + 1);
  }
  // The Else line of the innermost If.
  void Else(std::uint32_t line, ir::IfBranch branch) {
    Frame& frame = Innermost(P::IF);
    if (!frame.keep) return;
    ir::If& stmt = std::get<ir::If>(frame.stmt->node);
    stmt.branches.back().body = frame.body.Finish(line);
    stmt.branches.push_back(std::move(branch));
    frame.body = BlockWalker(s_, ir_, line + 1);
  }
  bool AtTopLevel() const { return frames_.size() == 1; }

  // Closes the innermost block (of type `type`) on line `line`: its Fend,
  // Next, EndIf or EndCycle there, or one the pre-scan added.
  void Close(std::size_t type, std::uint32_t line, ir::BlockEnd end, std::string next_var = {},
             SourceLoc next_var_loc = {}) {
    Frame frame = std::move(Innermost(type));
    frames_.pop_back();
    if (frame.keep) {
      ir::Block body = frame.body.Finish(line);
      std::visit(
          [&](auto& node) {
            using Node = std::decay_t<decltype(node)>;
            if constexpr (std::is_same_v<Node, ir::Function> || std::is_same_v<Node, ir::Cycle>) {
              node.body = std::move(body);
              node.end = std::move(end);
            } else if constexpr (std::is_same_v<Node, ir::For>) {
              node.body = std::move(body);
              node.end = std::move(end);
              node.next_var = std::move(next_var);
              node.next_var_loc = next_var_loc;
            } else if constexpr (std::is_same_v<Node, ir::If>) {
              node.branches.back().body = std::move(body);
              node.end = std::move(end);
            }
          },
          frame.stmt->node);
    }
    if (frame.joined) frames_.back().body.End(frame.start, line, std::move(frame.stmt));
  }

  ir::Block Finish(std::uint32_t end) {
    SMTCAL_CHECK(frames_.size() == 1, "the pre-scan closes every block");
    return frames_.back().body.Finish(end);
  }

 private:
  struct Frame {
    std::size_t type;     // FUNCTION, FOR, IF or CYCLE; 0 for the top level
    BlockWalker body;     // the block (an If's current branch)
    bool joined = false;  // its statement has its place in the block around it
    bool keep = true;     // its lines are built (false: the block is dropped)
    std::uint32_t start = 0;  // its first line
    ir::StmtPtr stmt;     // the statement, while it is kept
  };

  Frame& Innermost(std::size_t type) {
    SMTCAL_CHECK(frames_.size() > 1 && frames_.back().type == type, "the pre-scan keeps the blocks well nested");
    return frames_.back();
  }
  static void Drop(Frame& frame) {
    frame.keep = false;
    frame.stmt.reset();
  }

  const Session& s_;
  const IrBuilder& ir_;
  std::vector<Frame> frames_;
};

// ------------------------------------------------------------------ driver

class LineParser {
 public:
  explicit LineParser(Session& session, antlr4::ANTLRErrorListener& listener,
                      std::shared_ptr<antlr4::ANTLRErrorStrategy> strategy)
      : tokens_(session), parser_(&tokens_) {
    parser_.removeErrorListeners();
    parser_.addErrorListener(&listener);
    parser_.setErrorHandler(std::move(strategy));
    // The IR is built from the rules' labelled elements (and contexts know
    // their parents without it): no child lists, no node per token.
    parser_.setBuildParseTree(false);
  }
  // Parses `line` with `rule`; the tree lives until the next call.
  template <typename Context>
  Context* Parse(const Line& line, Context* (PlaceParser::*rule)()) {
    tokens_.Start(line);
    parser_.reset();  // frees the previous line's tree, starts at the first token
    return (parser_.*rule)();
  }

 private:
  LineTokens tokens_;
  PlaceParser parser_;
};

ir::Program Session::Run() {
  ir::Program program;
  program.file = file_;
  SplitLines();
  PreScan();
  try {
    SyntaxErrorListener listener(*this);
    LineParser parser(*this, listener, std::make_shared<LineErrorStrategy>(*this));
    IrBuilder ir(*this);
    BlockBuilder blocks(*this, ir);
    auto close_added = [&](std::span<const Closer> closers) {
      for (const Closer& closer : closers) {
        const PlaceToken& at = At(closer.at);
        std::size_t opener = closer.type == P::FEND ? P::FUNCTION
                             : closer.type == P::NEXT ? P::FOR
                             : closer.type == P::ENDIF ? P::IF
                                                      : P::CYCLE;
        blocks.Close(opener, at.line, ir.End(at));
      }
    };
    for (std::uint32_t n = 1; n < lines_.size(); ++n) {
      const Line& line = lines_[n];
      close_added(ClosersBefore(line));
      if (line.empty()) continue;
      // A block's first line: its rule, and the IR of its statement.
      auto open = [&](std::size_t type, auto rule, auto head) {
        auto* ctx = parser.Parse(line, rule);
        blocks.Open(type, n, [&] { return (ir.*head)(ctx); });
      };
      // A block's last line (Fend, EndIf, EndCycle; Next has its variable).
      auto close = [&](std::size_t type, auto rule) {
        blocks.Close(type, n, ir.End(parser.Parse(line, rule)->getStart()));
      };
      switch (TypeOf(At(line.first))) {
        case P::FUNCTION: open(P::FUNCTION, &PlaceParser::functionHead, &IrBuilder::FunctionHead); break;
        case P::FOR: open(P::FOR, &PlaceParser::forHead, &IrBuilder::ForHead); break;
        case P::IF: open(P::IF, &PlaceParser::ifHead, &IrBuilder::IfHead); break;
        case P::CYCLE: open(P::CYCLE, &PlaceParser::cycleHead, &IrBuilder::CycleHead); break;
        case P::ELSEIF: {
          P::ElseIfHeadContext* head = parser.Parse(line, &PlaceParser::elseIfHead);
          blocks.ElseIf(n, [&] { return ir.ElseIfHead(head); });
          break;
        }
        case P::ELSE: blocks.Else(n, ir.ElseHead(parser.Parse(line, &PlaceParser::elseHead))); break;
        case P::FEND: close(P::FUNCTION, &PlaceParser::fendLine); break;
        case P::NEXT: {
          P::NextLineContext* next = parser.Parse(line, &PlaceParser::nextLine);
          blocks.Close(P::FOR, n, ir.End(next->getStart()), ir.Name(next->var), ir.Loc(next->var));
          break;
        }
        case P::ENDIF: close(P::IF, &PlaceParser::endIfLine); break;
        case P::ENDCYCLE: close(P::CYCLE, &PlaceParser::endCycleLine); break;
        default:
          if (blocks.AtTopLevel()) {
            P::DeclarationLineContext* decl = parser.Parse(line, &PlaceParser::declarationLine);
            blocks.Statement(n, [&] { return ir.Declaration(decl); });
          } else {
            P::StatementLineContext* stmt = parser.Parse(line, &PlaceParser::statementLine);
            blocks.Statement(n, [&] { return ir.Statement(stmt); });
          }
      }
    }
    close_added(ClosersAtEnd());
    program.items = blocks.Finish(last_line() + 1);
  } catch (const antlr4::RuntimeException& e) {
    // ANTLR gave up in a way its recovery does not cover; say so plainly.
    Error(DiagKind::SyntaxError, SourceLoc{file_, 0, 0},
          fmt::format("the parser stopped ({}); fix the other errors and try again", e.what()));
  }
  Flush();
  return program;
}

void Session::Flush() {
  std::stable_sort(errors_.begin(), errors_.end(), [](const PendingError& a, const PendingError& b) {
    return a.loc.line != b.loc.line ? a.loc.line < b.loc.line : a.loc.column < b.loc.column;
  });
  for (std::size_t i = 0; i < errors_.size() && i < kMaxSyntaxErrors; ++i) {
    Diagnostic* diag = errors_[i].emit(diags_);
    for (auto& [range, text] : errors_[i].notes) Diagnostics::AddNote(diag, range, text);
  }
  if (errors_.size() > kMaxSyntaxErrors) {
    diags_.Report(DiagKind::TooManySyntaxErrors, SourceLoc{file_, 0, 0});
  }
}

}  // namespace

ir::Program ParseTokens(std::uint32_t file, LexedPlace lexed, Diagnostics& diags) {
  return Session(file, std::move(lexed), diags).Run();
}

ir::Program ParseProgram(std::uint32_t file, Diagnostics& diags) {
  const std::string& text = diags.sources().File(file).text;
  if (text.size() >= UINT32_MAX) {
    diags.Report(DiagKind::SyntaxError, SourceLoc{file, 0, 0},
                 fmt::format("the file has {} bytes; smtcal reads .place files of less than 4 GiB, so split the "
                             "program into several files",
                             text.size()));
    ir::Program program;
    program.file = file;
    return program;
  }
  if (ReportOtherInputKind(file, {InputKind::kProgram}, "a .place program", diags)) {
    ir::Program program;
    program.file = file;
    return program;
  }
  return ParseTokens(file, LexPlace(text), diags);
}

}  // namespace smtcal
