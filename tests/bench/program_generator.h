// Generated .place programs for the benchmarks: GenerateProgram for the parse
// + check benchmark (declarations, functions with loops, conditions, I/O and
// placements, with a fixture cycle, so every semantic check has work to do);
// GeneratePlacements for the compile and diff benchmarks (a CAD-sized
// program: one point and one Pick/Place pair per placement).
#pragma once

#include <string>

#include <fmt/format.h>

namespace smtcal::bench {

inline std::string GenerateProgram(int target_lines) {
  std::string text;
  text.reserve(static_cast<std::size_t>(target_lines) * 40);
  int lines = 0;
  auto line = [&](const std::string& s) {
    text += s;
    text += '\n';
    ++lines;
  };
  line("' generated for the parse + check benchmark");
  line("Program Bench");
  line("Units mm");
  line("Fixture Board");
  line("Vacuum 8");
  line("Local Layer1 = XY(12.0, 20.0, 0.0, 0.0) In Board");
  const int points = 2000;
  for (int i = 0; i < points; ++i) {
    line(fmt::format("Point P{} = XY({:.3f}, {:.3f}, -3.0, {}.0) In Layer1  ' part {}", i,
                     1.0 + (i % 50) * 0.9, 1.0 + (i / 50) * 1.1, (i % 4) * 90, i));
  }
  line("Point FeedA = XY(160.0, 10.0, -12.0, 0.0)");
  line("Point FeedB = XY(195.0, 10.0, -12.0, 0.0)");
  line("Point FeedC = XY(160.0, 22.0, -12.0, 0.0)");
  line("Pallet 1, FeedA, FeedB, FeedC, 8, 2");
  line("Integer total");
  int function_count = 0;
  while (lines < target_lines - 20) {
    line(fmt::format("Function Place{}", function_count));
    line("  Integer i");
    line("  Real dx");
    line("  For i = 0 To 2");
    line("    dx = i * 55.8 + 0.25");
    for (int k = 0; k < 40 && lines < target_lines - 20; ++k) {
      int p = (function_count * 40 + k) % points;
      line(fmt::format("    Pick Pallet(1, {}, {})", 1 + k % 8, 1 + (k / 8) % 2));
      line(fmt::format("    Place P{} + X(dx) - Y(0.5) LimZ -1.0", p));
      if (k % 10 == 9) {
        line("    If Sw(13) = On And total < 1000 Then");
        line("      total = total + 1");
        line("    Else");
        line("      Wait 0.05");
        line("    EndIf");
      }
    }
    line("  Next i");
    line("Fend");
    ++function_count;
  }
  line("Function Main");
  line("  Cycle Board");
  for (int f = 0; f < function_count; ++f) line(fmt::format("    Call Place{}", f));
  line("  EndCycle");
  line("  On 14");
  line("Fend");
  return text;
}

// `placements` placements for the paper cell, spread over its three layers,
// each a point of its own In its layer, picked from the two feeder banks.
// Every `moved_every`-th point (0: none) lies `moved_mm` further along x:
// the NEW side of the diff benchmark.
inline std::string GeneratePlacements(int placements, int moved_every = 0, double moved_mm = 0) {
  std::string text = "Program Bench\nUnits mm\nFixture Board\nVacuum 8\n";
  text += "Local Layer1 = XY(12.0, 20.0, 0.0, 0.0) In Board\n";
  text += "Local Layer2 = XY(67.8, 20.0, 0.0, 0.0) In Board\n";
  text += "Local Layer3 = XY(123.6, 20.0, 0.0, 0.0) In Board\n";
  text += "Point Bank1First = XY(160.0, 10.0, -12.0, 0.0)\nPoint Bank1Last = XY(195.0, 10.0, -12.0, 0.0)\n";
  text += "Point Bank1Back = XY(160.0, 22.0, -12.0, 0.0)\nPallet 1, Bank1First, Bank1Last, Bank1Back, 8, 2\n";
  text.reserve(static_cast<std::size_t>(placements) * 100 + text.size());
  for (int i = 0; i < placements; ++i) {
    int cell = i % 10000;  // 100 x 100 positions per layer, 0.38 mm apart
    double x = 6.0 + (cell % 100) * 0.38 + (moved_every > 0 && i % moved_every == 0 ? moved_mm : 0.0);
    text += fmt::format("Point P{} = XY({:.3f}, {:.3f}, -3.0, {}.0) In Layer{}\n", i, x, 6.0 + (cell / 100) * 0.38,
                        (i % 4) * 90, 1 + (i / 10000) % 3);
  }
  text += "Function Main\n  Cycle Board\n";
  for (int i = 0; i < placements; ++i) {
    text += fmt::format("    Pick Pallet(1, {}, {})\n    Place P{}\n", 1 + i % 8, 1 + (i / 8) % 2, i);
  }
  text += "  EndCycle\nFend\n";
  return text;
}

}  // namespace smtcal::bench
