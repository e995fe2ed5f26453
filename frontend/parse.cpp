// The .place parser: source text -> ir::Program, mistakes -> Diagnostics.
//
// Three steps, each working on the output of the one before:
//  1. Lex the whole file. The bytes go to ANTLR one byte per code point, so
//     ANTLR's columns are byte columns and invalid UTF-8 cannot throw.
//  2. Check the line structure (PreScan). .place has one statement per line,
//     and blocks open and close with the first word of a line, so block
//     mistakes ("Next" without "For", a missing "EndIf", a Point declared
//     inside a Function) are found here, with messages that name the block.
//     The pre-scan repairs what it reports -- it drops stray lines, inserts
//     the missing closers and cuts over-long expressions -- so ANTLR always
//     sees well-nested blocks, its errors stay inside one line, and its
//     recursion depth stays bounded.
//  3. Parse with ANTLR, one top-level line (a declaration or a whole
//     Function) at a time, turning each into IR and freeing its parse tree
//     before the next. Errors are recovered at the end of their line
//     (LineErrorStrategy) and rewritten into plain words from the rule and
//     the expected tokens (SyntaxErrorListener). One visitor (IrBuilder)
//     builds the IR; a statement whose line has a syntax error is dropped.
// All syntax errors are collected, sorted by position and capped, so a file
// of garbage gives a few clear errors. No ANTLR type or exception leaves
// this file.
#include "frontend/parse.h"

#include <algorithm>
#include <charconv>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <vector>

#include <fmt/format.h>

// ANTLR's headers #undef the EOF macro of <cstdio>; they come after every
// standard header that might include it.
#include "PlaceBaseVisitor.h"
#include "PlaceLexer.h"
#include "PlaceParser.h"

namespace smtcal {
namespace {

using antlr4::Token;
using grammar::PlaceLexer;
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

// Feeds ANTLR the file's bytes, one code point per byte. A UTF-8 byte order
// mark becomes three spaces, so it is skipped and columns stay byte columns.
class ByteStream : public antlr4::ANTLRInputStream {
 public:
  explicit ByteStream(std::string_view text) {
    _data.reserve(text.size());
    for (unsigned char c : text) _data.push_back(c);
    if (text.substr(0, 3) == "\xEF\xBB\xBF") _data[0] = _data[1] = _data[2] = U' ';
    p = 0;
  }
};

// ------------------------------------------------------------------ the session

struct PendingError {
  SourceLoc loc;
  std::function<Diagnostic*(Diagnostics&)> emit;
  std::vector<std::pair<SourceRange, std::string>> notes;
};

// One source line as the lexer saw it.
struct Line {
  std::vector<Token*> code;   // default-channel tokens except the NEWLINE
  Token* newline = nullptr;   // absent on the last line without a newline
  Token* comment = nullptr;   // the ' comment, if any
  bool had_code = false;      // the line held a statement (even if dropped)
  bool error = false;         // a syntax error was reported on this line
  std::vector<std::unique_ptr<Token>> insert_before;  // closers the pre-scan adds
};

// A block the pre-scan has seen open.
struct OpenBlock {
  std::size_t type;  // FUNCTION, FOR, IF or CYCLE
  Token* opener;
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
  Session(std::uint32_t file, Diagnostics& diags)
      : file_(file), diags_(diags), text_(diags.sources().File(file).text) {}

  ir::Program Run();

