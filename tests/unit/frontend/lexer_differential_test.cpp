// The hand-written lexer (frontend/place_lexer.h) against its reference, the
// lexer ANTLR generates from grammar/Place.g4: on every .place file of the
// golden suites and the examples, and on random programs (seeded; the seed is
// printed, SMTCAL_TEST_SEED varies it), both give the same tokens (type,
// offset, length, line, column) and lines, and parsing either gives the
// same diagnostics and the same IR.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "frontend/parse.h"
#include "frontend/place_lexer.h"
#include "ir/ir_dump.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

std::uint64_t Seed() {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 19940516;
}

std::string Describe(const LexedPlace& lexed, std::size_t i) {
  const PlaceToken& token = lexed.tokens[i];
  return fmt::format("{} at {}+{} (line {}, column {})", PlaceTokenName(token.type), token.start, token.length,
                     token.line, lexed.Column(token));
}

// The first token where the two lexers differ (column included), described;
// "" when they agree.
std::string FirstDifference(const LexedPlace& ours, const LexedPlace& reference) {
  std::size_t n = std::min(ours.tokens.size(), reference.tokens.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (!(ours.tokens[i] == reference.tokens[i]) || ours.Column(ours.tokens[i]) != reference.Column(reference.tokens[i])) {
      return fmt::format("token {}: ours {}, ANTLR's {}", i, Describe(ours, i), Describe(reference, i));
    }
  }
  if (ours.tokens.size() != reference.tokens.size()) {
    return fmt::format("ours has {} tokens, ANTLR's {}", ours.tokens.size(), reference.tokens.size());
  }
  if (ours.line_starts != reference.line_starts) return "the lines start at other offsets";
  return "";
}

struct ParseResult {
  std::string diagnostics;
  std::string ir;
};

ParseResult Parse(const std::string& text, LexedPlace lexed) {
  SourceManager sources;
  std::uint32_t file = sources.Add("t.place", text);
  Diagnostics diags(sources);
  ir::Program program = ParseTokens(file, std::move(lexed), diags);
  return {diags.RenderText(), DumpIr(program, true)};
}

// Both lexers, and the parser on both token lists.
void ExpectSameAsReference(const std::string& text) {
  LexedPlace ours = LexPlace(text);
  LexedPlace reference = LexPlaceWithAntlr(text);
  ASSERT_EQ(FirstDifference(ours, reference), "");
  ParseResult with_ours = Parse(text, std::move(ours));
  ParseResult with_reference = Parse(text, std::move(reference));
  EXPECT_EQ(with_ours.diagnostics, with_reference.diagnostics);
  EXPECT_EQ(with_ours.ir, with_reference.ir);
}

TEST(LexerDifferential, GoldenProgramsAndExamples) {
  std::vector<fs::path> files;
  for (const char* root : {"tests/golden", "examples"}) {
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(SMTCAL_SOURCE_DIR) / root)) {
      if (entry.is_regular_file() && entry.path().extension() == ".place") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  ASSERT_GT(files.size(), 50u);
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.string());
    ExpectSameAsReference(test::ReadFileText(path));
  }
}

// Every way a token can start, end, or fail to: keywords in any case and as
// prefixes of names, numbers with and without fraction and exponent (also
// the unfinished "1e+" and "1." forms), operators of one and two characters,
// comments, CR, LF and CRLF, tabs, bytes of UTF-8 and of nothing, NUL, and a
// byte order mark. Pieces are glued with and without spaces.
std::string RandomProgram(std::mt19937_64& rng) {
  static const std::string_view kPieces[] = {
      "Program", "PROGRAM", "program", "Units", "mm", "Fixture", "Local", "Point", "Points", "Taught", "In", "On",
      "Off", "XY", "xy(", "Pallet", "Vacuum", "Integer", "Real", "Function", "Fend", "Jump", "Go", "Goto", "Move",
      "LimZ", "Pick", "Place", "Placed", "Wait", "Sw", "For", "To", "Step", "Next", "If", "Then", "ElseIf", "Else",
      "EndIf", "EndIfs", "Call", "Cycle", "EndCycle", "Scan", "Exit", "And", "Or", "Xor", "Not", "Mod", "_", "_a1",
      "P12", "x", "e", "E5", "0", "7", "12.5", "12.", ".5", ".", "..", "1e5", "1E+5", "1e-", "1e+", "1.e3", "3.5e",
      "1.2.3", "00012", "=", "<>", "<", ">", "<=", ">=", "=<", "><", ",", "(", ")", "+", "-", "*", "/", "'", "' note",
      "'c\r", "\"", ":", "$", "#", "\\", "\t", " ", "  ", "\n", "\r\n", "\r", "\r\r\n", "\xC3\xA9", "\xE2\x82\xAC",
      "\xFF", "\x80", std::string_view("\0", 1), "\x7F", "\x01"};
  std::uniform_int_distribution<std::size_t> pick(0, std::size(kPieces) - 1);
  std::uniform_int_distribution<int> coin(0, 3);
  std::string text = coin(rng) == 0 ? "\xEF\xBB\xBF" : "";
  std::size_t count = std::uniform_int_distribution<std::size_t>(0, 120)(rng);
  for (std::size_t i = 0; i < count; ++i) {
    text += kPieces[pick(rng)];
    if (coin(rng) != 0) text += ' ';
  }
  return text;
}

TEST(LexerDifferential, RandomPrograms) {
  const std::uint64_t seed = Seed();
  SCOPED_TRACE(fmt::format("seed {} (set SMTCAL_TEST_SEED to vary)", seed));
  std::mt19937_64 rng(seed);
  for (int round = 0; round < 3000; ++round) {
    std::string text = RandomProgram(rng);
    SCOPED_TRACE(fmt::format("round {}: {:?}", round, text));
    ExpectSameAsReference(text);
    if (HasFatalFailure()) return;
  }
}

TEST(LexerDifferential, RandomBytes) {
  const std::uint64_t seed = Seed() + 1;
  SCOPED_TRACE(fmt::format("seed {} (set SMTCAL_TEST_SEED to vary)", seed));
  std::mt19937_64 rng(seed);
  for (int round = 0; round < 300; ++round) {
    std::string text(std::uniform_int_distribution<std::size_t>(0, 400)(rng), '\0');
    for (char& c : text) c = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    SCOPED_TRACE(fmt::format("round {}", round));
    ExpectSameAsReference(text);
    if (HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace smtcal
