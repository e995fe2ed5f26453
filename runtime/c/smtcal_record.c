/*
 * smtcal_record.c - the cycle record of the C99 runtime (smtcal_record.h;
 * the format is docs/monitor.md, read back by smtcal's frontend/cycle_record.h).
 */
#include "smtcal_record.h"

#include <stdarg.h>
#include <stdio.h>

/* ------------------------------------------------------------------ text */

/* Text appended into the caller's buffer, snprintf-style: `length` counts
 * everything asked for, the buffer holds what fits, always terminated. */
typedef struct text_out {
  char *buffer;
  size_t size;
  size_t length;
  int failed;
} text_out;

static void put(text_out *out, const char *format, ...) {
  va_list args;
  int n;
  char *at = NULL;
  size_t room = 0;
  if (out->length < out->size) {
    at = out->buffer + out->length;
    room = out->size - out->length;
  }
  va_start(args, format);
  n = vsnprintf(at, room, format, args);
  va_end(args);
  if (n < 0) {
    out->failed = 1;
    return;
  }
  out->length += (size_t)n;
}

static int finish(const text_out *out) {
  if (out->size > 0 && out->length >= out->size) out->buffer[out->size - 1] = '\0';
  if (out->failed || out->length > 0x7fffffff) return -1;
  return (int)out->length;
}

/* A number with `decimals` decimals, or (decimals < 0) with the 17
 * significant digits that read back as the same double. */
static void put_number(text_out *out, double value, int decimals) {
  if (decimals < 0) {
    put(out, " %.17g", value);
  } else {
    put(out, " %.*f", decimals, value);
  }
}

/* A name as the record writes it: letters, digits, '_', '-' and '.' (the
 * LinuxCNC runtime can print no other), anything else as '_'; "-" if empty. */
static void put_name(text_out *out, const char *name) {
  const char *c;
  if (name == NULL || name[0] == '\0') {
    put(out, "-");
    return;
  }
  for (c = name; *c != '\0'; ++c) {
    char ch = *c;
    int plain = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
                ch == '-' || ch == '.';
    put(out, "%c", plain ? ch : '_');
  }
}

/* ------------------------------------------------------------------ the record */

smtcal_scan_status smtcal_record_scan(const smtcal_fixture *fixture, int fixture_index, long cycle,
                                      const double *time_s, const double *trips_xy, const unsigned char *tripped,
                                      const smtcal_scan_result *result, smtcal_record *record) {
  int k;
  if (record == NULL) return SMTCAL_SCAN_BAD_ARGUMENT;
  if (fixture == NULL || trips_xy == NULL || result == NULL || fixture->trip_count < 1 ||
      fixture->trip_count > SMTCAL_MAX_TRIPS) {
    return SMTCAL_SCAN_BAD_ARGUMENT;
  }
  record->fixture = fixture_index;
  record->cycle = cycle;
  record->has_time = time_s != NULL;
  record->time_s = time_s != NULL ? *time_s : 0;
  record->status = result->status;
  record->trip = result->trip;
  record->trip_count = fixture->trip_count;
  for (k = 0; k < SMTCAL_MAX_TRIPS; ++k) {
    int present = k < fixture->trip_count;
    record->tripped[k] = (unsigned char)(present && (tripped == NULL || tripped[k]));
    record->trips[k][0] = present ? trips_xy[2 * k] : 0;
    record->trips[k][1] = present ? trips_xy[2 * k + 1] : 0;
  }
  for (k = 0; k <= SMTCAL_CHECK_COUNT; ++k) {
    record->checked[k] = k > 0 && result->evaluated[k];
    record->value[k] = record->checked[k] ? result->value[k] : 0;
  }
  /* The estimator gave a pose when the degenerate check ran and passed. */
  record->has_estimate = result->evaluated[SMTCAL_SCAN_DEGENERATE] && result->value[SMTCAL_SCAN_DEGENERATE] == 0;
  for (k = 0; k < 3; ++k) {
    record->s[k][0] = record->has_estimate ? result->s[k][0] : 0;
    record->s[k][1] = record->has_estimate ? result->s[k][1] : 0;
  }
  return result->status;
}

int smtcal_record_format(const smtcal_record *record, int decimals, char *buffer, size_t size) {
  text_out out;
  int k;
  if (record == NULL || (buffer == NULL && size > 0) || decimals < -1 || decimals > 17 || record->trip_count < 1 ||
      record->trip_count > SMTCAL_MAX_TRIPS) {
    return -1;
  }
  out.buffer = buffer;
  out.size = size;
  out.length = 0;
  out.failed = 0;
  if (size > 0) buffer[0] = '\0';
  /* cycle FIXTURE CYCLE STATUS TRIP TIME S1x S1y S2x S2y S3x S3y */
  put(&out, "cycle %d %ld %d %d", record->fixture, record->cycle, (int)record->status,
      record->trip >= 0 ? record->trip + 1 : 0);
  if (record->has_time) {
    put_number(&out, record->time_s, decimals);
  } else {
    put(&out, " -");
  }
  for (k = 0; k < 3; ++k) {
    if (record->has_estimate) {
      put_number(&out, record->s[k][0], decimals);
      put_number(&out, record->s[k][1], decimals);
    } else {
      put(&out, " - -");
    }
  }
  /* checks FIXTURE CYCLE V1 .. V11 */
  put(&out, "\nchecks %d %ld", record->fixture, record->cycle);
  for (k = 1; k <= SMTCAL_CHECK_COUNT; ++k) {
    if (record->checked[k]) {
      put_number(&out, record->value[k], decimals);
    } else {
      put(&out, " -");
    }
  }
  /* trip FIXTURE CYCLE K X Y, one line per trip */
  for (k = 0; k < record->trip_count; ++k) {
    put(&out, "\ntrip %d %ld %d", record->fixture, record->cycle, k + 1);
    if (record->tripped[k]) {
      put_number(&out, record->trips[k][0], decimals);
      put_number(&out, record->trips[k][1], decimals);
    } else {
      put(&out, " - -");
    }
  }
  put(&out, "\n");
  return finish(&out);
}

int smtcal_record_begin(const smtcal_program *program, const char *cell_name, const char *clock, long segment,
                        char *buffer, size_t size) {
  text_out out;
  int k;
  if (program == NULL || (buffer == NULL && size > 0) || program->fixture_count < 0 ||
      (program->fixtures == NULL && program->fixture_count > 0)) {
    return -1;
  }
  for (k = 0; k < program->fixture_count; ++k) {
    int trips = program->fixtures[k].trip_count;
    if (trips < 1 || trips > SMTCAL_MAX_TRIPS) return -1;
  }
  out.buffer = buffer;
  out.size = size;
  out.length = 0;
  out.failed = 0;
  if (size > 0) buffer[0] = '\0';
  put(&out, "smtcal-record %d cell=", SMTCAL_RECORD_FORMAT);
  put_name(&out, cell_name);
  put(&out, " fixtures=");
  for (k = 0; k < program->fixture_count; ++k) {
    if (k > 0) put(&out, ",");
    put_name(&out, program->fixtures[k].name);
    put(&out, ":%d", program->fixtures[k].trip_count);
  }
  if (program->fixture_count == 0) put(&out, "-");
  put(&out, " clock=");
  put_name(&out, clock != NULL && clock[0] != '\0' ? clock : "none");
  put(&out, " segment=%ld\n", segment);
  return finish(&out);
}
