// Reading a LinuxCNC machine configuration (frontend/linuxcnc_config.h): the
// INI as LinuxCNC reads it (sections, the first value of a key, #INCLUDE
// expanded), the HAL files' nets with [SECTION]KEY substituted and motmod's
// num_dio; the example's configuration reads as it is written.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "frontend/linuxcnc_config.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

class LinuxCncConfig : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("smtcal_lcnc_config_{}", ::getpid());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Write(const std::string& name, const std::string& text) { std::ofstream(dir_ / name, std::ios::binary) << text; }

  fs::path dir_;
  SourceManager sources_;
  Diagnostics diags_{sources_};
};

TEST_F(LinuxCncConfig, IniAsLinuxCncReadsIt) {
  Write("base.ini", "[EMCMOT]\nSERVO_PERIOD = 1000000\n[HAL]\nHALFILE = a.hal\nHALFILE = b.hal\n");
  Write("machine.ini",
        "# a comment\n; another\n[DISPLAY]\nDISPLAY = linuxcncrsh\n  [TASK]  \nCYCLE_TIME =   0.001  \n"
        "CYCLE_TIME = 0.010\n#INCLUDE base.ini\nnot a key\n");
  Result<IniFile> ini = ReadLinuxCncIni((dir_ / "machine.ini").string(), sources_, diags_);
  ASSERT_TRUE(ini) << ini.error().message;
  EXPECT_EQ(ini.value().directory, dir_);
  ASSERT_NE(ini.value().Find("TASK", "CYCLE_TIME"), nullptr);
  EXPECT_EQ(ini.value().Find("TASK", "CYCLE_TIME")->value, "0.001");  // the first value
  EXPECT_EQ(ini.value().Find("EMCMOT", "SERVO_PERIOD")->value, "1000000");  // from the include
  EXPECT_EQ(ini.value().FindAll("HAL", "HALFILE").size(), 2u);
  EXPECT_EQ(ini.value().Find("TASK", "MISSING"), nullptr);
  // The value's place: line 6, column 16.
  const SourceRange range = ini.value().Find("TASK", "CYCLE_TIME")->range;
  EXPECT_EQ(range.begin.line, 6u);
  EXPECT_EQ(range.begin.column, 16u);
  EXPECT_EQ(range.length, 5u);
  // The line that is no KEY = VALUE is a warning; nothing else.
  EXPECT_EQ(diags_.warning_count(), 1u);
  EXPECT_EQ(diags_.error_count(), 0u);
}

TEST_F(LinuxCncConfig, MissingIncludeIsAnError) {
  Write("machine.ini", "[EMC]\n#INCLUDE nowhere.ini\n");
  Result<IniFile> ini = ReadLinuxCncIni((dir_ / "machine.ini").string(), sources_, diags_);
  ASSERT_TRUE(ini);
  EXPECT_EQ(diags_.error_count(), 1u);
  EXPECT_FALSE(ReadLinuxCncIni((dir_ / "absent.ini").string(), sources_, diags_));
}

TEST_F(LinuxCncConfig, HalNetsWithIniSubstitutions) {
  Write("machine.ini", "[EMCMOT]\nEMCMOT = motmod\n[PINS]\nPROBE = motion.probe-input\n"
                       "[HAL]\nHALFILE = a.hal\nPOSTGUI_HALFILE = b.hal\nHALFILE = lib.tcl\n");
  Write("a.hal", "loadrt [EMCMOT]EMCMOT servo_period_nsec=1000000 num_joints=4 num_dio=16\n"
                 "net sensor => [PINS]PROBE  # the marker sensor\n"
                 "net valve motion.digital-out-08 => motion.digital-in-11 other.pin\n"
                 "# net ghost => motion.digital-in-12\n");
  Write("b.hal", "linkps motion.digital-in-13 lane\nlinksp transport motion.digital-in-12\n");
  Result<IniFile> ini = ReadLinuxCncIni((dir_ / "machine.ini").string(), sources_, diags_);
  ASSERT_TRUE(ini);
  const HalConfig hal = ReadLinuxCncHal(ini.value(), sources_, diags_);
  EXPECT_TRUE(hal.motmod_found);
  EXPECT_EQ(hal.num_dio, 16);
  for (const char* pin : {"motion.probe-input", "motion.digital-out-08", "motion.digital-in-11", "other.pin",
                          "motion.digital-in-13", "motion.digital-in-12"}) {
    EXPECT_TRUE(hal.connected.contains(pin)) << pin;
  }
  EXPECT_EQ(hal.connected.at("motion.digital-in-11").signal, "valve");
  EXPECT_EQ(hal.connected.at("motion.digital-in-12").signal, "transport");
  EXPECT_EQ(hal.connected.size(), 6u);
  EXPECT_EQ(hal.unread, std::vector<std::string>{"lib.tcl"});
  EXPECT_EQ(diags_.warning_count(), 1u);
}

TEST_F(LinuxCncConfig, TheExampleReadsAsWritten) {
  const fs::path example = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "linuxcnc" / "paper-cell-headless.ini";
  Result<IniFile> ini = ReadLinuxCncIni(example.string(), sources_, diags_);
  ASSERT_TRUE(ini);
  EXPECT_EQ(ini.value().Find("DISPLAY", "DISPLAY")->value, "linuxcncrsh");  // the headless file's, first
  EXPECT_EQ(ini.value().Find("RS274NGC", "SUBROUTINE_PATH")->value, "runtime:measure/subroutines");
  const HalConfig hal = ReadLinuxCncHal(ini.value(), sources_, diags_);
  EXPECT_EQ(hal.num_dio, 16);
  EXPECT_TRUE(hal.connected.contains("motion.probe-input"));
  EXPECT_EQ(diags_.error_count(), 0u);
  EXPECT_EQ(diags_.warning_count(), 0u);
}

}  // namespace
}  // namespace smtcal
