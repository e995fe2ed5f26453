/*
 * smtcal_record.h - the record of every cycle's marker scan, for the C99
 * runtime's caller to keep (docs/monitor.md has the format; `smtcal monitor`
 * reads it).
 *
 * Every cycle the runtime measures the board: the trips the sensor made, the
 * pose the estimator found, every check's value and the verdict. Kept, that
 * evidence shows a cell that drifts before it places parts out of tolerance:
 * a board pose that walks (the fixture wearing), markers measured ever
 * farther apart (the robot warming), residuals that creep up (the sensor).
 * The LinuxCNC runtime writes the same record itself (runtime/linuxcnc/); here
 * the caller gets it as a structure and as text, and writes the text where it
 * keeps its logs: appended with one write() per record, so an abort leaves
 * each record whole or absent.
 *
 *   smtcal_record record;
 *   char text[SMTCAL_RECORD_TEXT_SIZE];
 *   smtcal_scan(board, regions, region_count, trips, tripped, previous, &scan);
 *   smtcal_record_scan(board, 0, cycle, &now_s, trips, tripped, &scan, &record);
 *   if (smtcal_record_format(&record, -1, text, sizeof text) < (int)sizeof text)
 *     write(log_fd, text, strlen(text));
 *
 * Like the rest of the runtime: no heap, no writable globals; the text comes
 * from snprintf.
 */
#ifndef SMTCAL_RECORD_H
#define SMTCAL_RECORD_H

#include <stddef.h>

#include "smtcal_runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SMTCAL_RECORD_FORMAT 2        /* the format version the begin line states */
/* Room for the text of any record (32 trips: 34 lines) written with
 * decimals -1, or with 0..17 decimals and every value below 1e9 in
 * magnitude. */
#define SMTCAL_RECORD_TEXT_SIZE 4096

/* One cycle's scan as the record keeps it. */
typedef struct smtcal_record {
  int fixture;          /* the fixture's index in the program (the begin line's order) */
  long cycle;           /* 1, 2, ... scans of this fixture since the begin line */
  int has_time;         /* 1 when time_s is the caller's clock */
  double time_s;        /* seconds on the caller's clock */
  smtcal_scan_status status;  /* OK or the first failed check */
  int trip;             /* the trip that failure concerns (0-based), or -1 */
  int trip_count;
  unsigned char tripped[SMTCAL_MAX_TRIPS];  /* 1 where the sensor made the trip */
  double trips[SMTCAL_MAX_TRIPS][2];        /* as commanded when it tripped (mm, base frame) */
  int checked[SMTCAL_CHECK_COUNT + 1];      /* per check code: 1 when it ran */
  double value[SMTCAL_CHECK_COUNT + 1];     /* its value (mm, degrees, or trips missing) */
  int has_estimate;     /* 1 when the estimator gave a pose (checks 4.. ran) */
  double s[3][2];       /* S1, S2, S3 of that pose (mm, base frame) */
} smtcal_record;

/* The record of one scan: what smtcal_scan was given (trips_xy and tripped
 * as there; tripped NULL: all made) and what it found. time_s may be NULL
 * (no clock). Returns SMTCAL_SCAN_BAD_ARGUMENT for a null pointer or a bad
 * fixture, else result->status. */
smtcal_scan_status smtcal_record_scan(const smtcal_fixture *fixture, int fixture_index, long cycle,
                                      const double *time_s, const double *trips_xy, const unsigned char *tripped,
                                      const smtcal_scan_result *result, smtcal_record *record);

/* The record as text (docs/monitor.md): a `cycle` line, a `checks` line and
 * one `trip` line per trip, each ending in a newline; what was not measured
 * (a check that did not run, a trip the sensor did not make, the pose of a
 * scan that gave none, the time without a clock) is written `-`. decimals 0..17 writes every
 * number with that many decimals ("%.*f"); -1 writes each with the 17
 * significant digits that read back exactly. Like snprintf: returns the
 * length of the whole text (without the terminating NUL), writes at most
 * size bytes, always terminated when size > 0; -1 for a null record, a
 * buffer that is null with a size, or decimals out of range. */
int smtcal_record_format(const smtcal_record *record, int decimals, char *buffer, size_t size);

/* The begin line that opens a log (or a part of one): the format version,
 * the cell's name, every fixture of the program with its trip count,
 * the clock (NULL or "": none) and the log's segment number (the caller's
 * count of log files, 0 when it keeps one). Names are written with letters,
 * digits and `_ - .`, anything else as `_`. Returns and writes like
 * smtcal_record_format; -1 for a null program or a bad fixture. */
int smtcal_record_begin(const smtcal_program *program, const char *cell_name, const char *clock, long segment,
                        char *buffer, size_t size);

#ifdef __cplusplus
}
#endif

#endif /* SMTCAL_RECORD_H */
