// `smtcal table ...` as a user runs it: help on every subcommand, points from
// stdin, exit codes, and files written whole. (The outputs themselves are in
// the golden suites tests/golden/tables-*.)
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/unit/test_support.h"

namespace fs = std::filesystem;

namespace {

const std::string kTable = std::string(SMTCAL_SOURCE_DIR) + "/examples/paper-cell/placing-table.csv";

using CliRun = smtcal::test::SmtcalRun;
using smtcal::test::ReadFileText;

fs::path TempDir() {
  fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_table_cli_{}", ::getpid());
  fs::create_directories(dir);
  return dir;
}

// Runs `smtcal args` with `input` on stdin.
CliRun Smtcal(const std::string& args, const std::string& input = "") {
  return smtcal::test::RunSmtcal(args, fs::temp_directory_path(), input);
}

class TableCli : public testing::Test {
 protected:
  void TearDown() override { fs::remove_all(TempDir()); }
};

TEST_F(TableCli, EverySubcommandHasHelp) {
  for (const char* sub : {"build", "check", "stats", "forward", "inverse", "plot", "diff"}) {
    CliRun help = Smtcal(fmt::format("table {} --help", sub));
    EXPECT_EQ(help.exit_code, 0) << sub;
    EXPECT_NE(help.out.find("Usage"), std::string::npos) << sub;
  }
  CliRun table = Smtcal("table --help");
  for (const char* sub : {"build", "check", "stats", "forward", "inverse", "plot", "diff"}) {
    EXPECT_NE(table.out.find(sub), std::string::npos) << sub;
  }
}

TEST_F(TableCli, InverseReadsPointsFromStdin) {
  CliRun run = Smtcal("table inverse " + kTable, "172.5,81.25\n175,85\n");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  std::istringstream lines(run.out);
  std::string header, first;
  std::getline(lines, header);
  std::getline(lines, first);
  EXPECT_EQ(header, "x_mm,y_mm,residual_mm,iterations");
  EXPECT_EQ(first.substr(0, 21), "172.585852,81.235263,");
  // The same through the paper's solver, and back through forward.
  CliRun paper = Smtcal("table inverse --solver paper " + kTable + " -", "172.5,81.25\n");
  ASSERT_EQ(paper.exit_code, 0) << paper.err;
  CliRun forward = Smtcal("table forward " + kTable, "172.585852,81.235263\n");
  ASSERT_EQ(forward.exit_code, 0) << forward.err;
  EXPECT_EQ(forward.out, "x_mm,y_mm,residual_mm,iterations\n172.500000,81.250000,0.000e+00,0\n");
}

TEST_F(TableCli, ExitCodes) {
  EXPECT_EQ(Smtcal("table").exit_code, 2);
  EXPECT_EQ(Smtcal("table inverse " + kTable + " --solver fastest", "1,2\n").exit_code, 2);
  EXPECT_EQ(Smtcal("table inverse " + kTable + " --outside maybe", "1,2\n").exit_code, 2);
  EXPECT_EQ(Smtcal("table plot " + kTable).exit_code, 2) << "plot needs -o";
  CliRun missing = Smtcal("table check /nonexistent/table.csv");
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("cannot open '/nonexistent/table.csv'"), std::string::npos) << missing.err;
  EXPECT_EQ(Smtcal("table plot " + kTable + " -o /nonexistent/dir/plot.svg").exit_code, 3);
  CliRun outside = Smtcal("table inverse " + kTable, "100,100\n");
  EXPECT_EQ(outside.exit_code, 1);
  EXPECT_EQ(outside.out, "") << "no partial output when a point is refused";
  EXPECT_EQ(Smtcal("table inverse --outside none " + kTable, "100,100\n").exit_code, 0);
}

TEST_F(TableCli, StatsJsonIsJson) {
  CliRun run = Smtcal("table stats --json " + kTable);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["file"], "placing-table.csv");
  EXPECT_DOUBLE_EQ(j["axes"]["x"]["min_mm"].get<double>(), -0.153);
  EXPECT_DOUBLE_EQ(j["axes"]["y"]["mean_mm"].get<double>(), 0.007);
  EXPECT_EQ(j["inverse"]["iteration_bound"], 4);
}

TEST_F(TableCli, BuildAndPlotWriteTheirFiles) {
  fs::path dir = TempDir();
  fs::path table = dir / "table.csv", plot = dir / "plot.svg";
  CliRun build = Smtcal(fmt::format("table build {}/examples/paper-cell/placing-raw.csv -o {}", SMTCAL_SOURCE_DIR,
                                 table.string()));
  ASSERT_EQ(build.exit_code, 0) << build.err;
  EXPECT_EQ(ReadFileText(table), ReadFileText(kTable));
  CliRun draw = Smtcal(fmt::format("table plot {} -o {}", table.string(), plot.string()));
  ASSERT_EQ(draw.exit_code, 0) << draw.err;
  std::string svg = ReadFileText(plot);
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_NE(svg.find("</svg>\n"), std::string::npos);
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos) << "leftover " << entry.path();
  }
}

TEST_F(TableCli, DiffDrawsTheChangeAndGatesOnTheThreshold) {
  fs::path dir = TempDir();
  fs::path shifted = dir / "shifted.csv", picture = dir / "change.svg";
  // Every y error 20 µm larger.
  std::istringstream in(ReadFileText(kTable));
  std::ofstream out(shifted);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("y,", 0) == 0) {
      std::size_t c3 = line.find(',', line.find(',', 2) + 1), c4 = line.find(',', c3 + 1);
      line = line.substr(0, c3 + 1) + fmt::format("{:.6f}", std::stod(line.substr(c3 + 1, c4 - c3 - 1)) + 0.020) +
             line.substr(c4);
    }
    out << line << "\n";
  }
  out.close();
  CliRun gate = Smtcal(fmt::format("table diff {} {} --svg {}", kTable, shifted.string(), picture.string()));
  EXPECT_EQ(gate.exit_code, 1) << gate.err;
  EXPECT_NE(gate.out.find("Δy: 121 nodes of the same grid"), std::string::npos) << gate.out;
  // Every node moved alike: a uniform change, no node listed as changed "most".
  EXPECT_NE(gate.out.find("a uniform change: every node +20.0 µm, more than 10.0 µm"), std::string::npos)
      << gate.out;
  EXPECT_EQ(gate.out.find("the nodes that changed most"), std::string::npos) << gate.out;
  const std::string svg = ReadFileText(picture);
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_NE(svg.find("change of Δy, 11 x 11 nodes"), std::string::npos);
  EXPECT_NE(svg.find("the panel's own component of the change"), std::string::npos);
  EXPECT_NE(svg.find("µm"), std::string::npos);
  EXPECT_EQ(Smtcal(fmt::format("table diff {} {} --threshold 20.5", kTable, shifted.string())).exit_code, 0);
  EXPECT_EQ(Smtcal(fmt::format("table diff {} {} --exit-zero", kTable, shifted.string())).exit_code, 0);
  EXPECT_EQ(Smtcal(fmt::format("table diff {} {}", kTable, kTable)).exit_code, 0);
  EXPECT_EQ(Smtcal(fmt::format("table diff - - ")).exit_code, 2);
}

}  // namespace
