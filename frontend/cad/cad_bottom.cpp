// How a placement list writes its bottom side (see cad_bottom.h).
#include "frontend/cad/cad_bottom.h"

#include <fmt/format.h>

#include "base/field_text.h"

namespace smtcal::cad {

BottomDecision DecideBottomPositions(const ListReader& reader, const std::vector<SidedX>& parts) {
  BottomDecision decision;
  const bool kicad = reader.format() == Format::kKicadPos || reader.format() == Format::kKicadCsv;
  if (!kicad) {
    decision.why = fmt::format("{} lists write it so", FormatTitle(reader.format()));
    return decision;
  }
  const ToolVersion& version = reader.tool_version();
  if (reader.format() == Format::kKicadPos && version.major > 0 && version.major <= 6) {
    decision.positions = BottomPositions::kNegatedX;
    decision.why = fmt::format("KiCad {} writes it so (line {})", Printable(version.text), version.range.begin.line);
    return decision;
  }
  std::size_t bottom = 0, bottom_negative = 0, top = 0, top_positive = 0;
  for (const SidedX& part : parts) {
    if (part.side == Side::kBottom) {
      ++bottom;
      bottom_negative += part.x_mm < 0;
    } else {
      ++top;
      top_positive += part.x_mm > 0;
    }
  }
  const std::string who = version.major > 0 ? fmt::format("KiCad {}", Printable(version.text))
                                            : fmt::format("this {}", FormatTitle(reader.format()));
  if (bottom > 0 && bottom_negative == bottom && top_positive == top) {
    decision.positions = BottomPositions::kNegatedX;
    decision.why = top > 0 ? fmt::format("every bottom part has x < 0 and every top part x > 0 in {}", who)
                           : fmt::format("every bottom part has x < 0 in {}", who);
    decision.why += "; --bottom-positions top-view if it is not";
    return decision;
  }
  decision.why = version.major >= 7
                     ? fmt::format("{} writes it so unless 'negative X' was asked for; --bottom-positions negated-x if it was", who)
                     : fmt::format("{} names no KiCad version and its numbers do not tell (KiCad 6 negates x, KiCad 5 and, by default, 7 and later do not): check the first board; --bottom-positions negated-x if x is negated", who);
  return decision;
}

}  // namespace smtcal::cad