  // --- tokens and locations
  std::string_view Text(const Token* token) const {
    if (synthetic_.count(token) != 0) return Spelling(token->getType());
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
  // "'Jump'", "end of line" or "end of file": how a found token is named.
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
  std::uint32_t file() const { return file_; }
  std::uint32_t last_line() const { return static_cast<std::uint32_t>(lines_.size() - 1); }

  // Reports an ANTLR parse error in plain words (SyntaxErrorListener).
  void ReportParseError(antlr4::Parser* parser, antlr4::ParserRuleContext* ctx, Token* found,
                        const antlr4::misc::IntervalSet& expected, bool deep);

 private:
  void Lex(antlr4::ANTLRErrorListener& listener);
  void PreScan();
  void CheckCharacters(Line& line);
  void CheckExpressionSize(Line& line);
  void CheckStructure(Line& line, std::vector<OpenBlock>& stack, bool& misplaced_run);
  bool IfHasBlock(std::size_t if_line) const;
  void CloseBlocksAbove(std::size_t keep, std::vector<OpenBlock>& stack, Line& line, Token* at, bool quiet);
  // Error(), unless the line already has one: one error per line.
  template <typename... Args>
  void LineError(const Line& line, DiagKind kind, SourceRange range, Args... args) {
    if (!line.error) Error(kind, range, args...);
  }
  void Drop(Line& line) { line.code.clear(); line.error = true; }
  void CloseAtEndOfFile(std::vector<OpenBlock>& stack, bool report);
  std::unique_ptr<Token> MakeToken(std::size_t type, const Token* at);
  std::vector<std::unique_ptr<Token>> ParserTokens();
  void Flush();

  std::uint32_t file_;
  Diagnostics& diags_;
  const std::string& text_;
  std::unique_ptr<ByteStream> stream_;
  std::unique_ptr<PlaceLexer> lexer_;
  std::vector<std::unique_ptr<Token>> lexed_;  // every token the lexer made
  std::vector<Line> lines_;                    // by line number; [0] unused
  std::vector<std::unique_ptr<Token>> tail_;   // closers added at end of file
  std::unordered_set<const Token*> synthetic_;
  std::vector<PendingError> errors_;
};

// ------------------------------------------------------------------ step 1: lex

void Session::Lex(antlr4::ANTLRErrorListener& listener) {
  stream_ = std::make_unique<ByteStream>(text_);
  lexer_ = std::make_unique<PlaceLexer>(stream_.get());
  // BAD_CHAR takes any byte no other token does, so the lexer has nothing to
  // report; should it ever, the message goes through our listener.
  lexer_->removeErrorListeners();
  lexer_->addErrorListener(&listener);
  for (;;) {
    std::unique_ptr<Token> token = lexer_->nextToken();
    bool eof = token->getType() == Token::EOF;
    // Remember each token's place in lexed_, so ParserTokens() can move it.
    static_cast<antlr4::CommonToken*>(token.get())->setTokenIndex(lexed_.size());
    lexed_.push_back(std::move(token));
    if (eof) break;
  }
  std::size_t lines = std::max<std::size_t>(lexed_.back()->getLine(), 1) + 1;
  lines_.resize(lines);
  for (const auto& token : lexed_) {
    Line& line = lines_[std::min<std::size_t>(token->getLine(), lines - 1)];
    switch (token->getType()) {
      case Token::EOF: break;
      case P::NEWLINE: line.newline = token.get(); break;
      case P::COMMENT: line.comment = token.get(); break;
      default:
        line.code.push_back(token.get());
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
    CheckCharacters(line);
    if (line.code.empty()) continue;
    CheckStructure(line, stack, misplaced_run);
    CheckExpressionSize(line);
    if (stack.size() > kMaxBlockDepth) {
      // Stop here: drop this line and the rest, close what is open silently.
      Error(DiagKind::BlocksTooDeep, Range(stack.back().opener), kMaxBlockDepth);
      for (std::size_t rest = n + 1; rest < lines_.size(); ++rest) lines_[rest].code.clear();
      stack.pop_back();
      Drop(line);
      return CloseAtEndOfFile(stack, false);
    }
  }
  CloseAtEndOfFile(stack, true);
}

// Closes the blocks still open at the end of the file, innermost first.
void Session::CloseAtEndOfFile(std::vector<OpenBlock>& stack, bool report) {
  const Token* eof = lexed_.back().get();
  while (!stack.empty()) {
    const OpenBlock& open = stack.back();
    std::size_t closer = CloserOf(open.type);
    if (report) {
      ErrorElsewhere(DiagKind::MissingBlockEndAtEof, Range(open.opener), std::string(Spelling(closer)),
                     Describe(open), open.opener->getLine());
    }
    tail_.push_back(MakeToken(P::NEWLINE, eof));
    tail_.push_back(MakeToken(closer, eof));
    stack.pop_back();
  }
  if (!tail_.empty()) tail_.push_back(MakeToken(P::NEWLINE, eof));
}

// BAD_CHAR tokens: one error for the first per line (a UTF-8 sequence is one
// character); all of them leave the line so ANTLR never sees them.
void Session::CheckCharacters(Line& line) {
  bool reported = false;
  std::vector<Token*> kept;
  for (Token* token : line.code) {
    if (token->getType() != P::BAD_CHAR) {
      kept.push_back(token);
      continue;
    }
    if (reported) continue;
    reported = true;
    std::size_t at = token->getStartIndex();
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
  line.code = std::move(kept);
}

// Counts operators and '(' on the line; cuts the line where the count
// passes the limit, so ANTLR's recursion stays bounded.
void Session::CheckExpressionSize(Line& line) {
  int count = 0;
  for (std::size_t i = 0; i < line.code.size(); ++i) {
    std::size_t type = line.code[i]->getType();
    if (type == P::LPAREN || type == P::NOT || IsBinaryOperator(type)) ++count;
    if (count > kMaxExpressionSize) {
      LineError(line, DiagKind::ExpressionTooBig, Range(line.code[i]), kMaxExpressionSize);
      line.code.resize(i);
      return;
    }
  }
}

std::unique_ptr<Token> Session::MakeToken(std::size_t type, const Token* at) {
  // A real source: ANTLR's recovery asks a token for its source when it
  // conjures a missing token next to it.
  std::pair<antlr4::TokenSource*, antlr4::CharStream*> source(lexer_.get(), stream_.get());
  auto token = std::make_unique<antlr4::CommonToken>(source, type, Token::DEFAULT_CHANNEL, at->getStartIndex(),
                                                     at->getStartIndex());
  token->setLine(at->getLine());
  token->setCharPositionInLine(at->getCharPositionInLine());
  token->setText(std::string(type == P::NEWLINE ? "\n" : Spelling(type)));
  synthetic_.insert(token.get());
  return token;
}

void Session::CloseBlocksAbove(std::size_t keep, std::vector<OpenBlock>& stack, Line& line, Token* at,
                               bool quiet) {
  while (stack.size() > keep) {
    const OpenBlock& open = stack.back();
    std::size_t closer = CloserOf(open.type);
    std::string what = Describe(open);
    if (!quiet) {
      PendingError& error = Error(DiagKind::MissingBlockEnd, Range(at), std::string(Spelling(closer)), what,
                                  open.opener->getLine());
      error.notes.emplace_back(Range(open.opener), fmt::format("{} starts here", what));
    }
    line.insert_before.push_back(MakeToken(closer, at));
    line.insert_before.push_back(MakeToken(P::NEWLINE, at));
    stack.pop_back();
  }
}

// The block structure, from the first token of each line.
void Session::CheckStructure(Line& line, std::vector<OpenBlock>& stack, bool& misplaced_run) {
  Token* first = line.code.front();
  std::size_t type = first->getType();
  bool quiet = line.error;  // a bad character was reported on this line
  std::size_t second = line.code.size() > 1 ? line.code[1]->getType() : std::size_t{P::NEWLINE};
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
  // "If c Then Jump P": THEN before the end of the line.
  auto then_not_last = [&]() -> Token* {
    for (std::size_t i = 0; i + 1 < line.code.size(); ++i) {
      if (line.code[i]->getType() == P::THEN) return line.code[i];
    }
    return nullptr;
  };
  auto cut_after = [&](Token* token) {
    auto end = std::find(line.code.begin(), line.code.end(), token) + 1;
    line.code.erase(end, line.code.end());
  };

  switch (type) {
    case P::FUNCTION: {
      CloseBlocksAbove(0, stack, line, first, quiet);
      misplaced_run = false;
      std::string name = second == P::ID ? std::string(Text(line.code[1])) : std::string();
      stack.push_back({type, first, std::move(name), false});
      return;
    }
    case P::FOR:
    case P::IF:
    case P::CYCLE:
      if (stack.empty()) return misplaced(fmt::format("'{}'", Spelling(type)));
      if (Token* then = type == P::IF ? then_not_last() : nullptr) {
        LineError(line, DiagKind::SingleLineIf, Range(then), "Then");
        // A block If with something after Then keeps its header; a SPEL
        // single-line If (no EndIf follows) opens no block.
        if (!IfHasBlock(then->getLine())) return Drop(line);
        cut_after(then);
      }
      stack.push_back({type, first, {}, false});
      return;
    case P::ELSEIF:
    case P::ELSE: {
      if (stack.empty() && misplaced_run) return Drop(line);
      std::ptrdiff_t at = innermost(P::IF);
      if (at < 0) {
        LineError(line, DiagKind::UnexpectedBlockEnd, Range(first), std::string(Spelling(type)), "If");
        return Drop(line);
      }
      CloseBlocksAbove(static_cast<std::size_t>(at) + 1, stack, line, first, quiet);
      if (stack.back().seen_else) {
        LineError(line, DiagKind::ElseAfterElse, Range(first), std::string(Spelling(type)),
                  stack.back().opener->getLine());
        return Drop(line);
      }
      if (type == P::ELSE) stack.back().seen_else = true;
      if (Token* then = type == P::ELSEIF ? then_not_last() : nullptr) {
        LineError(line, DiagKind::SingleLineIf, Range(then), "Then");
        cut_after(then);
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
      CloseBlocksAbove(static_cast<std::size_t>(at) + 1, stack, line, first, quiet);
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
    if (lines_[n].code.empty()) continue;
    switch (lines_[n].code.front()->getType()) {
      case P::FOR: case P::CYCLE: ++depth; break;
      case P::IF: {
        const std::vector<Token*>& code = lines_[n].code;
        if (code.back()->getType() == P::THEN) ++depth;
        break;
      }
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

// The token list ANTLR parses: the kept code of each line, the closers the
// pre-scan inserted, the NEWLINEs and EOF. The tokens move out of lexed_;
// the objects stay put, so Line's pointers (and the comments, which stay in
// lexed_) remain valid.
std::vector<std::unique_ptr<Token>> Session::ParserTokens() {
  std::vector<std::unique_ptr<Token>> out;
  const Token* eof = lexed_.back().get();  // never moved: no line holds it
  auto take = [&](Token* token) { out.push_back(std::move(lexed_[token->getTokenIndex()])); };
  for (Line& line : lines_) {
    for (auto& token : line.insert_before) out.push_back(std::move(token));
    for (Token* token : line.code) take(token);
    if (line.newline != nullptr) take(line.newline);
  }
  // The grammar wants every line to end in NEWLINE (see Place.g4).
  if (out.empty() || out.back()->getType() != P::NEWLINE) out.push_back(MakeToken(P::NEWLINE, eof));
  for (auto& token : tail_) out.push_back(std::move(token));
  out.push_back(MakeToken(Token::EOF, eof));
  return out;
}

// ------------------------------------------------------------------ step 3: ANTLR errors

// Recovery by line: after an error, skip to the end of the line and let the
// enclosing rules finish there. Never deletes a NEWLINE, so a mistake cannot
// pull the next line into this statement.
class LineErrorStrategy : public antlr4::DefaultErrorStrategy {
 public:
  explicit LineErrorStrategy(Session& session) : session_(session) {}

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

// The nearest enclosing context of type C within the statement.
template <typename C>
C* Find(antlr4::RuleContext* ctx) {
  for (antlr4::RuleContext* c = ctx; c != nullptr; c = dynamic_cast<antlr4::RuleContext*>(c->parent)) {
    if (auto* found = dynamic_cast<C*>(c)) return found;
    if (dynamic_cast<P::BlockContext*>(c) != nullptr || dynamic_cast<P::ProgramContext*>(c) != nullptr) break;
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
  if (Find<P::VarDeclContext>(ctx) || Find<P::ForHeadContext>(ctx) || Find<P::ForStmtContext>(ctx)) {
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
    if (dynamic_cast<P::BlockContext*>(c) || dynamic_cast<P::ProgramContext*>(c)) break;
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
    for (auto* number : coords->signedNumber()) numbers += number->NUMBER() != nullptr ? 1 : 0;
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

// ------------------------------------------------------------------ step 3: the IR

// The one visitor: parse tree -> IR. Each visit leaves the IR piece it
// built (an empty one when the tree is incomplete after an error) in a
// member slot and returns an empty antlrcpp::Any: boxing every piece in an
// Any would cost a heap allocation and a dynamic_cast per node.
class IrBuilder : public grammar::PlaceBaseVisitor {
 public:
  explicit IrBuilder(Session& session) : s_(session) {}

  // A block's statements plus its comment lines and blank-line marks, built
  // line by line: Add() each statement in order, then Finish() at the line
  // that closes the block (past the end of the file for the top level).
  class BlockWalker {
   public:
    BlockWalker(IrBuilder& builder, std::uint32_t first) : b_(builder), line_(first) {}
    void Add(antlr4::ParserRuleContext* item) {
      std::uint32_t start = StartLine(item);
      if (start < line_) return;  // a second statement on one line: an error
      Until(start);
      if (!b_.s_.LineHasError(start)) {
        if (ir::StmtPtr stmt = b_.Stmt(item)) {
          stmt->blank_line_before = blank_;
          stmt->trailing_comment = b_.CommentOn(start);
          block_.push_back(std::move(stmt));
        }
      }
      blank_ = false;
      line_ = std::max(start + 1, StopLine(item) + 1);
    }
    ir::Block Finish(std::uint32_t end) {
      Until(end);
      return std::move(block_);
    }

   private:
    // The comment lines and blank lines before `end`.
    void Until(std::uint32_t end) {
      for (; line_ < end; ++line_) {
        const Line* info = b_.s_.LineAt(line_);
        if (info != nullptr && !info->had_code && info->comment != nullptr) {
          auto stmt = std::make_unique<ir::Stmt>();
          stmt->loc = b_.s_.Loc(info->comment);
          stmt->length = b_.s_.Length(info->comment);
          stmt->blank_line_before = blank_;
          stmt->node = ir::Comment{b_.CommentOn(line_)};
          block_.push_back(std::move(stmt));
          blank_ = false;
        } else {
          blank_ = info != nullptr && !info->had_code && info->comment == nullptr;
        }
      }
    }

    IrBuilder& b_;
    std::uint32_t line_;
    bool blank_ = false;
    ir::Block block_;
  };

 private:
  // ---- helpers
  antlrcpp::Any Yield(ir::ExprPtr expr) {
    expr_ = std::move(expr);
    return {};
  }
  antlrcpp::Any Yield(ir::StmtPtr stmt) {
    stmt_ = std::move(stmt);
    return {};
  }
  antlrcpp::Any Yield(std::optional<ir::PointExpr> point) {
    point_ = std::move(point);
    return {};
  }
  // Visits ctx; its visit method leaves the result in a slot via Yield.
  void Accept(antlr4::ParserRuleContext* ctx) {
    antlrcpp::Any boxed = ctx->accept(this);
    SMTCAL_CHECK(boxed.isNull(), "a visit returned its IR in the Any instead of through Yield");
  }
  ir::ExprPtr Expr(P::ExprContext* ctx) {
    if (ctx == nullptr) return nullptr;
    expr_.reset();
    Accept(ctx);
    return std::move(expr_);
  }
  std::optional<ir::PointExpr> Point(P::PointExprContext* ctx) {
    if (ctx == nullptr) return std::nullopt;
    point_.reset();
    Accept(ctx);
    std::optional<ir::PointExpr> point = std::move(point_);
    point_.reset();
    return point;
  }
  ir::StmtPtr Stmt(antlr4::ParserRuleContext* ctx) {
    if (ctx == nullptr) return nullptr;
    stmt_.reset();
    Accept(ctx);
    return std::move(stmt_);
  }
  static std::uint32_t StartLine(antlr4::ParserRuleContext* ctx) {
    return static_cast<std::uint32_t>(ctx->getStart()->getLine());
  }
  static std::uint32_t StopLine(antlr4::ParserRuleContext* ctx) {
    const Token* stop = ctx->getStop();
    if (stop == nullptr) return StartLine(ctx);
    return std::max(StartLine(ctx), static_cast<std::uint32_t>(stop->getLine()));
  }
  std::string Name(antlr4::tree::TerminalNode* node) const {
    return node == nullptr ? std::string() : std::string(s_.Text(node->getSymbol()));
  }
  SourceLoc Loc(antlr4::tree::TerminalNode* node) const {
    return node == nullptr ? SourceLoc{} : s_.Loc(node->getSymbol());
  }
  // The text of the comment on `line`, without its ' and without spaces or
  // tabs at its end: they are invisible, and printing them back would end a
  // canonical line in whitespace. Spaces after the ' are kept as written.
  std::string CommentOn(std::size_t line) const {
    const Line* info = s_.LineAt(line);
    if (info == nullptr || info->comment == nullptr) return {};
    std::string_view text = s_.Text(info->comment).substr(1);
    std::size_t end = text.find_last_not_of(" \t");
    return std::string(text.substr(0, end == std::string_view::npos ? 0 : end + 1));
  }
  // A new statement located at ctx's first token.
  ir::StmtPtr NewStmt(antlr4::ParserRuleContext* ctx) {
    auto stmt = std::make_unique<ir::Stmt>();
    stmt->loc = s_.Loc(ctx->getStart());
    stmt->length = s_.Length(ctx->getStart());
    return stmt;
  }
  template <typename Node>
  ir::StmtPtr MakeStmt(antlr4::ParserRuleContext* ctx, Node node) {
    ir::StmtPtr stmt = NewStmt(ctx);
    stmt->node = std::move(node);
    return stmt;
  }
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
  ir::BlockEnd End(antlr4::tree::TerminalNode* closer) const {
    if (closer == nullptr) return {};
    std::size_t line = closer->getSymbol()->getLine();
    return ir::BlockEnd{Loc(closer), CommentOn(line)};
  }
  static std::uint32_t LineOf(antlr4::tree::TerminalNode* node, std::uint32_t fallback) {
    return node == nullptr ? fallback : static_cast<std::uint32_t>(node->getSymbol()->getLine());
  }

  ir::Block Body(P::BlockContext* ctx, std::uint32_t first, std::uint32_t end) {
    if (ctx == nullptr) return {};
    BlockWalker walker(*this, first);
    for (P::BlockLineContext* line : ctx->blockLine()) {
      if (P::StatementContext* statement = line->statement()) walker.Add(statement);
    }
    return walker.Finish(end);
  }

  // A NUMBER token: value and whether it was written as a whole number.
  ir::NumberLit Number(antlr4::tree::TerminalNode* node) {
    ir::NumberLit lit;
    if (node == nullptr) return lit;
    std::string_view text = s_.Text(node->getSymbol());
    lit.is_integer = text.find_first_of(".eE") == std::string_view::npos;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), lit.value);
    (void)end;
    if (ec == std::errc::result_out_of_range) {
      s_.Error(DiagKind::NumberOutOfRange, s_.Range(node->getSymbol()), std::string(text));
      lit.value = 0;
    }
    return lit;
  }
  // A NUMBER that must be a whole number (pallet sizes, output numbers).
  int WholeNumber(antlr4::tree::TerminalNode* node, const char* what) {
    if (node == nullptr) return 0;
    ir::NumberLit lit = Number(node);
    std::string text(s_.Text(node->getSymbol()));
    if (!lit.is_integer) {
      s_.Error(DiagKind::WholeNumberRequired, s_.Range(node->getSymbol()), std::string(what), text);
      return 0;
    }
    if (lit.value > std::numeric_limits<int>::max()) {
      s_.Error(DiagKind::WholeNumberTooLarge, s_.Range(node->getSymbol()), std::string(what),
               std::numeric_limits<int>::max(), text);
      return 0;
    }
    return static_cast<int>(lit.value);
  }
  std::optional<ir::Coords> Coords(P::CoordsContext* ctx) {
    if (ctx == nullptr || ctx->signedNumber().size() != 4) return std::nullopt;
    ir::Coords coords;
    coords.loc = s_.Loc(ctx->getStart());
    for (std::size_t i = 0; i < 4; ++i) {
      P::SignedNumberContext* number = ctx->signedNumber(i);
      double value = Number(number->NUMBER()).value;
      coords.values[i] = number->MINUS() != nullptr ? -value : value;
    }
    return coords;
  }

  // ---- top level
  // programDecl : PROGRAM ID ;
  antlrcpp::Any visitProgramDecl(P::ProgramDeclContext* ctx) override {
    return Yield(MakeStmt(ctx, ir::ProgramDecl{Name(ctx->ID()), Loc(ctx->ID())}));
  }
  // unitsDecl : UNITS ID ;
  antlrcpp::Any visitUnitsDecl(P::UnitsDeclContext* ctx) override {
    return Yield(MakeStmt(ctx, ir::UnitsDecl{Name(ctx->ID()), Loc(ctx->ID())}));
  }
  // fixtureDecl : FIXTURE ID ;
  antlrcpp::Any visitFixtureDecl(P::FixtureDeclContext* ctx) override {
    return Yield(MakeStmt(ctx, ir::FixtureDecl{Name(ctx->ID()), Loc(ctx->ID())}));
  }
  // localDecl : LOCAL ID '=' coords (IN ID)? ;
  antlrcpp::Any visitLocalDecl(P::LocalDeclContext* ctx) override {
    std::optional<ir::Coords> coords = Coords(ctx->coords());
    if (!coords) return Yield(ir::StmtPtr());
    ir::LocalDecl decl;
    decl.name = Name(ctx->ID(0));
    decl.name_loc = Loc(ctx->ID(0));
    decl.origin = *coords;
    decl.frame = Name(ctx->ID(1));
    decl.frame_loc = Loc(ctx->ID(1));
    return Yield(MakeStmt(ctx, std::move(decl)));
  }
  // pointDecl : TAUGHT? POINT ID '=' coords ((IN | ON) ID)? ;
  antlrcpp::Any visitPointDecl(P::PointDeclContext* ctx) override {
    std::optional<ir::Coords> coords = Coords(ctx->coords());
    if (!coords) return Yield(ir::StmtPtr());
    ir::PointDecl decl;
    decl.name = Name(ctx->ID(0));
    decl.name_loc = Loc(ctx->ID(0));
    decl.taught = ctx->TAUGHT() != nullptr;
    decl.coords = *coords;
    decl.frame = Name(ctx->ID(1));
    decl.frame_loc = Loc(ctx->ID(1));
    // The IR keeps one frame for both forms, so the keyword must fit the point.
    if (decl.taught && ctx->IN() != nullptr) {
      s_.Error(DiagKind::TaughtPointIn, s_.Range(ctx->IN()->getSymbol()), decl.frame);
    }
    if (!decl.taught && ctx->ON() != nullptr) {
      s_.Error(DiagKind::ProgrammedPointOn, s_.Range(ctx->ON()->getSymbol()), decl.frame, decl.frame);
    }
    return Yield(MakeStmt(ctx, std::move(decl)));
  }
  // palletDecl : PALLET NUMBER ',' ID ',' ID ',' ID ',' NUMBER ',' NUMBER ;
  antlrcpp::Any visitPalletDecl(P::PalletDeclContext* ctx) override {
    if (ctx->NUMBER().size() != 3 || ctx->ID().size() != 3) return Yield(ir::StmtPtr());
    ir::PalletDecl decl;
    decl.number = WholeNumber(ctx->NUMBER(0), "the pallet number");
    decl.number_loc = Loc(ctx->NUMBER(0));
    for (std::size_t i = 0; i < 3; ++i) {
      decl.corners[i] = Name(ctx->ID(i));
      decl.corner_locs[i] = Loc(ctx->ID(i));
    }
    decl.columns = WholeNumber(ctx->NUMBER(1), "the number of pallet columns");
    decl.columns_loc = Loc(ctx->NUMBER(1));
    decl.rows = WholeNumber(ctx->NUMBER(2), "the number of pallet rows");
    decl.rows_loc = Loc(ctx->NUMBER(2));
    return Yield(MakeStmt(ctx, std::move(decl)));
  }
  // vacuumDecl : VACUUM NUMBER ;
  antlrcpp::Any visitVacuumDecl(P::VacuumDeclContext* ctx) override {
    return Yield(
        MakeStmt(ctx, ir::VacuumDecl{WholeNumber(ctx->NUMBER(), "the vacuum output"), Loc(ctx->NUMBER())}));
  }
  // varDecl : (INTEGER | REAL) ID (',' ID)* ;
  antlrcpp::Any visitVarDecl(P::VarDeclContext* ctx) override {
    ir::VarDecl decl;
    decl.type = ctx->REAL() != nullptr ? ir::VarType::Real : ir::VarType::Integer;
    for (auto* id : ctx->ID()) {
      decl.names.push_back(Name(id));
      decl.name_locs.push_back(Loc(id));
    }
    return Yield(MakeStmt(ctx, std::move(decl)));
  }
  // functionDecl : functionHead block FEND ;
  // functionHead : FUNCTION ID ('(' ')')? NEWLINE ;
  antlrcpp::Any visitFunctionDecl(P::FunctionDeclContext* ctx) override {
    if (ctx->functionHead() == nullptr) return Yield(ir::StmtPtr());
    ir::Function function;
    function.name = Name(ctx->functionHead()->ID());
    function.name_loc = Loc(ctx->functionHead()->ID());
    std::uint32_t head = StartLine(ctx);
    function.body = Body(ctx->block(), head + 1, LineOf(ctx->FEND(), StopLine(ctx) + 1));
    function.end = End(ctx->FEND());
    return Yield(MakeStmt(ctx, std::move(function)));
  }
  // topLevel : programDecl | unitsDecl | ... ;
  antlrcpp::Any visitTopLevel(P::TopLevelContext* ctx) override {
    if (!ctx->children.empty()) ctx->children.front()->accept(this);
    return {};
  }

  // ---- statements
  // statement : varDecl | assignment | motion | ... ;
  antlrcpp::Any visitStatement(P::StatementContext* ctx) override {
    if (!ctx->children.empty()) ctx->children.front()->accept(this);
    return {};
  }
  // assignment : ID '=' expr ;
  antlrcpp::Any visitAssignment(P::AssignmentContext* ctx) override {
    ir::ExprPtr value = Expr(ctx->expr());
    if (!value) return Yield(ir::StmtPtr());
    return Yield(MakeStmt(ctx, ir::Assign{Name(ctx->ID()), std::move(value)}));
  }
  // motion : (JUMP | GO | MOVE) pointExpr (LIMZ expr)? ;
  antlrcpp::Any visitMotion(P::MotionContext* ctx) override {
    std::optional<ir::PointExpr> target = Point(ctx->pointExpr());
    if (!target) return Yield(ir::StmtPtr());
    ir::Motion motion;
    motion.kind = ctx->GO() != nullptr     ? ir::MotionKind::Go
                  : ctx->MOVE() != nullptr ? ir::MotionKind::Move
                                           : ir::MotionKind::Jump;
    motion.target = std::move(*target);
    motion.limz = Expr(ctx->expr());
    motion.limz_loc = Loc(ctx->LIMZ());
    return Yield(MakeStmt(ctx, std::move(motion)));
  }
  // pickPlace : (PICK | PLACE) pointExpr (VACUUM expr)? (LIMZ expr)? ;
  antlrcpp::Any visitPickPlace(P::PickPlaceContext* ctx) override {
    std::optional<ir::PointExpr> target = Point(ctx->pointExpr());
    if (!target) return Yield(ir::StmtPtr());
    ir::PickPlace pick;
    pick.kind = ctx->PLACE() != nullptr ? ir::PickPlaceKind::Place : ir::PickPlaceKind::Pick;
    pick.target = std::move(*target);
    // Which expr is which: the keyword before it says.
    std::size_t keyword = 0;
    for (antlr4::tree::ParseTree* child : ctx->children) {
      if (auto* terminal = dynamic_cast<antlr4::tree::TerminalNode*>(child)) {
        keyword = terminal->getSymbol()->getType();
      } else if (auto* expr = dynamic_cast<P::ExprContext*>(child)) {
        (keyword == P::VACUUM ? pick.vacuum : pick.limz) = Expr(expr);
      }
    }
    return Yield(MakeStmt(ctx, std::move(pick)));
  }
  // onOff : (ON | OFF) expr ;
  antlrcpp::Any visitOnOff(P::OnOffContext* ctx) override {
    ir::ExprPtr bit = Expr(ctx->expr());
    if (!bit) return Yield(ir::StmtPtr());
    return Yield(MakeStmt(ctx, ir::SetOutput{ctx->ON() != nullptr, std::move(bit)}));
  }
  // waitStmt : WAIT expr ;   Sw(n) = On|Off waits for an input, else seconds.
  antlrcpp::Any visitWaitStmt(P::WaitStmtContext* ctx) override {
    ir::ExprPtr expr = Expr(ctx->expr());
    if (!expr) return Yield(ir::StmtPtr());
    if (auto* eq = std::get_if<ir::BinaryExpr>(&expr->node); eq != nullptr && eq->op == ir::BinaryOp::Eq) {
      auto* sw = std::get_if<ir::SwitchRead>(&eq->lhs->node);
      auto* state = std::get_if<ir::OnOffLit>(&eq->rhs->node);
      if (sw != nullptr && state != nullptr) {
        return Yield(MakeStmt(ctx, ir::WaitSwitch{std::move(sw->bit), state->on}));
      }
    }
    return Yield(MakeStmt(ctx, ir::WaitTime{std::move(expr)}));
  }
  // forStmt : forHead block NEXT ID? ;
  // forHead : FOR ID '=' expr TO expr (STEP expr)? NEWLINE ;
  antlrcpp::Any visitForStmt(P::ForStmtContext* ctx) override {
    P::ForHeadContext* head = ctx->forHead();
    if (head == nullptr || head->expr().size() < 2) return Yield(ir::StmtPtr());
    ir::For loop;
    loop.var = Name(head->ID());
    loop.var_loc = Loc(head->ID());
    loop.from = Expr(head->expr(0));
    loop.to = Expr(head->expr(1));
    loop.step = Expr(head->expr(2));
    if (!loop.from || !loop.to) return Yield(ir::StmtPtr());
    loop.body = Body(ctx->block(), StartLine(ctx) + 1, LineOf(ctx->NEXT(), StopLine(ctx) + 1));
    loop.end = End(ctx->NEXT());
    loop.next_var = Name(ctx->ID());
    loop.next_var_loc = Loc(ctx->ID());
    return Yield(MakeStmt(ctx, std::move(loop)));
  }
  // ifStmt     : ifHead block elseIfPart* elsePart? ENDIF ;
  // elseIfPart : elseIfHead block ;       elsePart : elseHead block ;
  antlrcpp::Any visitIfStmt(P::IfStmtContext* ctx) override {
    P::IfHeadContext* head = ctx->ifHead();
    if (head == nullptr) return Yield(ir::StmtPtr());
    // The line where each branch starts, then the EndIf line.
    std::vector<std::uint32_t> starts = {StartLine(ctx)};
    for (auto* part : ctx->elseIfPart()) starts.push_back(StartLine(part));
    if (ctx->elsePart() != nullptr) starts.push_back(StartLine(ctx->elsePart()));
    starts.push_back(LineOf(ctx->ENDIF(), StopLine(ctx) + 1));

    ir::If stmt;
    ir::IfBranch first;
    first.loc = Loc(head->IF());
    first.condition = Expr(head->expr());
    if (!first.condition) return Yield(ir::StmtPtr());
    first.body = Body(ctx->block(), starts[0] + 1, starts[1]);
    stmt.branches.push_back(std::move(first));
    std::size_t k = 1;
    for (auto* part : ctx->elseIfPart()) {
      ir::IfBranch branch;
      P::ElseIfHeadContext* part_head = part->elseIfHead();
      if (part_head == nullptr || s_.LineHasError(starts[k])) return Yield(ir::StmtPtr());
      branch.loc = Loc(part_head->ELSEIF());
      branch.condition = Expr(part_head->expr());
      if (!branch.condition) return Yield(ir::StmtPtr());
      branch.body = Body(part->block(), starts[k] + 1, starts[k + 1]);
      branch.comment = CommentOn(starts[k]);
      stmt.branches.push_back(std::move(branch));
      ++k;
    }
    if (P::ElsePartContext* part = ctx->elsePart()) {
      ir::IfBranch branch;
      if (part->elseHead() == nullptr) return Yield(ir::StmtPtr());
      branch.loc = Loc(part->elseHead()->ELSE());
      branch.body = Body(part->block(), starts[k] + 1, starts[k + 1]);
      branch.comment = CommentOn(starts[k]);
      stmt.branches.push_back(std::move(branch));
    }
    stmt.end = End(ctx->ENDIF());
    return Yield(MakeStmt(ctx, std::move(stmt)));
  }
  // callStmt : CALL ID ('(' ')')? ;
  antlrcpp::Any visitCallStmt(P::CallStmtContext* ctx) override {
    return Yield(MakeStmt(ctx, ir::Call{Name(ctx->ID()), Loc(ctx->ID())}));
  }
  // cycleStmt : cycleHead block ENDCYCLE ;    cycleHead : CYCLE ID NEWLINE ;
  antlrcpp::Any visitCycleStmt(P::CycleStmtContext* ctx) override {
    if (ctx->cycleHead() == nullptr) return Yield(ir::StmtPtr());
    ir::Cycle cycle;
    cycle.fixture = Name(ctx->cycleHead()->ID());
    cycle.fixture_loc = Loc(ctx->cycleHead()->ID());
    cycle.body = Body(ctx->block(), StartLine(ctx) + 1, LineOf(ctx->ENDCYCLE(), StopLine(ctx) + 1));
    cycle.end = End(ctx->ENDCYCLE());
    return Yield(MakeStmt(ctx, std::move(cycle)));
  }
  // scanStmt : SCAN ID ;
  antlrcpp::Any visitScanStmt(P::ScanStmtContext* ctx) override {
    return Yield(MakeStmt(ctx, ir::Scan{Name(ctx->ID()), Loc(ctx->ID())}));
  }
  // exitStmt : EXIT FUNCTION ;
  antlrcpp::Any visitExitStmt(P::ExitStmtContext* ctx) override {
    return Yield(MakeStmt(ctx, ir::ExitFunction{}));
  }

  // ---- points
  // pointExpr : pointAtom (('+' | '-') offset)* ;
  // offset    : ID '(' expr ')' ;
  antlrcpp::Any visitPointExpr(P::PointExprContext* ctx) override {
    std::optional<ir::PointExpr> point;
    if (ctx->pointAtom() == nullptr) return Yield(std::move(point));
    point.emplace();
    point->loc = s_.Loc(ctx->getStart());
    P::PointAtomContext* atom = ctx->pointAtom();
    if (auto* named = dynamic_cast<P::NamedPointContext*>(atom)) {
      point->base = ir::NamedPoint{Name(named->ID()), s_.Length(named->getStart())};
    } else if (auto* literal = dynamic_cast<P::LiteralPointContext*>(atom)) {
      std::optional<ir::Coords> coords = Coords(literal->coords());
      if (!coords) return Yield(std::optional<ir::PointExpr>());
      point->base = *coords;
    } else if (auto* pallet = dynamic_cast<P::PalletPointContext*>(atom)) {
      ir::PalletPoint base;
      base.number = Expr(pallet->expr(0));
      base.i = Expr(pallet->expr(1));
      base.j = Expr(pallet->expr(2));
      if (!base.number || !base.i) return Yield(std::optional<ir::PointExpr>());
      point->base = std::move(base);
    } else {
      return Yield(std::optional<ir::PointExpr>());
    }
    // Each offset follows its sign token.
    bool negative = false;
    const Token* sign = nullptr;
    for (antlr4::tree::ParseTree* child : ctx->children) {
      if (auto* terminal = dynamic_cast<antlr4::tree::TerminalNode*>(child)) {
        sign = terminal->getSymbol();
        negative = sign->getType() == P::MINUS;
      } else if (auto* offset = dynamic_cast<P::OffsetContext*>(child)) {
        if (offset->ID() == nullptr || sign == nullptr) return Yield(std::optional<ir::PointExpr>());
        ir::PointOffset out;
        out.loc = s_.Loc(sign);
        out.negative = negative;
        std::string axis = Name(offset->ID());
        if (axis == "x" || axis == "X") {
          out.axis = ir::Axis::X;
        } else if (axis == "y" || axis == "Y") {
          out.axis = ir::Axis::Y;
        } else if (axis == "z" || axis == "Z") {
          out.axis = ir::Axis::Z;
        } else if (axis == "u" || axis == "U") {
          out.axis = ir::Axis::U;
        } else {
          s_.Error(DiagKind::UnknownOffsetAxis, s_.Range(offset->ID()->getSymbol()), axis);
        }
        out.amount = Expr(offset->expr());
        if (!out.amount) return Yield(std::optional<ir::PointExpr>());
        point->offsets.push_back(std::move(out));
      }
    }
    return Yield(std::move(point));
  }

  // ---- expressions
  // expr : '(' expr ')'
  antlrcpp::Any visitParenExpr(P::ParenExprContext* ctx) override { return Yield(Expr(ctx->expr())); }
  //      | op=('-' | '+' | NOT) expr
  antlrcpp::Any visitUnaryExpr(P::UnaryExprContext* ctx) override {
    ir::ExprPtr operand = Expr(ctx->expr());
    if (!operand || ctx->op == nullptr) return Yield(ir::ExprPtr());
    ir::ExprPtr expr = NewExpr(ctx);
    std::size_t op = ctx->op->getType();
    expr->node = ir::UnaryExpr{op == P::MINUS ? ir::UnaryOp::Negate
                               : op == P::PLUS ? ir::UnaryOp::Plus
                                               : ir::UnaryOp::Not,
                               std::move(operand)};
    return Yield(std::move(expr));
  }
  //      | expr op=(...) expr
  antlrcpp::Any visitBinaryExpr(P::BinaryExprContext* ctx) override {
    if (ctx->expr().size() != 2 || ctx->op == nullptr) return Yield(ir::ExprPtr());
    ir::ExprPtr lhs = Expr(ctx->expr(0));
    ir::ExprPtr rhs = Expr(ctx->expr(1));
    if (!lhs || !rhs) return Yield(ir::ExprPtr());
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
      default: return Yield(ir::ExprPtr());
    }
    ir::ExprPtr expr = NewExpr(ctx);
    expr->node = ir::BinaryExpr{op, std::move(lhs), std::move(rhs)};
    return Yield(std::move(expr));
  }
  //      | SW '(' expr ')'
  antlrcpp::Any visitSwitchExpr(P::SwitchExprContext* ctx) override {
    ir::ExprPtr bit = Expr(ctx->expr());
    if (!bit) return Yield(ir::ExprPtr());
    ir::ExprPtr expr = NewExpr(ctx);
    expr->node = ir::SwitchRead{std::move(bit)};
    return Yield(std::move(expr));
  }
  //      | (ON | OFF)
  antlrcpp::Any visitOnOffExpr(P::OnOffExprContext* ctx) override {
    ir::ExprPtr expr = NewExpr(ctx);
    expr->node = ir::OnOffLit{ctx->ON() != nullptr};
    return Yield(std::move(expr));
  }
  //      | NUMBER
  antlrcpp::Any visitNumberExpr(P::NumberExprContext* ctx) override {
    ir::ExprPtr expr = NewExpr(ctx);
    expr->node = Number(ctx->NUMBER());
    return Yield(std::move(expr));
  }
  //      | ID
  antlrcpp::Any visitVariableExpr(P::VariableExprContext* ctx) override {
    ir::ExprPtr expr = NewExpr(ctx);
    expr->node = ir::VariableRef{Name(ctx->ID())};
    return Yield(std::move(expr));
  }

  Session& s_;
  ir::ExprPtr expr_;
  ir::StmtPtr stmt_;
  std::optional<ir::PointExpr> point_;
};

// ------------------------------------------------------------------ driver

ir::Program Session::Run() {
  ir::Program program;
  program.file = file_;
  try {
    SyntaxErrorListener listener(*this);
    Lex(listener);
    PreScan();
    antlr4::ListTokenSource source(ParserTokens());
    antlr4::CommonTokenStream tokens(&source);
    PlaceParser parser(&tokens);
    parser.removeErrorListeners();
    parser.addErrorListener(&listener);
    parser.setErrorHandler(std::make_shared<LineErrorStrategy>(*this));
    // One top-level line (a declaration, or a whole Function) at a time,
    // freeing its parse tree once it is IR: the tree of a large program
    // would take several times the memory of its IR.
    IrBuilder builder(*this);
    IrBuilder::BlockWalker top(builder, 1);
    while (tokens.LA(1) != Token::EOF) {
      std::size_t before = tokens.index();
      P::ProgramLineContext* line = parser.programLine();
      if (P::TopLevelContext* item = line->topLevel()) top.Add(item);
      parser.getTreeTracker().reset();
      if (tokens.index() == before) parser.consume();  // never loop in place
    }
    program.items = top.Finish(last_line() + 1);
  } catch (const std::bad_alloc&) {
    throw;  // out of memory is no syntax error: the driver reports it (exit 3)
  } catch (const std::exception& e) {
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

ir::Program ParseProgram(std::uint32_t file, Diagnostics& diags) { return Session(file, diags).Run(); }

}  // namespace smtcal
