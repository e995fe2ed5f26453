// The one check of every number a user gives (base/number_range.h), and the
// one quoting function of text on stderr (base/field_text.h: strict UTF-8).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/field_text.h"
#include "base/number_range.h"

namespace smtcal {
namespace {

constexpr NumberRange kRate = Closed(0, 1, "");
constexpr NumberRange kPositive = AboveZero(10, "mm");
constexpr NumberRange kCount = Whole(1, 100000);
constexpr NumberRange kSeed = Whole(0, 18446744073709551615.0);

TEST(NumberRange, NonFiniteAndOutsideAreNeverInRange) {
  for (double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL, 1.5, -0.5, 1e308}) EXPECT_FALSE(InRange(bad, kRate)) << bad;
  EXPECT_TRUE(InRange(0, kRate));
  EXPECT_TRUE(InRange(1, kRate));
  EXPECT_FALSE(InRange(0, kPositive)) << "greater than 0";
  EXPECT_TRUE(InRange(1e-300, kPositive));
  EXPECT_TRUE(InRange(10, kPositive));
  EXPECT_FALSE(InRange(2.5, kCount)) << "whole";
  EXPECT_TRUE(InRange(100000, kCount));
}

TEST(NumberRange, TheWordingIsTheOneTheDocsUse) {
  EXPECT_EQ(RangeText(Closed(0, 1e6, "µm")), "a number from 0 to 1000000 µm");
  EXPECT_EQ(RangeText(kPositive), "a number greater than 0 and at most 10 mm");
  EXPECT_EQ(RangeText(kRate), "a number from 0 to 1");
  EXPECT_EQ(RangeText(kCount), "a whole number from 1 to 100000");
  EXPECT_EQ(RangeText(kSeed), "a whole number from 0 to 18446744073709551615");
  EXPECT_EQ(RangeText(Closed(-1e5, 1e5, "mm")), "a number from -100000 to 100000 mm");
  EXPECT_EQ(NumberText(-0.0), "0");
  EXPECT_EQ(NumberText(0.1), "0.1");
}

TEST(NumberRange, OnlyOnePlainNumberInRangeIsAccepted) {
  struct Case {
    const char* text;
    const char* says;  // part of the error; nullptr: accepted
  };
  const std::vector<Case> cases = {
      {"0.5", nullptr},       {"1", nullptr},          {"0", nullptr},         {"+0.25", nullptr},
      {"1e-1", nullptr},      {"nan", "not a finite"}, {"NaN", "not a finite"}, {"inf", "not a finite"},
      {"-inf", "not a finite"}, {"infinity", "not a finite"}, {"1e308", "out of range"}, {"-1e308", "out of range"},
      {"1e400", "not a finite"}, {"-0", "negative zero"}, {"-0.0", "negative zero"}, {"", "no value"},
      {" 1", "not a number"}, {"1 ", "not a number"}, {"0x1p-1", "not a number"}, {"0,5", "not a number"},
      {"1.5", "out of range"}, {"--1", "not a number"}, {"+-1", "not a number"}, {"\xff", "not a number"},
  };
  for (const Case& c : cases) {
    Result<double> value = ParseNumberIn(c.text, kRate);
    if (c.says == nullptr) {
      EXPECT_TRUE(value.ok()) << c.text;
      continue;
    }
    ASSERT_FALSE(value.ok()) << c.text;
    EXPECT_NE(value.error().message.find(c.says), std::string::npos) << c.text << ": " << value.error().message;
    EXPECT_NE(value.error().message.find("a number from 0 to 1"), std::string::npos) << value.error().message;
  }
  // The refused text is quoted with the rule of every message: valid UTF-8.
  EXPECT_EQ(ParseNumberIn("\xff", kRate).error().message.find('\xff'), std::string::npos);
}

TEST(NumberRange, WholeNumbersAreDigitsOnlyAndSeedsTakeAllSixtyFourBits) {
  Result<WholeNumber> max = ParseWholeNumberIn("18446744073709551615", kSeed);
  ASSERT_TRUE(max.ok());
  EXPECT_EQ(max.value().magnitude, std::numeric_limits<std::uint64_t>::max());
  for (const char* bad : {"-1", "18446744073709551616", "1e3", "1.0", "", "-0", "nan", " 1", "0x10"}) {
    EXPECT_FALSE(ParseWholeNumberIn(bad, kSeed).ok()) << bad;
  }
  EXPECT_TRUE(ParseWholeNumberIn("100000", kCount).ok());
  EXPECT_FALSE(ParseWholeNumberIn("100001", kCount).ok());
  EXPECT_FALSE(ParseWholeNumberIn("0", kCount).ok());
  Result<WholeNumber> minus = ParseWholeNumberIn("-5", Whole(-10, 10));
  ASSERT_TRUE(minus.ok());
  EXPECT_TRUE(minus.value().negative);
  EXPECT_EQ(minus.value().magnitude, 5u);
}

// Well-formed UTF-8 only (Unicode's table 3-7): what Printable passes through
// is valid for a terminal and a JSON reader.
TEST(Utf8, OverlongFormsSurrogatesAndCodePointsBeyondTheLastAreNotUtf8) {
  EXPECT_EQ(Utf8Length("a", 0), 1u);
  EXPECT_EQ(Utf8Length("\xc3\xa9", 0), 2u);          // é
  EXPECT_EQ(Utf8Length("\xe2\x82\xac", 0), 3u);      // €
  EXPECT_EQ(Utf8Length("\xf0\x9f\x98\x80", 0), 4u);  // U+1F600
  EXPECT_EQ(Utf8Length("\xf4\x8f\xbf\xbf", 0), 4u);  // U+10FFFF, the last
  EXPECT_EQ(Utf8Length("\xed\x9f\xbf", 0), 3u);      // U+D7FF, before the surrogates
  for (const char* bad : {"\xc0\xaf", "\xc1\xbf", "\xe0\x80\xaf", "\xe0\x9f\xbf", "\xf0\x80\x80\xaf", "\xf0\x8f\xbf\xbf",
                          "\xed\xa0\x80", "\xed\xbf\xbf", "\xf4\x90\x80\x80", "\xf5\x80\x80\x80", "\xff", "\x80",
                          "\xc3", "\xe2\x82", "\xf0\x9f\x98"}) {
    EXPECT_EQ(Utf8Length(bad, 0), 0u) << Printable(bad);
  }
}

TEST(Utf8, PrintableQuotesWhatIsNotUtf8ByTheDocsRule) {
  EXPECT_EQ(Printable("a\xc0\xafz"), "a\\xc0\\xafz");
  EXPECT_EQ(Printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");
  EXPECT_EQ(Printable("x\ty\n"), "x\\x09y\\x0a");
  EXPECT_EQ(Printable("x\ty\n", TextQuoting::kMessage), "x\ty\n");
  EXPECT_EQ(Printable("x\ty\xf4\x90\x80\x80", TextQuoting::kSourceLine), "x\ty????");
  EXPECT_EQ(Printable("caf\xc3\xa9"), "caf\xc3\xa9");
}

TEST(Utf8, MessagesAreCutAtACharacterBoundary) {
  std::string long_text(999, 'a');
  long_text += "\xe2\x82\xac and more";
  const std::string cut = CutForMessage(long_text);
  EXPECT_EQ(cut, std::string(999, 'a') + "...");
  EXPECT_EQ(CutForMessage("short"), "short");
}

}  // namespace
}  // namespace smtcal
