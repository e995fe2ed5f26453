/*
 * smtcal_runtime.h - the C99 runtime of smtcal's periphery calibration.
 *
 * On the cell's host computer or controller, at the start of every
 * assembling cycle: the marker scan's trip points -> a checked fixture pose
 * FIX (the paper's Eq. 4, or a least-squares fit over all trips) -> for each
 * point of the program, the position it must reach this cycle
 * (FIX . FIXPOS_0, Eq. 6) -> the nominal command that reaches it, through
 * the region's error tables (inverse calibration, bounded iteration).
 *
 * The data (regions with their tables, fixtures, the program's points) is
 * written by `smtcal compile --target c` as a C source of const structures
 * that links with this library. The library allocates nothing, has no
 * writable globals, uses fixed-size arrays and only sqrt and atan2 from
 * libm. Every function returns a named status; a scan that fails a check
 * gives no pose (has_fix = 0), and the cycle must not place.
 *
 * Units: mm and degrees in the data and the results. Documented in
 * runtime/c/README.md and docs/periphery.md; the C++ implementation it is
 * tested against is calibration/fixture_estimation.h.
 */
#ifndef SMTCAL_RUNTIME_H
#define SMTCAL_RUNTIME_H

#ifdef __cplusplus
extern "C" {
#endif

/* Sizes of the fixed arrays. */
#define SMTCAL_MAX_TRIPS 32 /* trips per scan */
#define SMTCAL_EDGE_COUNT 4 /* marker edges p1..p4 */
#define SMTCAL_CHECK_COUNT 11

/* Tolerances; the same values as smtcal's calibration/tolerances.h. */
#define SMTCAL_MIN_TRIP_SEPARATION_MM 0.01
#define SMTCAL_MIN_LINE_CROSSING_SIN 0.1
#define SMTCAL_MIN_RELATIVE_DETERMINANT 1e-12
#define SMTCAL_RIGID_STEP_TOL_RAD 1e-15
#define SMTCAL_RIGID_MAX_ITERATIONS 20
#define SMTCAL_INVERSE_RESIDUAL_TOL_MM 1e-9
#define SMTCAL_INVERSE_POLISH_MM 1e-12
#define SMTCAL_TABLE_EDGE_TOL_MM 1e-9

/* The outcome of a scan: OK, or the first check it failed (the fault code).
 * The checks run in this order. */
typedef enum smtcal_scan_status {
  SMTCAL_SCAN_OK = 0,
  SMTCAL_SCAN_MISSING_TRIP = 1,      /* a trip is missing: the sensor did not trip on a leg */
  SMTCAL_SCAN_TRIP_WINDOW = 2,       /* a trip is farther than trip_window_mm from its nominal point */
  SMTCAL_SCAN_DEGENERATE = 3,        /* the trips define no pose (coincident trips, parallel lines) */
  SMTCAL_SCAN_LENGTH_L1 = 4,         /* | |S2 - S1| - L1 | > length_tolerance_mm */
  SMTCAL_SCAN_LENGTH_L2 = 5,         /* | |S3 - S1| - L2 | > length_tolerance_mm */
  SMTCAL_SCAN_SQUARENESS = 6,        /* | angle(S2 - S1, S3 - S1) - 90 deg | > squareness_deg */
  SMTCAL_SCAN_LINE_RESIDUAL = 7,     /* a trip is farther than max_line_residual_mm from its edge line */
  SMTCAL_SCAN_NOMINAL_SHIFT = 8,     /* |p - p_nominal| > max_shift_mm */
  SMTCAL_SCAN_NOMINAL_ROTATION = 9,  /* |angle - angle_nominal| > max_rotation_deg */
  SMTCAL_SCAN_CYCLE_SHIFT = 10,      /* |p_n - p_(n-1)| > max_shift_mm */
  SMTCAL_SCAN_CYCLE_ROTATION = 11,   /* |angle_n - angle_(n-1)| > max_rotation_deg */
  SMTCAL_SCAN_BAD_ARGUMENT = 12      /* a null pointer, or a fixture the data check rejects */
} smtcal_scan_status;

/* The outcome of correcting one point. */
typedef enum smtcal_point_status {
  SMTCAL_POINT_OK = 0,            /* inside the region's table: corrected */
  SMTCAL_POINT_CLAMPED = 1,       /* outside the table, corrected with its edge values (policy clamp) */
  SMTCAL_POINT_UNCORRECTED = 2,   /* outside the table, commanded as required (policy none) */
  SMTCAL_POINT_OUTSIDE = 3,       /* outside the table, refused (policy error): do not move there */
  SMTCAL_POINT_NOT_CONVERGED = 4, /* the inverse stopped above its tolerance (never with valid data) */
  SMTCAL_POINT_NO_REGION = 5,     /* outside every region's bounds: commanded as required */
  SMTCAL_POINT_BAD_ARGUMENT = 6   /* a null pointer, an index out of range, no FIX for a fixture point */
} smtcal_point_status;

/* The outcome of smtcal_check_program (the data as a whole). */
typedef enum smtcal_data_status {
  SMTCAL_DATA_OK = 0,
  SMTCAL_DATA_NULL = 1,        /* a pointer is null where data is needed */
  SMTCAL_DATA_TABLE = 2,       /* a table has fewer than 2 x 2 nodes, lines not increasing, or a wrong domain */
  SMTCAL_DATA_FIXTURE = 3,     /* a fixture's trip count, edge index, lengths or limits are out of range */
  SMTCAL_DATA_POINT = 4        /* a point names a fixture that does not exist */
} smtcal_data_status;

/* What to do with a point whose inverse falls outside the region's table
 * (smtcal's OutsidePolicy; the cell file's `outside`). */
typedef enum smtcal_outside_policy {
  SMTCAL_OUTSIDE_ERROR = 0,
  SMTCAL_OUTSIDE_CLAMP = 1,
  SMTCAL_OUTSIDE_NONE = 2
} smtcal_outside_policy;

/* The fixture's estimator (the cell file's `estimator`). */
typedef enum smtcal_estimator {
  SMTCAL_ESTIMATOR_PAPER = 0,       /* Eq. 4 on the crossings of the fitted lines */
  SMTCAL_ESTIMATOR_RIGID = 1,       /* least squares over all trips: rotation + translation */
  SMTCAL_ESTIMATOR_RIGID_SCALE = 2  /* the same plus one scale */
} smtcal_estimator;

/* One axis's error table on its own rectilinear grid. */
typedef struct smtcal_axis_table {
  int nx, ny;            /* grid lines, at least 2 each */
  const double *xs;      /* nx lines, strictly increasing (mm) */
  const double *ys;      /* ny lines, strictly increasing (mm) */
  const double *values;  /* the error at (xs[i], ys[j]) is values[j * nx + i] (mm) */
} smtcal_axis_table;

/* A calibrated region: the required positions it serves and its tables. */
typedef struct smtcal_region {
  const char *name;
  double x_lo, x_hi, y_lo, y_hi;  /* bounds (mm, base frame) */
  smtcal_axis_table dx, dy;       /* Delta-x and Delta-y */
  double domain_x0, domain_x1, domain_y0, domain_y1;  /* where both grids overlap */
  double contraction;             /* L = max |grad Delta|_inf over the domain (< 1) */
  int iteration_bound;            /* inverse iterations that always reach 1e-9 mm */
  smtcal_outside_policy outside;
} smtcal_region;

/* A fixture board: nominal pose, marker edges, expected trips, limits. */
typedef struct smtcal_fixture {
  const char *name;
  smtcal_estimator estimator;
  double origin_x, origin_y;         /* nominal S1 (mm, base frame) */
  double cos_angle, sin_angle;       /* nominal direction of the fixture's x axis */
  double l1, l2;                     /* |S2 - S1|, |S3 - S1| (mm) */
  /* Edge lines p1..p4 in fixture coordinates: normal . f = offset, unit normal. */
  double edge_normal[SMTCAL_EDGE_COUNT][2];
  double edge_offset[SMTCAL_EDGE_COUNT];
  int trip_count;                    /* 1..SMTCAL_MAX_TRIPS */
  int trip_edge[SMTCAL_MAX_TRIPS];   /* the edge (0..3) each trip lies on */
  double trip_nominal[SMTCAL_MAX_TRIPS][2];  /* each trip at the nominal pose (mm, base frame) */
  double trip_window;                /* mm */
  double max_shift, max_rotation_deg, length_tolerance, squareness_deg, max_line_residual;
} smtcal_fixture;

/* FIX = [n o a p] with a = (0, 0, 1) and p_z = 0: base (x, y) of a fixture
 * point (fx, fy) is fx n + fy o + p; z passes through. */
typedef struct smtcal_fix {
  double n[2], o[2], p[2];
} smtcal_fix;

/* Everything a scan found. */
typedef struct smtcal_scan_result {
  smtcal_scan_status status;    /* OK or the first failed check */
  int trip;                     /* the trip that failure concerns (0-based), or -1 */
  int has_fix;                  /* 1 only when status is SMTCAL_SCAN_OK */
  smtcal_fix fix;               /* the pose when has_fix; zero otherwise */
  /* Per check, indexed by its status code (1..SMTCAL_CHECK_COUNT): whether it
   * ran and its value (mm, degrees, or the number of missing trips). */
  int evaluated[SMTCAL_CHECK_COUNT + 1];
  double value[SMTCAL_CHECK_COUNT + 1];
  double s[3][2];               /* S1, S2, S3 of the estimate (when one was made) */
  double scale;                 /* the estimate's |n| */
  double calibrated[SMTCAL_MAX_TRIPS][2];  /* trips after direct calibration */
  double residual[SMTCAL_MAX_TRIPS];       /* distance of each trip from its edge line */
  int has_delta;                /* 1 when a previous FIX was given and a pose estimated */
  smtcal_fix delta;             /* FIX_n . FIX_(n-1)^-1 */
} smtcal_scan_result;

/* One corrected point. */
typedef struct smtcal_corrected {
  smtcal_point_status status;
  int region;            /* the region whose bounds hold `required`, or -1 */
  double required[2];    /* FIX . FIXPOS_0: where the part must go (mm, base frame) */
  double command[2];     /* the nominal position to command (mm) */
  double z;              /* passed through (mm) */
  double u_deg;          /* the point's u plus the fixture's angle (degrees) */
  double residual;       /* |F(command) - required| (mm) */
  int iterations;        /* inverse iterations used */
} smtcal_corrected;

/* A program's point, given in its fixture's frame (fixture >= 0) or in the
 * base frame (fixture = -1). */
typedef struct smtcal_point {
  const char *name;
  int fixture;
  double x, y, z, u_deg;
} smtcal_point;

/* Everything `smtcal compile --target c` emits for one program. */
typedef struct smtcal_program {
  const char *name;
  const smtcal_region *regions;
  int region_count;
  const smtcal_fixture *fixtures;
  int fixture_count;
  const smtcal_point *points;
  int point_count;
} smtcal_program;

/* Checks the data once, before the first cycle: tables usable (2 x 2 nodes,
 * increasing lines, domain = the grids' overlap, contraction below 1),
 * fixtures within their array sizes, points naming existing fixtures. The
 * other functions assume data that passed. */
smtcal_data_status smtcal_check_program(const smtcal_program *program);

/* Checks one region's data (as smtcal_check_program does for each). */
smtcal_data_status smtcal_check_region(const smtcal_region *region);

/* Checks one fixture's data (as smtcal_check_program does for each). */
smtcal_data_status smtcal_check_fixture(const smtcal_fixture *fixture);

/* One marker scan. trips_xy holds 2 * fixture->trip_count numbers (x, y of
 * T1, T2, ... in the base frame, as commanded when the sensor tripped);
 * tripped[k] is nonzero when trip k happened (NULL: all did). Trips are
 * direct-calibrated through the first region whose table covers them, the
 * fixture's estimator gives FIX, and every check runs. previous is the last
 * accepted FIX (NULL before the first cycle: no cycle checks). Returns
 * result->status; result->has_fix is 1 only when it is SMTCAL_SCAN_OK. */
smtcal_scan_status smtcal_scan(const smtcal_fixture *fixture, const smtcal_region *regions, int region_count,
                               const double *trips_xy, const unsigned char *tripped, const smtcal_fix *previous,
                               smtcal_scan_result *result);

/* Direct calibration F(n) = n + Delta(n) through one region's tables
 * (Delta taken at n clamped into the table's domain). Writes actual[2]. */
smtcal_point_status smtcal_direct(const smtcal_region *region, const double nominal[2], double actual[2]);

/* Inverse calibration: the command that reaches the required base position
 * through the region whose bounds hold it (SMTCAL_POINT_NO_REGION, command =
 * required, when none does), with the region's outside policy. */
smtcal_point_status smtcal_invert(const smtcal_region *regions, int region_count, const double required[2],
                                  smtcal_corrected *out);

/* A fixture point (x, y in the fixture frame) this cycle: required =
 * FIX . point (Eq. 6), then smtcal_invert. z and u of *out are left 0. */
smtcal_point_status smtcal_correct(const smtcal_fix *fix, const smtcal_region *regions, int region_count,
                                   const double point[2], smtcal_corrected *out);

/* Point `index` of the program this cycle: fix is the accepted FIX of the
 * point's fixture (ignored, may be NULL, for a base-frame point). Fills all
 * of *out, z passed through and u turned with the fixture. */
smtcal_point_status smtcal_program_point(const smtcal_program *program, const smtcal_fix *fix, int index,
                                         smtcal_corrected *out);

/* The fixture's angle of FIX in degrees (atan2 of n). */
double smtcal_fix_angle_deg(const smtcal_fix *fix);

/* The name of a status, for logs: "ok", "missing_trip", ... (the C++
 * ScanCheckName) and "ok", "clamped", ... */
const char *smtcal_scan_status_name(smtcal_scan_status status);
const char *smtcal_point_status_name(smtcal_point_status status);

#ifdef __cplusplus
}
#endif

#endif /* SMTCAL_RUNTIME_H */
