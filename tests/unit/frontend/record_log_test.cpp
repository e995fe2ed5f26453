// Reading logs of cycle records (frontend/record_log.h): a record whole or
// left out with a warning; what a power cut or a restart leaves, one warning
// with the records around it read; what no power cut makes, an error at its
// line naming the record; records read twice counted once.
#include <fmt/format.h>
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
  EXPECT_NE(r.Text().find("are not records (the last line, without its end of line (the file was cut while it was "
                          "written); the record of cycle 2 of fixture 'Board' (line 6) it cut short)"),
            std::string::npos)
      << r.Text();
}

// A power cut leaves a line cut short and a tail of NUL bytes; the restart's
// begin line follows: one warning naming the bytes, every record around read.
TEST(RecordLog, APowerCutAndARestartAreOneWarningAndTheRecordsAroundCount) {
  const std::string before = std::string(kBegin) + Record(1) + Record(2) + "cycle 0 3 0 0 - 138 40 3";
  const std::string text = before + std::string(4096, '\0') + kBegin + Record(1) + Record(2);
  Read r(text);
  ASSERT_TRUE(r.ok) << r.Text();
  EXPECT_EQ(r.diags.warning_count(), 1u) << r.Text();
  EXPECT_NE(r.Text().find(fmt::format("a.log:10:1: warning: bytes {}-{} (line 10) are not records (line 10: 'cycle 0 3 0 "
                                      "0 - 138 40 3' cut, then 4096 NUL bytes)",
                                      before.size() - 24, before.size() + 4095)),
            std::string::npos)
      << r.Text();
  ASSERT_EQ(r.log.cycles.size(), 4u);
  ASSERT_EQ(r.log.begins.size(), 2u);
  EXPECT_EQ(r.log.cycles[2].begin, 1u);
  EXPECT_TRUE(r.log.cycles[2].restart) << "the restart's first record: no previous pose";
  EXPECT_FALSE(r.log.cycles[3].restart);
  // The cut glued to the begin line, without NUL bytes.
  Read glued(std::string(kBegin) + Record(1) + "trip 0 2 1 13" + kBegin + Record(1));
  ASSERT_TRUE(glued.ok) << glued.Text();
  EXPECT_EQ(glued.log.cycles.size(), 2u);
  EXPECT_NE(glued.Text().find("'trip 0 2 1 13' cut where a begin line starts"), std::string::npos) << glued.Text();
}

// Bytes that are not records between records: one warning per stretch, the
// record they spoil left out, the others read.
TEST(RecordLog, DamageIsOneWarningPerStretchAndTheOtherRecordsAreRead) {
  struct Case {
    std::string damage;  // between the records of cycles 1 and 3
    std::string want;
  };
  const std::vector<Case> cases = {
      {"frobnicate 1\n", "line 6: 'frobnicate' is not a line of a record"},
      {"cycle 0 2 0 0 - 138 40 328 40 138\n", "line 6: a 'cycle' line with 11 fields (it has 12)"},
      {"cycle 0 2 0 0 - 138 40 328 40 138 x130\nchecks 0 2 0 0.1 0 0 0 0 0.01 0 0 - -\n",
       "line 6: an estimated crossing's coordinate is 'x130', not a number"},
      {"checks 0 2 0 0 0 0 0 0 0 0 0 0 0\n", "a checks line without the cycle line of its record before it"},
      {"cycle 0 2 0 0 - 138 40 328 40 138 130\ntrip 0 2 1 1 2\n", "a trip line before the cycle's checks line"},
      {"cycle 0 2 0 0 - 138 40 328 40 138 130\nchecks 0 2 0 0.1 0 0 0 0 0.01 0 0 - -\ntrip 0 2 2 1 2\n",
       "trip T2 where T1 comes"},
      {"cycle 0 2 0 0 - 138 40 328 40 138 130\nchecks 0 3 0 0.1 0 0 0 0 0.01 0 0 - -\n",
       "a checks line of cycle 3 of fixture 0 where the record of cycle 2 of fixture 0 goes on"},
      {"cycle 1 2 0 0 - 138 40 328 40 138 130\n", "the fixture is '1', not a whole number from 0 to 0"},
      {"cycle 0 1.5 0 0 - 138 40 328 40 138 130\n", "the cycle is '1.5', not a whole number"},
      {"cycle 0 2 0 0 - 138 40 - - 138 130\n", "the crossings S1, S2, S3 are given in part"},
      {std::string("\x01\x02garbage\n"), "line 6: 9 bytes no writer of a record writes"},
  };
  for (const Case& c : cases) {
    Read r(std::string(kBegin) + Record(1) + c.damage + Record(3));
    EXPECT_TRUE(r.ok) << c.damage << r.Text();
    EXPECT_EQ(r.log.cycles.size(), 2u) << c.damage << r.Text();
    EXPECT_NE(r.Text().find(c.want), std::string::npos) << "want: " << c.want << "\ngot:\n" << r.Text();
    EXPECT_NE(r.Text().find("are not records"), std::string::npos) << r.Text();
  }
}

