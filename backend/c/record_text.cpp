// Cycle records as text through the C runtime's formatter (backend/c/record_text.h).
#include "backend/c/record_text.h"

#include <vector>

#include "base/check.h"
#include "runtime/c/smtcal_record.h"

namespace smtcal {
namespace {

// snprintf-style formatters: measured, then written.
template <typename Format>
std::string Formatted(Format format) {
  const int length = format(nullptr, 0);
  SMTCAL_CHECK(length >= 0, "the record formatter refused its arguments");
  std::string text(static_cast<std::size_t>(length) + 1, '\0');
  SMTCAL_CHECK(format(text.data(), text.size()) == length, "the record formatter wrote another length");
  text.resize(static_cast<std::size_t>(length));
  return text;
}

}  // namespace

std::string RecordBeginText(const RecordBegin& begin) {
  std::vector<smtcal_fixture> fixtures(begin.fixtures.size());
  for (std::size_t k = 0; k < begin.fixtures.size(); ++k) {
    fixtures[k].name = begin.fixtures[k].name.c_str();
    fixtures[k].trip_count = static_cast<int>(begin.fixtures[k].trips);
  }
  const smtcal_program program{nullptr, nullptr, 0, fixtures.empty() ? nullptr : fixtures.data(),
                               static_cast<int>(fixtures.size()), nullptr, 0};
  return Formatted([&](char* buffer, std::size_t size) {
    return smtcal_record_begin(&program, begin.cell.c_str(), begin.clock == "none" ? nullptr : begin.clock.c_str(),
                               begin.segment, buffer, size);
  });
}

std::string CycleRecordText(const CycleRecord& record, int decimals) {
  SMTCAL_CHECK(!record.trips.empty() && record.trips.size() <= SMTCAL_MAX_TRIPS, "a record of 1 to 32 trips");
  smtcal_record c{};
  c.fixture = record.fixture;
  c.cycle = record.cycle;
  c.has_time = record.time_s.has_value();
  c.time_s = record.time_s.value_or(0);
  c.status = static_cast<smtcal_scan_status>(record.status);
  c.trip = record.trip;
  c.trip_count = static_cast<int>(record.trips.size());
  for (std::size_t k = 0; k < record.trips.size(); ++k) {
    c.tripped[k] = record.trips[k] ? 1 : 0;
    c.trips[k][0] = record.trips[k] ? record.trips[k]->x() : 0;
    c.trips[k][1] = record.trips[k] ? record.trips[k]->y() : 0;
  }
  for (std::size_t k = 0; k < record.checks.size(); ++k) {
    c.checked[k + 1] = record.checks[k] ? 1 : 0;
    c.value[k + 1] = record.checks[k].value_or(0);
  }
  c.has_estimate = record.estimate ? 1 : 0;
  for (std::size_t k = 0; k < 3 && record.estimate; ++k) {
    c.s[k][0] = (*record.estimate)[k].x();
    c.s[k][1] = (*record.estimate)[k].y();
  }
  return Formatted([&](char* buffer, std::size_t size) { return smtcal_record_format(&c, decimals, buffer, size); });
}

}  // namespace smtcal
