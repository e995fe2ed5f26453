// Reading logs of cycle records (frontend/record_log.h): a record whole or
// left out with a warning, every mistake at its line and field.
#include <gtest/gtest.h>

#include "frontend/record_log.h"

namespace smtcal {
namespace {

constexpr const char* kBegin = "smtcal-record 2 cell=paper-cell fixtures=Board:2 clock=none segment=0\n";

std::string Record(long cycle, const char* status_line = "0 0 - 138 40 328 40 138 130",
                   const char* checks = "0 0.1 0 0 0 0 0.01 0 0 - -") {
  return fmt::format("cycle 0 {} {}\nchecks 0 {} {}\ntrip 0 {} 1 138.0 43.0\ntrip 0 {} 2 141 40\n", cycle,
                     status_line, cycle, checks, cycle, cycle);
}

struct Read {
  SourceManager sources;
  Diagnostics diags{sources};
  RecordLog log;
  bool ok = false;
  explicit Read(const std::string& text) { ok = ReadRecordLog(sources.Add("a.log", text), log, diags); }
  std::string Text() const { return diags.RenderText(); }
};

TEST(RecordLog, ReadsRecordsAfterTheirBeginLine) {
  Read r(std::string(kBegin) + Record(1) + Record(2) + "# a comment\n\n" + Record(3));
  ASSERT_TRUE(r.ok) << r.Text();
  EXPECT_EQ(r.diags.warning_count(), 0u) << r.Text();
  ASSERT_EQ(r.log.cycles.size(), 3u);
  EXPECT_EQ(r.log.cycles[2].record.cycle, 3);
  EXPECT_EQ(r.log.cycles[0].record.trips[1], Eigen::Vector2d(141, 40));
  EXPECT_EQ(r.log.begins[0].begin.fixtures[0].trips, 2u);
  EXPECT_FALSE(r.log.cycles[0].record.checks[9].has_value());
  EXPECT_EQ(r.log.cycles[0].record.checks[1], 0.1);
}

TEST(RecordLog, AnIncompleteRecordIsLeftOutWithAWarning) {
  std::string text = std::string(kBegin) + Record(1) + "cycle 0 2 0 0 - 138 40 328 40 138 130\nchecks 0 2 0 0 0 0 0 0 0 0 0 - -\n" +
                     kBegin + Record(1);
  Read r(text);
  ASSERT_TRUE(r.ok) << r.Text();
  EXPECT_EQ(r.log.cycles.size(), 2u);
  EXPECT_NE(r.Text().find("a.log:6:1: warning: the record of cycle 2 of fixture 'Board' stops here (trip T1 and after "
                          "are missing)"),
            std::string::npos)
      << r.Text();
}

TEST(RecordLog, ACutOffLastLineIsLeftOut) {
  std::string text = std::string(kBegin) + Record(1) + Record(2);
  text.pop_back();  // no end of line: the last trip line was cut
  Read r(text);
  ASSERT_TRUE(r.ok) << r.Text();
  EXPECT_EQ(r.log.cycles.size(), 1u);
  EXPECT_NE(r.Text().find("warning: the last line has no end of line"), std::string::npos) << r.Text();
}

TEST(RecordLog, MistakesAreReportedAtTheirField) {
  struct Case {
    std::string text;
    std::string want;
  };
  const std::vector<Case> cases = {
      {"cycle 0 1 0 0 - 1 2 3 4 5 6\n", "a.log:1:1: error: the first line of 'a.log' is 'cycle 0 1 0 0 - 1 2 3 4 5 6'"},
      {"smtcal-record 3 cell=a fixtures=F:8 clock=none segment=0\n", "a.log:1:15: error: format version 3"},
      {"smtcal-record 1 cell=a fixtures=F:8 clock=none segment=0\n",
       "format version 1 is not one this smtcal reads (it reads version 2): in format 1 the LinuxCNC runtime wrote "
       "every value below 1e-4 mm or deg as 0"},
      {"smtcal-record 2 cell=a fixtures=F:8 clok=none segment=0\n",
       "'clok=none' is not a key of the begin line (did you mean 'clock='?)"},
      {"smtcal-record 2 cell=a fixtures=F:40 clock=none segment=0\n", "a fixture's trip count is '40': outside 1..32"},
      {std::string(kBegin) + "cycle 0 1 0 0 - 138 40 328 40 138\n", "a 'cycle' line has 11 fields here: it needs 12 fields"},
      {std::string(kBegin) + "cycle 1 1 0 0 - 138 40 328 40 138 130\n", "the fixture is '1': outside 0..0"},
      {std::string(kBegin) + "cycle 0 1 0 0 - 138 40 328 40 138 1e999\n", "is '1e999': not a finite number"},
      {std::string(kBegin) + "cycle 0 1.5 0 0 - 138 40 328 40 138 130\n", "the cycle is '1.5': not a whole number"},
      {std::string(kBegin) + "cycle 0 1 0 0 - 138 40 - - 138 130\n", "the crossings S1, S2, S3 are given in part"},
      {std::string(kBegin) + "checks 0 1 0 0 0 0 0 0 0 0 0 0 0\n", "a checks line without the cycle line before it"},
      {std::string(kBegin) + "cycle 0 1 0 0 - 138 40 328 40 138 130\ntrip 0 1 1 1 2\n",
       "a trip line before the cycle's checks line"},
      {std::string(kBegin) + "cycle 0 1 0 0 - 138 40 328 40 138 130\nchecks 0 1 0 0 0 0 0 0 0 0 0 - -\ntrip 0 1 2 1 2\n",
       "trip T2 where T1 comes"},
      {std::string(kBegin) + "cycle 0 1 0 0 - 138 40 328 40 138 130\nchecks 0 2 0 0 0 0 0 0 0 0 0 - -\n",
       "this checks line is of cycle 2 of fixture 0, but the record being read is of cycle 1"},
      {std::string(kBegin) + "frobnicate 1\n", "'frobnicate' is not a line of a cycle record"},
      {std::string(kBegin) + Record(1, "7 0 - 138 40 328 40 138 130", "0 0.1 0 0 0 0 - 0 0 - -"),
       "the scan failed line_residual but that check has no value"},
      {std::string(kBegin) + Record(1, "0 0 - - - - - - -"),
       "the scan gave a pose (check 3 passed) but S1, S2, S3 are not given"},
      {std::string(kBegin) + Record(1, "1 1 - - - - - - -", "1 0 - - - - - - - - -"),
       "check 2 has a value, but no check runs after missing_trip fails"},
      {std::string(kBegin) + Record(3) + Record(2), "cycle 2 of fixture 'Board' follows its cycle 3: the log goes back"},
      {std::string(kBegin) + "smtcal-record 2 cell=a fixtures=Board:2 clock=none segment=0\n" +
           "smtcal-record 2 cell=a fixtures=Board:2 clock=none segment=-1\n",
       "the segment is '-1'"},
  };
  for (const Case& c : cases) {
    Read r(c.text);
    EXPECT_FALSE(r.ok) << c.text;
    EXPECT_NE(r.Text().find(c.want), std::string::npos) << "want: " << c.want << "\ngot:\n" << r.Text();
  }
}

TEST(RecordLog, MissingCyclesAreAWarningAndLogsContinueAcrossFiles) {
  SourceManager sources;
  Diagnostics diags(sources);
  RecordLog log;
  ASSERT_TRUE(ReadRecordLog(sources.Add("a.log", std::string(kBegin) + Record(1) + Record(2)), log, diags));
  ASSERT_TRUE(ReadRecordLog(
      sources.Add("b.log", "smtcal-record 2 cell=paper-cell fixtures=Board:2 clock=none segment=1\n" +
                               Record(5)),
      log, diags));
  EXPECT_EQ(log.cycles.size(), 3u);
  EXPECT_NE(diags.RenderText().find("b.log:2:1: warning: cycle 5 of fixture 'Board' follows cycle 2: the records of 2 "
                                    "cycles are missing here"),
            std::string::npos)
      << diags.RenderText();
  // A third file older than the second: refused.
  EXPECT_FALSE(ReadRecordLog(
      sources.Add("c.log", "smtcal-record 2 cell=paper-cell fixtures=Board:2 clock=none segment=0\n"), log,
      diags));
}

TEST(RecordLog, OtherFilesAreNamed) {
  Read r("[robot]\nx_mm = [0, 1]\n");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.Text().find("looks like a cell file (TOML), not a log of cycle records"), std::string::npos) << r.Text();
}

}  // namespace
}  // namespace smtcal