TEST(RecordLog, RecordsThatSayImpossibleThingsAreErrorsNamingTheRecord) {
  struct Case {
    std::string text;
    std::string want;
  };
  const std::vector<Case> cases = {
      {"cycle 0 1 0 0 - 1 2 3 4 5 6\n", "a.log:1:1: error: the first record of 'a.log' comes before any begin line: a "
                                        "log of cycle records starts with its begin line 'smtcal-record 2 cell=NAME "
                                        "fixtures=NAME:TRIPS,... clock=PIN segment=N'"},
      {"smtcal-record 3 cell=a fixtures=F:8 clock=none segment=0\n", "a.log:1:15: error: format version 3"},
      {"smtcal-record 1 cell=a fixtures=F:8 clock=none segment=0\n",
       "format version 1 is not one this smtcal reads (it reads version 2): in format 1 the LinuxCNC runtime wrote "
       "every value below 1e-4 mm or deg as 0"},
      {"smtcal-record 2 cell=a fixtures=F:8 clok=none segment=0\n",
       "'clok=none' is not a key of the begin line (did you mean 'clock='?)"},
      {"smtcal-record 2 cell=a fixtures=F:40 clock=none segment=0\n",
       "a fixture's trip count is '40': not a whole number from 1 to 32"},
      {std::string(kBegin) + Record(1, "0 0 - 138 40 328 40 138 1e300"),
       "an estimated crossing's coordinate of the record of cycle 1 of fixture 'Board' is 1e300: outside "
       "-100000..100000 mm"},
      {std::string(kBegin) + Record(1, "0 0 - 138 40 328 40 138 1e999"), "is 1e999: not a finite number"},
      {std::string(kBegin) + Record(1, "0 0 -5 138 40 328 40 138 130"), "the time of the record of cycle 1"},
      {std::string(kBegin) + Record(1, "0 0 - 138 40 328 40 138 130", "0 0.1 0 0 0 0 1e300 0 0 - -"),
       "the value of check 7 (line_residual) of the record of cycle 1 of fixture 'Board' is 1e300: outside "
       "0..100000 mm"},
      {std::string(kBegin) + Record(1, "0 0 - 138 40 328 40 138 130", "0 0.1 0 0 0 280 0.01 0 0 - -"),
       "the value of check 6 (squareness) of the record of cycle 1 of fixture 'Board' is 280: outside 0..270 deg"},
      {std::string(kBegin) + Record(1, "0 0 - 138 40 328 40 138 130", "0 0.1 0 0 0 0 0.01 0 200 - -"),
       "the value of check 9 (nominal_rotation) of the record of cycle 1 of fixture 'Board' is 200: outside 0..180 "
       "deg"},
      {std::string(kBegin) + Record(1, "0 0 - 138 40 328 40 138 130", "3 0.1 0 0 0 0 0.01 0 0 - -"),
       "the value of check 1 (missing_trip) of the record of cycle 1 of fixture 'Board' is 3: outside 0..2 trips"},
      {std::string(kBegin) + Record(1, "7 0 - 138 40 328 40 138 130", "0 0.1 0 0 0 0 - 0 0 - -"),
       "the scan failed line_residual but that check has no value"},
      {std::string(kBegin) + Record(1, "0 0 - - - - - - -"),
       "the scan gave a pose (check 3 passed) but S1, S2, S3 are not given"},
      {std::string(kBegin) + Record(1, "1 1 - - - - - - -", "1 0 - - - - - - - - -"),
       "check 2 has a value, but no check runs after missing_trip fails"},
      {std::string(kBegin) + Record(3) + Record(2),
       "cycle 2 of fixture 'Board' follows its cycle 3 in the same run: the log goes back"},
      {std::string(kBegin) + Record(1, "0 0 20 138 40 328 40 138 130") + Record(2, "0 0 10 138 40 328 40 138 130"),
       "the time of cycle 2 of fixture 'Board', 10 s, is before its cycle 1's, 20 s, in the same run"},
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
  // A file rotated by copying and truncating: no begin line, the run goes on.
  ASSERT_TRUE(ReadRecordLog(sources.Add("c.log", Record(6)), log, diags)) << diags.RenderText();
  EXPECT_EQ(log.cycles.size(), 4u);
  EXPECT_FALSE(log.cycles[2].restart) << "a new file of the same program run";
  EXPECT_NE(diags.RenderText().find("b.log:2:1: warning: cycle 5 of fixture 'Board' follows cycle 2: the records of 2 "
                                    "cycles are missing here"),
            std::string::npos)
      << diags.RenderText();
  // A file older than the last: refused.
  EXPECT_FALSE(ReadRecordLog(
      sources.Add("d.log", "smtcal-record 2 cell=paper-cell fixtures=Board:2 clock=none segment=0\n"), log,
      diags));
}

// The same log given twice, or rotated copies that overlap: each record once.
TEST(RecordLog, RecordsReadTwiceAreCountedOnce) {
  SourceManager sources;
  Diagnostics diags(sources);
  RecordLog log;
  const std::string first = std::string(kBegin) + Record(1) + Record(2) + Record(3);
  ASSERT_TRUE(ReadRecordLog(sources.Add("a.log", first), log, diags));
  ASSERT_TRUE(ReadRecordLog(sources.Add("a-again.log", first + Record(4)), log, diags)) << diags.RenderText();
  DropRepeatedRecords(log, diags);
  ASSERT_EQ(log.cycles.size(), 4u);
  EXPECT_EQ(log.cycles[3].record.cycle, 4);
  EXPECT_NE(diags.RenderText().find("a-again.log:2:1: warning: 3 records of this file, the first here, repeat records "
                                    "read before (this one is also a.log:2)"),
            std::string::npos)
      << diags.RenderText();
  // Two runs that merely start alike (a restart after one scan) are not one.
  SourceManager sources2;
  Diagnostics diags2(sources2);
  RecordLog log2;
  ASSERT_TRUE(ReadRecordLog(sources2.Add("b.log", std::string(kBegin) + Record(1) + kBegin +
                                                       Record(1, "0 0 - 138.001 40 328 40 138 130")),
                            log2, diags2));
  DropRepeatedRecords(log2, diags2);
  EXPECT_EQ(log2.cycles.size(), 2u);
  EXPECT_EQ(diags2.warning_count(), 0u) << diags2.RenderText();
}

TEST(RecordLog, OtherFilesAreNamed) {
  Read r("[robot]\nx_mm = [0, 1]\n");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.Text().find("looks like a cell file (TOML), not a log of cycle records"), std::string::npos) << r.Text();
}

}  // namespace
}  // namespace smtcal
