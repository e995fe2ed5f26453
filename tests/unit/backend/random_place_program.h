// Random .place programs for examples/paper-cell (the diff's matrix test and
// the LinuxCNC reader's round trip): every kind of target the machine model
// knows — points in rotated and plain Local frames on the board and on the
// board itself, base points, taught points, pallet slots chosen at compile
// time and in loops, offsets known only as loop variables, XY(...) literals —
// under Pick, Place, Jump (with and without LimZ), Go and Move, in Cycles,
// loops, Ifs on inputs and called functions. Every position lies at least
// 4 mm inside its calibrated region for the board's nominal pose (the check
// limits move the board 2 mm), so each one is commanded at every pose the
// diff evaluates. Deterministic in the seed.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "ir/ir_walk.h"

namespace smtcal::test {

inline std::string RandomPlaceProgram(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  auto pick = [&](int n) { return static_cast<int>(std::uniform_int_distribution<int>(0, n - 1)(rng)); };
  auto mm = [](double v) { return fmt::format("{:.3f}", v); };
  std::string text = fmt::format("' generated: seed {}\nProgram Gen{}\nUnits mm\nFixture Board\nVacuum 8\n", seed, seed);
  // The layers: the example's layer 1 region is x 150.5..199.5, y 60.5..109.5
  // in the base frame, the board's origin (138, 40): layer n's region is
  // x 12.5..61.5 (+ 55 (n - 1)), y 20.5..69.5 in the board's frame.
  struct Frame {
    std::string name;
    double x0, y0, angle;  // in the board
  };
  std::vector<Frame> frames;
  for (int layer = 0; layer < 3; ++layer) {
    const double angle = pick(3) == 0 ? 90.0 : 0.0;  // u stays within the robot's +-360
    frames.push_back({fmt::format("L{}", layer + 1), 37 + 55.8 * layer + uniform(-0.5, 0.5), 45 + uniform(-0.5, 0.5), angle});
    const Frame& f = frames.back();
    text += fmt::format("Local {} = XY({}, {}, 0.0, {}) In Board\n", f.name, mm(f.x0), mm(f.y0), f.angle);
  }
  // Points within 17 mm of each frame's origin, offsets of 2 mm at most: 4.5
  // mm inside the region.
  std::vector<std::string> board_points;
  const int points = 3 + pick(10);
  for (int i = 0; i < points; ++i) {
    const std::string name = fmt::format("P{}", i);
    if (pick(5) == 0) {  // straight on the board, in layer 1 or 2
      const int layer = pick(2);
      text += fmt::format("Point {} = XY({}, {}, -3.0, {}) In Board\n", name, mm(37 + 55.8 * layer + uniform(-17, 17)),
                          mm(45 + uniform(-17, 17)), 90 * pick(3));
    } else {
      const Frame& f = frames[static_cast<std::size_t>(pick(3))];
      text += fmt::format("Point {} = XY({}, {}, {}, {}) In {}\n", name, mm(uniform(-17, 17)), mm(uniform(-17, 17)),
                          mm(-3 + uniform(0, 0.4)), 90 * pick(3), f.name);
    }
    board_points.push_back(name);
  }
  // A base point in layer 1's region, the feeder banks' corners.
  text += fmt::format("Point Spot = XY({}, {}, -5.0, 0.0)\n", mm(175 + uniform(-15, 15)), mm(85 + uniform(-15, 15)));
  text += "Point F1 = XY(160.0, 10.0, -12.0, 0.0)\nPoint F2 = XY(195.0, 10.0, -12.0, 0.0)\n";
  text += "Point F3 = XY(160.0, 22.0, -12.0, 0.0)\nPallet 1, F1, F2, F3, 8, 2\n";
  text += "Point G1 = XY(210.0, 10.0, -11.5, 0.0)\nPoint G2 = XY(240.0, 10.0, -11.5, 0.0)\n";
  text += "Point G3 = XY(210.0, 22.0, -11.5, 0.0)\nPallet 2, G1, G2, G3, 4, 2\n";
  // A taught point in layer 1 (robot coordinates, the teach pose is within
  // 0.2 mm of the nominal one).
  const bool taught = pick(2) == 0;
  if (taught) {
    text += fmt::format("Taught Point T = XY({}, {}, -3.0, 0.0) On Board\n", mm(175 + uniform(-15, 15)),
                        mm(85 + uniform(-15, 15)));
  }
  text += "Integer i\nReal dx\n";
  auto board_point = [&] { return board_points[static_cast<std::size_t>(pick(static_cast<int>(board_points.size())))]; };
  auto pick_line = [&](const std::string& indent) {
    switch (pick(3)) {
      case 0: return fmt::format("{}Pick Pallet({}, {}, {})\n", indent, 1, 1 + pick(8), 1 + pick(2));
      case 1: return fmt::format("{}Pick Pallet(2, {})\n", indent, 1 + pick(8));
      default: return fmt::format("{}Pick XY({}, {}, -12.0, 0.0)\n", indent, mm(uniform(165, 235)), mm(uniform(12, 22)));
    }
  };
  auto motion_line = [&](const std::string& indent) {
    switch (pick(7)) {
      case 0: return fmt::format("{}Jump {}\n", indent, board_point());
      case 1: return fmt::format("{}Jump {} LimZ -1.0\n", indent, board_point());
      case 2: return fmt::format("{}Go {}\n", indent, board_point());
      case 3: return fmt::format("{}Move {}\n", indent, board_point());
      case 4: return fmt::format("{}Go Spot\n", indent);
      case 5: return fmt::format("{}Jump XY({}, {}, -5.0, 0.0)\n", indent, mm(uniform(160, 190)), mm(uniform(70, 100)));
      default: return fmt::format("{}Place {} + Y({})\n", indent, board_point(), mm(uniform(-1, 1)));
    }
  };
  // A function called from the cycle.
  text += "Function Layer\n";
  for (int k = 0, n = 1 + pick(4); k < n; ++k) {
    text += pick_line("  ");
    text += fmt::format("  Place {}\n", board_point());
  }
  text += "Fend\n";
  text += "Function Main\n  Cycle Board\n";
  for (int k = 0, n = 2 + pick(5); k < n; ++k) {
    switch (pick(5)) {
      case 0:  // a loop: pallet slots and offsets known only as the loop's variable
        text += fmt::format("    For i = 1 To {}\n      dx = i * 0.5\n", 2 + pick(3));
        text += "      Pick Pallet(1, i)\n";
        text += fmt::format("      Place {} + X(dx)\n    Next i\n", board_point());
        break;
      case 1:  // a branch on an input
        text += "    If Sw(13) = On Then\n" + pick_line("      ") + fmt::format("      Place {}\n", board_point());
        text += "    Else\n" + motion_line("      ") + "    EndIf\n";
        break;
      case 2: text += "    Call Layer\n"; break;
      case 3: text += motion_line("    "); break;
      default: text += pick_line("    ") + fmt::format("    Place {}\n", board_point()); break;
    }
  }
  if (taught) text += pick_line("    ") + "    Place T LimZ -1.0\n";
  text += "  EndCycle\nFend\n";
  return text;
}

// The motion statements of a program (Motion, Pick, Place), in order.
inline std::vector<const ir::Stmt*> Motions(const ir::Program& program) {
  std::vector<const ir::Stmt*> motions;
  ir::ForEachStmt(program.items, [&](const ir::Stmt& stmt) {
    if (std::holds_alternative<ir::Motion>(stmt.node) || std::holds_alternative<ir::PickPlace>(stmt.node)) {
      motions.push_back(&stmt);
    }
  });
  return motions;
}

}  // namespace smtcal::test
