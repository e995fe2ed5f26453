// The text smtcal takes from the command line and quotes on stderr: any
// bytes through the one check of numbers (base/number_range.h) and the one
// quoting function (base/field_text.h). Properties: a number accepted is
// finite and in its range, and reads back; what Printable and a diagnostic
// give is valid UTF-8 (decoded by the tests' own oracle,
// tests/unit/utf8_oracle.h, not with Utf8Length), the
// source-line form keeps one character per character, and a message is cut
// at its limit.
#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>

#include "base/diagnostics.h"
#include "base/field_text.h"
#include "base/number_range.h"
#include "tests/fuzz/fuzz_target.h"
#include "tests/unit/utf8_oracle.h"

namespace {

bool Utf8Characters(std::string_view text, std::size_t* characters) {
  return smtcal::test::IsWellFormedUtf8(text, characters);
}

// The characters of arbitrary bytes as Printable's kSourceLine walks them:
// a well-formed sequence, or one byte.
std::size_t Characters(std::string_view text) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < text.size(); ++count) i += std::max<std::size_t>(smtcal::Utf8Length(text, i), 1);
  return count;
}

}  // namespace

SMTCAL_FUZZ_TARGET(text) {
  using namespace smtcal;
  const std::string_view text = fuzz::AsText(data, size);

  for (TextQuoting quoting : {TextQuoting::kField, TextQuoting::kMessage, TextQuoting::kSourceLine}) {
    std::size_t shown = 0;
    if (!Utf8Characters(Printable(text, quoting), &shown)) fuzz::Fail("Printable gave text that is not UTF-8");
    if (quoting == TextQuoting::kSourceLine && shown != Characters(text)) {
      fuzz::Fail("the source line's characters no longer match the caret line's");
    }
  }
  const std::string cut = CutForMessage(Printable(text, TextQuoting::kMessage));
  if (cut.size() > kMaxMessageBytes + 3 || !Utf8Characters(cut, nullptr)) fuzz::Fail("a cut message is too long or not UTF-8");

  // A diagnostic quoting the bytes, with the bytes as its source line: both
  // renderings are valid UTF-8 (the JSON one escapes what is not).
  SourceManager sources;
  const std::uint32_t file = sources.Add(std::string(text.substr(0, 16)), std::string(text));
  Diagnostics diags(sources);
  Diagnostic* diag =
      diags.Report(DiagKind::CsvLengthTooLarge, SourceRange(SourceLoc{file, 1, 1}, 3), text, "x_mm", 1e5);
  Diagnostics::AddNote(diag, SourceRange(SourceLoc{file, 1, 2}), text);
  if (!Utf8Characters(diags.RenderText(), nullptr)) fuzz::Fail("a diagnostic's text is not UTF-8");
  if (!Utf8Characters(diags.RenderJson(), nullptr)) fuzz::Fail("a diagnostic's JSON is not UTF-8");

  // Numbers: accepted only finite, in range, and as the same number.
  for (const NumberRange& range :
       {Closed(0, 1, ""), AboveZero(10, "mm"), Closed(-1e5, 1e5, "mm"), Closed(0, 1e6, "µm")}) {
    Result<double> number = ParseNumberIn(text, range);
    if (number.ok() && (!InRange(number.value(), range) || ParseNumber(text) != number.value())) {
      fuzz::Fail("a number was accepted outside its range");
    }
    if (!number.ok() && !Utf8Characters(number.error().message, nullptr)) fuzz::Fail("a refusal is not UTF-8");
  }
  for (const NumberRange& range : {Whole(1, 100000), Whole(0, 18446744073709551615.0), Whole(-10, 10)}) {
    Result<WholeNumber> number = ParseWholeNumberIn(text, range);
    if (!number.ok()) continue;
    const WholeNumber& n = number.value();
    const double value = n.negative ? -static_cast<double>(n.magnitude) : static_cast<double>(n.magnitude);
    if (!InRange(value, range) || (n.negative && n.magnitude == 0)) fuzz::Fail("a whole number outside its range");
  }
  return 0;
}
