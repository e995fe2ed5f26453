#include "base/diagnostics.h"

#include <gtest/gtest.h>

namespace smtcal {
namespace {

TEST(Diagnostics, RendersLocationLineAndCaret) {
  SourceManager sources;
  std::uint32_t file = sources.Add("a.place", "Program A\n  Jump Nowhere\n");
  Diagnostics diags(sources);
  diags.Report(DiagKind::SyntaxError, SourceRange({file, 2, 8}, 7), "no such point");
  EXPECT_EQ(diags.RenderText(),
            "a.place:2:8: error: no such point\n"
            "    Jump Nowhere\n"
            "         ^~~~~~~\n");
  EXPECT_EQ(diags.error_count(), 1u);
}

TEST(Diagnostics, StopsAtTheErrorLimit) {
  SourceManager sources;
  std::uint32_t file = sources.Add("a.place", "x\n");
  Diagnostics diags(sources, 3);
  for (int i = 0; i < 10; ++i) diags.Report(DiagKind::SyntaxError, SourceLoc{file, 1, 1}, "bad");
  EXPECT_EQ(diags.all().size(), 4u);
  EXPECT_EQ(diags.all().back().kind, DiagKind::TooManyErrors);
}

TEST(Diagnostics, SuggestsTheClosestName) {
  EXPECT_EQ(ClosestName("Feed805", {"Feed0805", "C1", "U3"}), "Feed0805");
  EXPECT_EQ(ClosestName("board", {"Board"}), "Board");
  EXPECT_EQ(ClosestName("Zzz", {"Feed0805", "C1"}), "");
}

}  // namespace
}  // namespace smtcal
